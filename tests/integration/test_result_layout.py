#!/usr/bin/python3
"""The result file layout of docs/results-format.md, checked with h5py the way a user would read it.

Runs the CLI on api/examples/seed_layers.json twice, with its own settings (the paper's penalty scheme) and with
the default solver (exact contact), (CONTACT_BINARY_DIR and CONTACT_SOURCE_DIR come from ctest) and checks the
files it writes and the XDMF sidecars next to them. With a path argument, checks that file instead:
    python3 tests/integration/test_result_layout.py some/result.hdf
Prints one line per check and "N passed, M failed"; exits non-zero on any failure.
"""
import json
import os
import re
import subprocess
import sys
import tempfile
import traceback
import xml.etree.ElementTree as ET

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
import checks  # noqa: E402  (check below is this file's decorator: checks.check counts)

STOP_REASONS = {"converged", "max_iterations", "stagnation", "cancelled", "error"}
METHODS = {"interface_newton", "neumann", "robin", "monolithic"}
ENFORCEMENTS = {"exact", "penalty", "augmented_lagrangian"}
MEASURES = {"fixed_point", "complementarity", "gradient"}
CHECKS = []


def check(fn):
    """Registers a check of a result file: it passes unless it raises (expect)."""
    CHECKS.append(fn)
    return fn


def text(value):
    """An h5py attribute or scalar string dataset as str (variable-length strings may come back as bytes)."""
    if isinstance(value, bytes):
        return value.decode("utf-8")
    if isinstance(value, np.ndarray) and value.shape == ():
        return text(value[()])
    return str(value)


def names(value):
    return [text(v) for v in np.asarray(value).ravel()]


def expect(condition, message):
    if not condition:
        raise AssertionError(message)


class Context:
    def __init__(self, path, job_path=None, bodies=(), floating=()):
        self.path = path
        self.floating = floating
        self.job_path = job_path
        self.bodies = bodies
        self.f = h5py.File(path, "r")


@check
def root_attributes(c):
    a = c.f.attrs
    expect(text(a["format"]) == "contact-ddm-result", f"format is {a['format']!r}")
    expect(int(a["format_version"]) == 3 and np.issubdtype(np.asarray(a["format_version"]).dtype, np.integer),
           f"format_version is {a['format_version']!r}")
    expect(text(a["solver_version"]) != "", "solver_version is empty")
    text(a["job_id"])  # may be empty for the CLI
    expect(re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?Z", text(a["created"])),
           f"created {a['created']!r} is not ISO 8601 UTC")
    expect(float(a["wall_seconds"]) >= 0, "wall_seconds < 0")
    expect(int(a["converged"]) in (0, 1), "converged is not 0/1")
    expect(text(a["stop_reason"]) in STOP_REASONS, f"stop_reason {a['stop_reason']!r}")
    expect((int(a["converged"]) == 1) == (text(a["stop_reason"]) == "converged"),
           "converged and stop_reason disagree")
    expect(int(a["iterations"]) >= 0, "iterations < 0")
    expect(text(a["method"]) in METHODS, f"method {a['method']!r}")
    text(a["message"])
    text(a["name"])


@check
def input_documents(c):
    job = json.loads(c.f["input/job"].asstr()[()])
    normalized = json.loads(c.f["input/normalized"].asstr()[()])
    if c.job_path:
        with open(c.job_path, encoding="utf-8") as fh:
            submitted = json.load(fh)
        expect(job == submitted, "/input/job differs from the submitted job")
        expect(isinstance(normalized, dict) and "solver" in normalized, "/input/normalized has no 'solver'")
        expect(normalized.get("name", submitted.get("name")) == submitted.get("name"), "normalized renames the job")


@check
def warnings(c):
    w = c.f["warnings"]
    pointers, messages = names(w["pointer"][()]), names(w["message"][()])
    expect(len(pointers) == len(messages), "/warnings: pointer and message lengths differ")
    for p, m in zip(pointers, messages):
        expect(p == "" or p.startswith("/"), f"/warnings pointer {p!r} is not a JSON pointer")
        expect(len(m) > 0, "/warnings: an empty message")
    normalized = json.loads(c.f["input/normalized"].asstr()[()])
    expect(all(x in messages for x in (e["message"] for e in normalized.get("warnings", []))),
           "/warnings lacks a warning of the normalized job's")


