#!/usr/bin/env python3
"""A collapse analysis on MPI ranks (issue 48, item 1): the same running-bond wall of 2:1 stones (precompressed,
sheared at its top, mu = 0.6) on 1 and 2 ranks gives the same bracket of the collapse multiplier (to 1e-3), the same
rigid-block statics' bound (its loads summed over the ranks that own the bodies) and the same mechanism; a column of
three blocks overturning about its base's toe gives lambda_c = b / (n h) = 1/3 on 2 ranks as on one.

Exits 77 (skipped) when mpirun is missing or contact-solve was built without MPI."""
import json
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(HERE, "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
CLI = os.path.join(BIN, "contact-solve")
EXAMPLES = os.path.join(SRC, "api", "examples")
sys.path.insert(0, os.path.join(HERE, ".."))  # tests/: checks.py
from checks import check, finish, skip  # noqa: E402
from limit_jobs import column  # noqa: E402

import h5py  # noqa: E402

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_rmaps_base_oversubscribe="1")


def mpirun(ranks, *args):
    return subprocess.run(["mpirun", "-n", str(ranks), CLI, *args], capture_output=True, text=True, timeout=300,
                          env=ENV)


def collapse(path):
    with h5py.File(path, "r") as f:
        g = f["collapse"]
        t = g["trials"]
        return {"verdict": g.attrs["verdict"], "held": float(g.attrs["held"]), "failed": float(g.attrs["failed"]),
                "bound": float(g.attrs["statics_bound"]), "kind": g["mechanism"].attrs["kind"],
                "source": g["mechanism"].attrs.get("source", ""),
                "moving": sorted(n.decode() for n in g["mechanism"]["body_names"][()]),
                "joints": sorted(zip((n.decode() for n in g["mechanism"]["pair_names"][()]),
                                     (k.decode() for k in g["mechanism"]["joint_kind"][()]))),
                "curve": sorted((float(m), float(d)) for m, h, d in
                                zip(t["multiplier"][()], t["held"][()], t["displacement"][()]) if h)}


if not shutil.which("mpirun"):
    skip("mpirun not found (Debian's openmpi-bin; scripts/setup.sh installs it)")

with tempfile.TemporaryDirectory() as tmp:
    probe = mpirun(2, os.path.join(EXAMPLES, "flat_patch.json"), "-o", os.path.join(tmp, "probe.hdf"), "-q")
    if "MPI ranks" not in probe.stdout:
        skip("contact-solve was built without MPI (CONTACT_WITH_MPI off or MPI not found)\n" + probe.stdout[-300:])

    wall = os.path.join(tmp, "wall.json")
    subprocess.run([sys.executable, os.path.join(SRC, "scripts", "make_brick_wall.py"), "--rows", "4", "--bricks",
                    "4", "--head-joints", "--friction", "0.6", "--brick-height", "0.12", "--collapse", "-o", wall],
                   check=True, capture_output=True, timeout=60)
    answers = {}
    for ranks in (1, 2):
        out = os.path.join(tmp, f"wall_{ranks}.hdf")
        r = mpirun(ranks, wall, "-o", out, "-q")
        check(f"the wall on {ranks} rank(s): exit 0", r.returncode == 0, r.stderr[-500:])
        answers[ranks] = collapse(out)
    one, two = answers[1], answers[2]
    check("1 and 2 ranks: a collapse, the same bracket to 1e-3",
          one["verdict"] == two["verdict"] == "collapse" and abs(one["held"] - two["held"]) <= 1e-3 * one["held"]
          and abs(one["failed"] - two["failed"]) <= 1e-3 * one["failed"], (one, two))
    check("1 and 2 ranks: the same statics bound (1e-9) and mechanism",
          abs(one["bound"] - two["bound"]) <= 1e-9 * one["bound"] and one["kind"] == two["kind"] != "", (one, two))
    # The mechanism is read off the elastic states near the limit (the increment into the last held state, fitted by
    # rigid motions on the ranks that own the bodies and summed): the same bodies move, the same joints do the same.
    check("1 and 2 ranks: the elastic solution's own mechanism, the same bodies and joints",
          one["source"] == two["source"] == "elastic" and one["moving"] == two["moving"] != [] and
          one["joints"] == two["joints"], (one["source"], two["source"], one["moving"], two["moving"]))
    check("the bracket lies below the statics bound", one["failed"] <= one["bound"] * 1.001, one)
    # The capacity curve's displacement sums the live loads' work over the ranks that own the bodies: at the first
    # held trial (the same multiplier on both) the same to 1e-8.
    check("1 and 2 ranks: the same live-load displacement at the first held trial (1e-8)",
          one["curve"] and two["curve"] and one["curve"][0][0] == two["curve"][0][0] and
          abs(one["curve"][0][1] - two["curve"][0][1]) <= 1e-8 * abs(one["curve"][0][1]) and one["curve"][0][1] > 0,
          (one["curve"][:2], two["curve"][:2]))

    path = os.path.join(tmp, "column.json")
    with open(path, "w") as f:
        json.dump(column(), f)
    out = os.path.join(tmp, "column.hdf")
    r = mpirun(2, path, "-o", out, "-q")
    c = collapse(out) if r.returncode == 0 else {}
    check("the column on 2 ranks: lambda_c = 1/3 to 1e-3, overturning",
          c.get("verdict") == "collapse" and c["held"] <= 1 / 3 + 1e-12 <= c["failed"] + 2e-12 and
          abs(0.5 * (c["held"] + c["failed"]) - 1 / 3) <= 1e-3 / 3 and c["kind"] == "overturning", (r.stderr[-300:], c))

finish()