@check
def provenance(c):
    p = c.f["provenance"]
    for key in ("solver_version", "compiler", "build_type", "host", "method", "enforcement"):
        expect(isinstance(text(p.attrs[key]), str), f"provenance {key}")
    expect(text(p.attrs["enforcement"]) in ENFORCEMENTS, f"provenance enforcement {p.attrs['enforcement']!r}")
    for key in ("gamma", "setup_seconds", "factorization_seconds", "wall_seconds"):
        expect(np.isfinite(float(p.attrs[key])), f"provenance {key} not finite")
    expect(text(p.attrs["solver_version"]) == text(c.f.attrs["solver_version"]), "two solver versions")
    theta = p["theta"][()]
    expect(len(names(p["pair_names"][()])) == len(theta), "theta and pair_names lengths differ")
    if text(p.attrs["enforcement"]) == "exact":
        expect(np.all(theta == 0), "theta must be 0 for exact contact")
    else:
        expect(np.all(theta > 0), "theta must be positive")


@check
def iteration_history(c):
    g = c.f["history/iterations"]
    n = g["iteration"].shape[0]
    nb, npair = len(names(g.attrs["body_names"])), len(names(g.attrs["pair_names"]))
    for col in ("iteration", "update", "paper_criterion", "fixed_point_residual", "complementarity",
                "active_nodes_total", "active_set_changes", "elapsed_seconds"):
        expect(g[col].shape == (n,), f"{col} has shape {g[col].shape}, expected ({n},)")
    expect(g["measure"].shape == (n,), "measure length")
    expect(set(names(g["measure"][()])) <= MEASURES, f"measure values {set(names(g['measure'][()]))}")
    for col in ("elements", "dofs", "elements_refined"):
        expect(g[col].shape == (n, nb), f"{col} has shape {g[col].shape}, expected ({n}, {nb})")
    for col in ("force", "max_pressure", "extent_begin", "extent_end", "active_nodes", "changed_nodes", "theta",
                "max_penetration"):
        expect(g[col].shape == (n, npair), f"{col} has shape {g[col].shape}, expected ({n}, {npair})")
    expect(np.issubdtype(g["iteration"].dtype, np.integer), "iteration is not an integer column")
    it = g["iteration"][()]
    expect(np.all(np.diff(it) > 0), "iteration numbers do not increase")
    expect(np.all(g["max_pressure"][()] >= 0), "a max_pressure is negative")
    expect(np.all(g["active_nodes"][()].sum(axis=1) == g["active_nodes_total"][()]) if npair else True,
           "active_nodes_total is not the sum over the pairs")
    expect(np.all(g["elapsed_seconds"][()] >= 0), "elapsed_seconds < 0")
    if text(c.f.attrs["stop_reason"]) != "error":
        expect(n >= 1, "no iteration recorded")
        expect(int(c.f.attrs["iterations"]) == n, f"iterations = {c.f.attrs['iterations']} but {n} history rows")


PAIR_STRINGS = ("slave_body", "slave_edge", "master_body", "master_edge", "enforcement", "friction")
PAIR_REALS = ("theta", "force", "friction_coefficient", "friction_bound", "tangential_force")
NODE_COLUMNS = ("node", "arc_length", "status", "weight", "gap", "normal_gap", "pressure", "penetration", "active",
                "tangential_traction", "slip", "stick", "pair")
NODE_PAIRS = ("position", "normal", "tangent")


def pair_rows(contacts, p):
    """Pair p of a step's contact tables as docs/results-format.md says to read it: its node rows
    offsets[p]..offsets[p+1] of every node table, its scalars row p of the pair tables, its segments rows
    segment_offsets[p]..segment_offsets[p+1] (rows of the node tables)."""
    offsets, s_off = contacts["offsets"][()], contacts["segment_offsets"][()]
    rows = slice(int(offsets[p]), int(offsets[p + 1]))
    out = {key: contacts[key][rows] for key in NODE_COLUMNS + NODE_PAIRS}
    out["segments"] = contacts["segments"][int(s_off[p]):int(s_off[p + 1])]
    out["first"] = int(offsets[p])
    for key in PAIR_STRINGS:
        out[key] = text(contacts[key].asstr()[p])
    for key in PAIR_REALS:
        out[key] = float(contacts[key][p])
    out["resultant"] = contacts["resultant"][p]
    return out


@check
def step_history(c):
    g = c.f["history/steps"]
    n = g["step"].shape[0]
    nb = len(names(g.attrs["body_names"]))
    expect(n == int(c.f["steps"].attrs["count"]), "history/steps rows != steps count")
    expect(g["iteration"].shape == (n,), "history/steps/iteration length")
    expect(g["elements"].shape == (n, nb) and g["dofs"].shape == (n, nb), "history/steps matrix shapes")
    expect(list(g["step"][()]) == list(range(n)), "step column is not 0..n-1")
    pairs = names(g.attrs["pair_names"])
    np_ = len(pairs)
    for name in ("force", "contact_begin", "contact_end"):
        expect(g[name].shape == (n, np_), f"history/steps/{name} has shape {g[name].shape}, expected {(n, np_)}")
    expect(g["load_factor"].shape == (n,) and np.all(g["load_factor"][()] > 0), "history/steps/load_factor")
    for k in range(n):
        st = c.f["steps"][str(k)]
        expect(float(st.attrs["load_factor"]) == float(g["load_factor"][k]), f"step {k} load_factor attribute")
        for p, pair in enumerate(pairs):
            group = pair_rows(st["contacts"], p)
            expect(float(g["force"][k, p]) == group["force"], f"step {k} pair {pair} force vs the contact table")
            arc, active = group["arc_length"], group["active"]
            begin, end = g["contact_begin"][k, p], g["contact_end"][k, p]
            if len(arc) > 2 and group["segments"].shape[0] == len(arc):
                # A closed slave edge: the zone is the loop less its longest open stretch, across the start where
                # begin > end, [0, the loop's length] all round.
                position = group["position"]
                length = arc[-1] + float(np.hypot(*(position[0] - position[-1])))
                if active.all():
                    expect(begin == 0 and abs(end - length) <= 1e-9 * length,
                           f"step {k} pair {pair} a loop in contact all round: zone [{begin}, {end}], not [0, {length}]")
                elif active.any():
                    expect(0 <= begin < length and 0 <= end < length,
                           f"step {k} pair {pair} contact zone [{begin}, {end}] is not on the loop [0, {length})")
                continue
            expect(begin <= end, f"step {k} pair {pair} contact_begin > contact_end")
            if active.any():
                # Interpolated between nodes (docs/results-format.md): the zone holds every node in contact and
                # ends before the first open node on either side.
                on = np.flatnonzero(active == 1)
                lo = arc[on[0] - 1] if on[0] > 0 else arc[on[0]]
                hi = arc[on[-1] + 1] if on[-1] + 1 < len(arc) else arc[on[-1]]
                expect(lo <= begin <= arc[on[0]] and arc[on[-1]] <= end <= hi,
                       f"step {k} pair {pair} contact zone [{begin}, {end}] is not between the nodes in contact and "
                       f"the open ones next to them")


@check
def floating_bodies(c):
    """A floating body's group names its free motions and its rigid motion; other bodies have none of them."""
    steps = c.f["steps"]
    for k in range(int(steps.attrs["count"])):
        for body, b in steps[str(k)]["bodies"].items():
            keys = {"free_motions", "rigid_center", "rigid_motion"} & set(b.attrs.keys())
            expect(keys in (set(), {"free_motions", "rigid_center", "rigid_motion"}),
                   f"step {k} body {body} has only {keys} of the floating-body attributes")
            if keys:
                expect(len(names(b.attrs["free_motions"])) >= 1, f"step {k} body {body} free_motions empty")
                expect(b.attrs["rigid_center"].shape == (2,) and b.attrs["rigid_motion"].shape == (3,),
                       f"step {k} body {body} rigid_center/rigid_motion shapes")
    for body in c.floating:
        last = steps[str(int(steps.attrs["count"]) - 1)]["bodies"][body]
        expect("free_motions" in last.attrs, f"floating body {body} has no free_motions")


@check
def steps_bodies(c):
    steps = c.f["steps"]
    count = int(steps.attrs["count"])
    expect(count >= 1 or text(c.f.attrs["stop_reason"]) == "error", "no step")
    expect(sorted(steps.keys(), key=int) == [str(k) for k in range(count)], f"step groups {list(steps.keys())}")
    for k in range(count):
        s = steps[str(k)]
        body_names = names(s.attrs["body_names"])
        expect(sorted(body_names) == sorted(s["bodies"].keys()), f"step {k} body_names vs groups")
        for body in c.bodies:
            expect(body in body_names, f"step {k} has no body {body!r}")
        for body in body_names:
            b = s["bodies"][body]
            where = f"step {k} body {body}"
            n, m = b["points"].shape[0], b["cells"].shape[0]
            expect(n > 0 and m > 0, f"{where} is empty")
            shapes = {"points": (n, 2), "cells": (m, 4), "cell_types": (m,), "displacement": (n, 2),
                      "stress_cell": (m, 4), "stress_node": (n, 4), "stress_cell_tensor": (m, 6),
                      "stress_node_tensor": (n, 6), "von_mises": (m,), "level": (m,), "reaction": (n, 2)}
            if "indicator" in b:
                shapes["indicator"] = (m,)
            for name, shape in shapes.items():
                expect(b[name].shape == shape, f"{where} {name} has shape {b[name].shape}, expected {shape}")
            expect(b["points"].dtype == np.float64, f"{where} points dtype {b['points'].dtype}")
            expect(b["cells"].dtype == np.int64, f"{where} cells dtype {b['cells'].dtype}")
            expect(b["cell_types"].dtype == np.uint8, f"{where} cell_types dtype {b['cell_types'].dtype}")
            expect(np.issubdtype(b["level"].dtype, np.integer), f"{where} level dtype")
            cells, types = b["cells"][()], b["cell_types"][()]
            expect(np.all((types == 5) | (types == 9)), f"{where} cell_types other than 5 and 9")
            expect(np.all((cells[:, 3] == -1) == (types == 5)), f"{where} triangles are not the rows ending in -1")
            if np.all(types == 9):  # all quadrilaterals: `quads` is the same dataset
                expect("quads" in b and np.array_equal(b["quads"][()], cells), f"{where} quads differs from cells")
            else:
                expect("quads" not in b and "xdmf_topology" in b, f"{where} with triangles: quads or xdmf_topology")
            expect(cells[:, :3].min() >= 0 and cells.max() < n, f"{where} cells index outside 0..{n - 1}")
            expect(np.all(np.isfinite(b["displacement"][()])), f"{where} displacement not finite")
            expect(np.all(b["von_mises"][()] >= 0), f"{where} von Mises < 0")
            # counter-clockwise cells (positive shoelace area), as mesh.hpp promises; a triangle's last node is
            # its first again (zero-length side)
            q = np.where(cells >= 0, cells, cells[:, :1])
            p = b["points"][()][q]
            area = 0.5 * np.sum(p[:, :, 0] * np.roll(p[:, :, 1], -1, axis=1)
                                - np.roll(p[:, :, 0], -1, axis=1) * p[:, :, 1], axis=1)
            expect(np.all(area > 0), f"{where} has cells that are not counter-clockwise")


@check
def steps_contacts(c):
    steps = c.f["steps"]
    for k in range(int(steps.attrs["count"])):
        s = steps[str(k)]
        pair_names = names(s.attrs["pair_names"])
        t = s["contacts"]
        P = len(pair_names)
        if c.job_path:
            expect(P >= 1, f"step {k} has no contact pair")
        # The tables: P + 1 offsets from 0, N rows per node table, P per pair table, segments within the nodes.
        offsets, s_off = t["offsets"][()], t["segment_offsets"][()]
        expect(offsets.shape == (P + 1,) and offsets[0] == 0 and np.all(np.diff(offsets) >= 0),
               f"step {k} offsets {offsets} do not rise from 0 in P + 1 = {P + 1} entries")
        expect(s_off.shape == (P + 1,) and s_off[0] == 0 and np.all(np.diff(s_off) >= 0), f"step {k} segment_offsets")
        expect(offsets.dtype == np.int64 and s_off.dtype == np.int64, f"step {k} offsets dtype")
        n_all = int(offsets[-1])
        for name in NODE_COLUMNS:
            expect(t[name].shape == (n_all,), f"step {k} contacts/{name} has shape {t[name].shape}, expected ({n_all},)")
        for name in NODE_PAIRS:
            expect(t[name].shape == (n_all, 2), f"step {k} contacts/{name} has shape {t[name].shape}")
        for name in PAIR_STRINGS + PAIR_REALS:
            expect(t[name].shape == (P,), f"step {k} contacts/{name} has shape {t[name].shape}, expected ({P},)")
        expect(t["resultant"].shape == (P, 2), f"step {k} contacts/resultant shape")
        expect(t["segments"].shape == (int(s_off[-1]), 2) and t["segments"].dtype == np.int64, f"step {k} segments")
        for name in ("active", "status", "stick"):
            expect(t[name].dtype == np.int8, f"step {k} contacts/{name} dtype {t[name].dtype}")
        expect(np.array_equal(t["pair"][()], np.repeat(np.arange(P), np.diff(offsets))),
               f"step {k} contacts/pair is not each node's pair index")
        for p, pair in enumerate(pair_names):
            g = pair_rows(t, p)
            where = f"step {k} pair {pair}"
            n, first = len(g["node"]), g["first"]
            # Consecutive nodes of the pair, and on a closed slave edge (n rows) the last back to the first.
            segments = g["segments"] - first
            closed = n > 2 and segments.shape == (n, 2)
            expect(segments.shape == ((n, 2) if closed else (max(n - 1, 0), 2)),
                   f"{where} segments has shape {segments.shape}, expected ({max(n - 1, 0)}, 2) or ({n}, 2)")
            expect(segments.tolist() == [[j, (j + 1) % n] for j in range(segments.shape[0])],
                   f"{where} segments do not join consecutive nodes of the pair's rows")
            expect(set(np.unique(g["active"]).tolist()) <= {0, 1}, f"{where} active is not 0/1")
            status = g["status"]
            expect(set(np.unique(status).tolist()) <= {0, 1, 2, 3, 4, 5}, f"{where} status outside 0..5")
            pressure = g["pressure"]
            expect(np.all(np.isfinite(pressure)) and np.all(pressure >= 0),
                   f"{where} pressure must be >= 0 (positive in compression)")
            # multiplier nodes without a multiplier in this pair (5: another pair of its group carries it)
            dropped = ((status >= 1) & (status <= 3)) | (status == 5)
            expect(np.all(pressure[dropped] == 0), f"{where} a node without multiplier carries pressure")
            weight = g["weight"]
            expect(np.all(weight[status == 0] > 0) and np.all(weight[status != 0] == 0), f"{where} weight vs status")
            expect(abs(float(np.dot(weight, pressure)) - g["force"]) <= 1e-9 * max(1.0, g["force"]),
                   f"{where} force is not sum(weight * pressure)")
            # Gaps are defined (finite) at the nodes that carry a multiplier, NaN at the dropped ones.
            for name in ("gap", "normal_gap"):
                v = g[name]
                expect(np.all(np.isfinite(v[status == 0])) and np.all(np.isnan(v[dropped])), f"{where} {name} NaNs")
            expect(np.allclose(np.linalg.norm(g["normal"], axis=1), 1.0), f"{where} normals are not unit vectors")
            expect(np.allclose(g["tangent"], np.column_stack([-g["normal"][:, 1], g["normal"][:, 0]])),
                   f"{where} tangent is not the normal turned a quarter anticlockwise")
            expect(np.all(g["penetration"] >= 0), f"{where} penetration < 0")
            expect(np.all(np.diff(g["arc_length"]) > 0), f"{where} arc_length does not increase")
            for key in ("slave_body", "slave_edge", "master_body", "master_edge"):
                expect(g[key] != "", f"{where} {key} empty")
            expect(g["enforcement"] in ENFORCEMENTS, f"{where} enforcement {g['enforcement']!r}")
            expect(g["friction"] in ("none", "coulomb", "tresca"), f"{where} friction {g['friction']!r}")
            if g["friction"] == "none":  # no friction: no traction, no slip, nothing sticks
                expect(np.all(g["tangential_traction"] == 0) and np.all(np.isnan(g["slip"]))
                       and np.all(g["stick"] == 0) and g["tangential_force"] == 0,
                       f"{where} a frictionless pair with friction values")
            body_names = names(s.attrs["body_names"])
            expect(g["slave_body"] in body_names and g["master_body"] in body_names,
                   f"{where} names a body that is not in the step")
            slave = s["bodies"][g["slave_body"]]
            node = g["node"]
            if n:
                expect(node.min() >= 0 and node.max() < slave["points"].shape[0], f"{where} node outside the slave mesh")
            expect(np.array_equal(slave["points"][()][node], g["position"]), f"{where} position != slave points")
            if g["enforcement"] == "exact":
                expect(g["theta"] == 0, f"{where} theta != 0 for exact contact")
            else:
                expect(g["theta"] > 0, f"{where} theta <= 0")
            expect(g["force"] >= 0, f"{where} force < 0")


@check
def vtkhdf(c):
    if int(c.f["steps"].attrs["count"]) == 0:
        expect("VTKHDF" not in c.f, "VTKHDF without steps")
        return
    v = c.f["VTKHDF"]
    expect(list(v.attrs["Version"]) == [1, 0], f"Version is {v.attrs['Version']!r}")
    type_id = v.attrs.get_id("Type").get_type()
    expect(type_id.get_class() == h5py.h5t.STRING and not type_id.is_variable_str(), "Type is not fixed-length")
    expect(type_id.get_size() == 16, f"Type is {type_id.get_size()} bytes, expected 16")
    expect(text(v.attrs["Type"]) == "UnstructuredGrid", f"Type is {v.attrs['Type']!r}")
    npts, ncells, nids = (v[k][()] for k in ("NumberOfPoints", "NumberOfCells", "NumberOfConnectivityIds"))
    last = c.f["steps"][str(int(c.f["steps"].attrs["count"]) - 1)]
    nbody, npair = len(names(last.attrs["body_names"])), len(names(last.attrs["pair_names"]))
    expect(len(npts) == nbody + npair, "one partition per body, then one per contact pair")
    expect(v["Points"].shape == (npts.sum(), 3), f"Points shape {v['Points'].shape}")
    expect(np.all(v["Points"][:, 2] == 0), "Points z != 0")
    expect(v["Connectivity"].shape == (nids.sum(),), "Connectivity length")
    expect(v["Offsets"].shape == (ncells.sum() + len(ncells),), "Offsets length (n_cells + 1 per partition)")
    expect(v["Types"].shape == (ncells.sum(),) and v["Types"].dtype == np.uint8, "Types shape/dtype")
    body_cells = int(ncells[:nbody].sum())
    expect(np.all((v["Types"][:body_cells] == 9) | (v["Types"][:body_cells] == 5)),
           "body cells are not all VTK_QUAD (9) or VTK_TRIANGLE (5)")
    expect(np.all(v["Types"][body_cells:] == 3), "contact cells are not all VTK_LINE (3)")
    for name in ("pressure", "gap", "active"):
        expect(v["PointData"][name].shape == (npts.sum(),), f"PointData/{name} shape")
    body_points = int(npts[:nbody].sum())
    expect(np.all(np.isnan(v["PointData/pressure"][:body_points])), "body points carry a pressure")
    expect(np.all(v["PointData/pressure"][body_points:] >= 0), "contact points have negative pressure")
    expect(np.all(v["CellData/pair_id"][body_cells:] >= 0), "contact cells without pair_id")
    offsets, conn = v["Offsets"][()], v["Connectivity"][()]
    o = i = 0
    for p in range(len(npts)):
        part = offsets[o:o + ncells[p] + 1]
        expect(part[0] == 0 and part[-1] == nids[p], f"partition {p} offsets run {part[0]}..{part[-1]}")
        ids = conn[i:i + nids[p]]
        expect(ids.min() >= 0 and ids.max() < npts[p], f"partition {p} connectivity is not partition-local")
        o += ncells[p] + 1
        i += nids[p]
    expect(v["PointData/displacement"].shape == (npts.sum(), 3), "PointData/displacement shape")
    for name in v["CellData"]:
        expect(v["CellData"][name].shape[0] == ncells.sum(), f"CellData/{name} rows")
    for name in ("stress", "von_mises", "body_id", "pair_id", "level"):
        expect(name in v["CellData"], f"CellData/{name} missing")


@check
def xdmf_sidecar(c):
    base, _ = os.path.splitext(c.path)
    xmf = base + ".xmf"
    folder = os.path.dirname(c.path) or "."
    expect(os.path.exists(xmf), f"no sidecar {xmf} (files there: {sorted(os.listdir(folder))})")
    root = ET.parse(xmf).getroot()
    expect(root.tag == "Xdmf", f"root element is {root.tag}")
    temporal = root.find("Domain/Grid")
    expect(temporal is not None and temporal.get("CollectionType") == "Temporal", "no temporal collection")
    count = int(c.f["steps"].attrs["count"])
    children = temporal.findall("Grid")
    expect(len(children) == count, f"{len(children)} step grids for {count} steps")
    hdf_name = os.path.basename(c.path)
    # Load steps are timed by their (increasing) load factors, adaptive steps by their index.
    factors = [float(f) for f in c.f["history/steps/load_factor"][()]]
    by_load = len(factors) > 1 and all(b > a for a, b in zip(factors, factors[1:]))
    for k, step in enumerate(children):
        time = float(step.find("Time").get("Value"))
        expect(time == (factors[k] if by_load else k), f"step {k} has Time {time}")
        grids = {g.get("Name"): g for g in step.findall("Grid")}
        st = c.f["steps"][str(k)]
        surfaces = ["contacts"] if st["contacts"]["segments"].shape[0] > 0 else []
        expect(sorted(grids) == sorted(names(st.attrs["body_names"]) + surfaces),
               f"step {k} grids: one per body and one for the contact surfaces")
        if surfaces:
            expect(grids["contacts"].find("Topology").get("TopologyType") == "Polyline", f"step {k} contacts topology")
            attributes = {a.get("Name") for a in grids["contacts"].findall("Attribute")}
            expect({"pressure", "gap", "active", "pair"} <= attributes, f"step {k} contacts attributes {attributes}")
        for item in step.iter("DataItem"):
            if item.get("Format") != "HDF":
                continue
            file_name, _, dataset = item.text.strip().partition(":")
            expect(file_name == hdf_name, f"data item names {file_name}, expected {hdf_name}")
            expect(dataset in c.f, f"{dataset} referenced by the sidecar is not in the file")
            dims = tuple(int(d) for d in item.get("Dimensions").split())
            expect(c.f[dataset].shape == dims, f"{dataset} is {c.f[dataset].shape}, sidecar says {dims}")


def run_cli(tmp, name, solver="own"):
    """contact-solve on api/examples/<name> with its own solver settings, or with the defaults (solver="default"),
    or with the defaults in 3 load steps (solver="steps")."""
    binary = os.path.join(os.environ.get("CONTACT_BINARY_DIR", "build"), "contact-solve")
    job = os.path.join(os.environ.get("CONTACT_SOURCE_DIR", "."), "api", "examples", name)
    for needed in (binary, job):
        if not os.path.exists(needed):
            raise RuntimeError(f"{needed} does not exist")
    if solver in ("default", "steps"):
        with open(job, encoding="utf-8") as fh:
            document = json.load(fh)
        document.pop("solver", None)
        if solver == "steps":
            document["loading"] = {"steps": 3}
        job = os.path.join(tmp, "default_" + name)
        with open(job, "w", encoding="utf-8") as fh:
            json.dump(document, fh)
    out = os.path.join(tmp, f"{solver}_{os.path.splitext(name)[0]}.hdf")
    proc = subprocess.run([binary, job, "-o", out], capture_output=True, text=True, timeout=540)
    if proc.returncode != 0:
        raise RuntimeError(f"contact-solve exited {proc.returncode}:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    if not os.path.exists(out):
        raise RuntimeError(f"contact-solve exited 0 but wrote no {out} (files: {sorted(os.listdir(tmp))})")
    return out, job


def check_file(context, label):
    for fn in CHECKS:
        try:
            fn(context)
            ok, detail = True, ""
        except Exception as e:
            ok = False
            detail = str(e) if isinstance(e, AssertionError) else traceback.format_exc(limit=2)
        checks.check(f"{label}{fn.__name__}", ok, detail)
    context.f.close()


def main():
    checks.show_passes()
    with tempfile.TemporaryDirectory() as tmp:
        contexts = []
        try:
            if len(sys.argv) > 1:
                contexts.append(("", Context(sys.argv[1])))
            else:
                for name, solver in (("seed_layers.json", "own"), ("seed_layers.json", "default"), ("stack3.json", "default"),
                                     ("stack3_floating.json", "steps")):
                    path, job = run_cli(tmp, name, solver)
                    floating = ("middle",) if name == "stack3_floating.json" else ()
                    contexts.append((f"[{solver} {name}] ", Context(path, job_path=job, floating=floating)))
        except Exception as e:  # a file is unavailable: one failure, nothing else to check
            checks.check("produce a result file", False, e)
            checks.finish()
        for label, context in contexts:
            check_file(context, label)
    checks.finish()


if __name__ == "__main__":
    main()
