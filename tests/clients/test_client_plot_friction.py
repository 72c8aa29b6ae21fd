#!/usr/bin/env python3
"""The client's plot and progress lines show friction (issue 21, item 4): friction jobs solved by contactd (a
half cylinder pressed and pushed sideways in three load steps, Coulomb; a block pushed sideways under Tresca's
bound in four load steps; the roller held by friction between two plates, one step, plotted with its events)
and plotted by the client. Read back from the figure: each friction pair has a tangential-traction panel under
its pressure panel on the same horizontal axis, its final curve the file's tangential traction, one curve per
step (or per iteration of the events, those being the events' tangential tractions); the stick zone is shaded
in both panels exactly over the sticking nodes (each sticking node inside a span, every other node outside, each
span reaching halfway to the neighbouring nodes), and the legend names the law, its coefficient or bound and the
tangential force. A frictionless result has no such panel, and a file written before friction (no `friction`
attribute, no tangential datasets) plots as frictionless. The progress lines carry t_force for friction pairs
only, and `plot` prints the law and the stick zone.

Starts contactd through tests/server/harness.py. Standard library + Debian's numpy, h5py, matplotlib. Prints
"N passed, M failed"; exits 1 on any failure."""
import os
import shutil
import subprocess
import sys
import tempfile

from client_paths import CLIENT, EXAMPLES, HERE, SRC  # noqa: E402,F401  (sets the import path)

import h5py  # noqa: E402
import numpy as np  # noqa: E402

import contact_client as cc  # noqa: E402
from harness import HOST, Server, example, roller_job  # noqa: E402
from checks import check, finish  # noqa: E402


ROLLER_PAIRS = ("roller.bottom-base.top", "roller.top-plate.bottom")


def pushed_job():
    """A half cylinder (R = 2) pressed on a block, then pushed sideways by a force at its top left corner (0, 0.5,
    1 in three steps): partial slip, Coulomb mu = 0.2 (tests/integration/test_friction.cpp's pushed_cylinder)."""
    block = {"name": "block", "material": {"E": 1000, "nu": 0.3},
             "mesh": {"block": {"corners": [[-2, -2], [2, -2], [2, 0], [-2, 0]], "nx": 37, "ny": 9}},
             "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]}
    cylinder = {"name": "cylinder", "material": {"E": 600, "nu": 0.25},
                "mesh": {"block": {"corners": [[-1.2, 0.4], [1.2, 0.4], [1.2, 2], [-1.2, 2]], "nx": 29, "ny": 8,
                                   "edges": {"bottom": {"arc": {"center": [0, 2], "radius": 2}}}}},
                "boundary": [{"edge": "top", "displacement": {"y": -0.03}},
                             {"vertex": "top_left", "force": [1, 0], "history": [0, 0.5, 1]}]}
    return {"name": "pushed", "bodies": [block, cylinder],
            "contacts": [{"name": "c", "slave": "cylinder.bottom", "master": "block.top",
                          "friction": {"coefficient": 0.2}}],
            "loading": {"factors": [1, 1, 1]}}


def tresca_job():
    """A block pressed on a foundation and moved sideways until it slides under Tresca's bound g = 5
    (tests/integration/test_friction.cpp's tresca_job): increasing load factors, so the figure has its load curve too."""
    ground = {"name": "ground", "material": {"E": 1000, "nu": 0.3},
              "mesh": {"block": {"corners": [[-1, -0.5], [1, -0.5], [1, 0], [-1, 0]], "nx": 20, "ny": 5}},
              "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]}
    block = {"name": "block", "material": {"E": 1000, "nu": 0.3},
             "mesh": {"block": {"corners": [[-0.5, 0], [0.5, 0], [0.5, 0.5], [-0.5, 0.5]], "nx": 7, "ny": 4}},
             "boundary": [{"edge": "top", "displacement": {"x": 0.05, "y": -0.005}}]}
    return {"name": "tresca", "bodies": [ground, block],
            "contacts": [{"name": "c", "slave": "block.bottom", "master": "ground.top", "friction": {"bound": 5}}],
            "loading": {"factors": [0.02, 0.05, 0.5, 1]}}


def solve(client, job, tmp):
    """The job solved by contactd: (the result file's path, its events)."""
    events = []
    submitted = client.submit(job)
    final = client.wait(submitted["id"], on_event=events.append)
    check(f"{job['name']}: SUCCEEDED", final.get("state") == "SUCCEEDED", final)
    path = os.path.join(tmp, f"{job['name']}.hdf")
    client.download(submitted["id"], path)
    return path, events


def panels(fig):
    """The figure's pressure axes and its tangential-traction axes (told apart by their vertical labels)."""
    tangential = [ax for ax in fig.axes if ax.get_ylabel() == "tangential traction"]
    pressure = [ax for ax in fig.axes if ax.get_ylabel() == "contact pressure"]
    return pressure, tangential


def gid_lines(ax, gid):
    return [line for line in ax.get_lines() if line.get_gid() == gid]


def spans(ax):
    """The x ranges (lo, hi) of ax's shaded stick zones (axvspan patches, x in data units), in increasing order."""
    out = []
    for patch in ax.patches:
        if patch.get_gid() == "stick_zone":
            xs = patch.get_patch_transform().transform(patch.get_path().vertices)[:, 0]
            out.append((float(xs.min()), float(xs.max())))
    return sorted(out)


def check_stick_spans(name, found, s, stick):
    """The shaded spans cover the sticking nodes and no other, each reaching halfway to its neighbours."""
    inside = [any(lo <= x <= hi for lo, hi in found) for x in s]
    check(f"{name}: every sticking node lies in a shaded span, every other node outside",
          list(inside) == list(stick), (found, s[stick], s[~stick][:10]))
    order = np.argsort(s)
    xs, on = s[order], stick[order]
    for lo, hi in found:
        first, last = np.flatnonzero((xs >= lo) & (xs <= hi))[[0, -1]]
        want_lo = (xs[first - 1] + xs[first]) / 2 if first > 0 else xs[first]
        want_hi = (xs[last] + xs[last + 1]) / 2 if last + 1 < len(xs) else xs[last]
        check(f"{name}: the span ({lo:.4g}, {hi:.4g}) reaches halfway to the nodes beyond it",
              np.isclose(lo, want_lo) and np.isclose(hi, want_hi) and on[first:last + 1].all(),
              ((lo, hi), (want_lo, want_hi)))


def check_friction_panel(name, fig, drawn, pair, c, law, curves):
    """The pair's tangential panel: under its pressure panel, sharing its x range; its final curve the file's
    tangential traction; `curves` coloured curves besides the final one and the bound; the stick spans in both
    panels; the legend naming the law and the force. Returns the tangential axes."""
    pressure, tangential = panels(fig)
    mine = [ax for ax in tangential if any(np.array_equal(np.asarray(line.get_ydata(), float),
                                                          np.asarray(c["tangential_traction"], float))
                                           for line in gid_lines(ax, "tangential_traction"))]
    if not check(f"{name}: a tangential-traction panel whose final curve is the file's tangential traction",
                 len(mine) == 1, [ax.get_lines() for ax in tangential]):
        return None
    tax = mine[0]
    above = [ax for ax in pressure if tax in ax.get_shared_x_axes().get_siblings(ax) and ax is not tax]
    check(f"{name}: it shares its horizontal axis with one pressure panel, right above it",
          len(above) == 1 and above[0].get_position().y0 >= tax.get_position().y1 - 1e-9,
          [ax.get_position() for ax in pressure])
    check(f"{name}: the same horizontal range as the pressure (as drawn)",
          tuple(tax.get_xlim()) == drawn["pressure_xlim"][pair], (tax.get_xlim(), drawn["pressure_xlim"][pair]))
    final = gid_lines(tax, "tangential_traction")[0]
    check(f"{name}: drawn against arc length", np.array_equal(final.get_xdata(), c["arc_length"]))
    others = [line for line in tax.get_lines() if line.get_gid() is None and len(line.get_xdata()) > 2]
    check(f"{name}: {curves} coloured curves besides the final one", len(others) == curves, len(others))
    stick = np.asarray(c["stick"]) == 1
    check(f"{name}: some node sticks", stick.any(), c["stick"])
    s = np.asarray(c["arc_length"], float)
    check_stick_spans(f"{name}, tangential panel", spans(tax), s, stick)
    if above:
        check(f"{name}: the pressure panel shades the same spans", spans(above[0]) == spans(tax),
              (spans(above[0]), spans(tax)))
    check(f"{name}: drawn['stick_zones'] are the spans shaded", drawn["stick_zones"][pair] == spans(tax),
          (drawn["stick_zones"][pair], spans(tax)))
    legend = [text.get_text() for text in tax.get_legend().get_texts()] if tax.get_legend() else []
    force = c["attrs"]["tangential_force"]
    check(f"{name}: the legend names the law and the tangential force",
          any(law in text and f"force {force:.4g}" in text for text in legend) and "stick zone (final)" in legend,
          legend)
    bound = gid_lines(tax, "friction_bound")
    return tax, bound


def test_coulomb_steps(path):
    result = cc.read_result(path)
    steps = result["steps"]
    c = steps[-1]["contacts"]["c"]
    f = cc.results.pair_friction(c)
    check("pushed: pair_friction reads Coulomb mu 0.2 and the tangential force",
          f is not None and f["law"] == "coulomb" and f["coefficient"] == 0.2
          and f["tangential_force"] == c["attrs"]["tangential_force"], f)
    fig_png = os.path.join(os.path.dirname(path), "pushed.png")
    drawn = cc.plot_result(result, fig_png)
    check("pushed: drawn['friction'] names the law", drawn["friction"] == {"c": "Coulomb, mu = 0.2"},
          drawn["friction"])
    found = check_friction_panel("pushed", drawn["figure"], drawn, "c", c, "Coulomb, mu = 0.2", curves=len(steps))
    if found:
        _, bound = found
        mu_p = 0.2 * np.asarray(c["pressure"], float)
        check("pushed: the slip bound is +-mu p of the final step",
              len(bound) == 2 and np.allclose(bound[0].get_ydata(), mu_p) and np.allclose(bound[1].get_ydata(), -mu_p),
              [b.get_ydata() for b in bound])
    slipping = (np.asarray(c["active"]) == 1) & (np.asarray(c["stick"]) == 0)
    check("pushed: where the final state slips, the traction is on the bound (what the dotted lines show)",
          slipping.any() and np.allclose(np.abs(c["tangential_traction"][slipping]),
                                         0.2 * c["pressure"][slipping], rtol=1e-6), c["stick"])


def test_tresca(path):
    result = cc.read_result(path)
    drawn = cc.plot_result(result, os.path.join(os.path.dirname(path), "tresca.png"))
    check("tresca: drawn['friction'] names the law and bound", drawn["friction"] == {"c": "Tresca, g = 5"},
          drawn["friction"])
    steps = result["steps"]
    pressure, tangential = panels(drawn["figure"])
    check("tresca: one pressure and one tangential panel", len(pressure) == 1 and len(tangential) == 1,
          (len(pressure), len(tangential)))
    check("tresca: the load curve is still drawn", any(ax.get_xlabel() == "load factor" for ax in drawn["figure"].axes))
    tax = tangential[0] if tangential else None
    bound = gid_lines(tax, "friction_bound") if tax else []
    check("tresca: the slip bound is +-g", len(bound) == 2 and np.allclose(bound[0].get_ydata(), 5)
          and np.allclose(bound[1].get_ydata(), -5), [b.get_ydata() for b in bound])
    # The last step slides (no node sticks): no span. An early step sticks: its zone drawn on its own.
    check("tresca: the final step slides everywhere, nothing shaded", tax is not None and spans(tax) == []
          and drawn["stick_zones"]["c"] == [], tax and spans(tax))
    k = next((k for k, step in enumerate(steps) if np.any(step["contacts"]["c"]["stick"] == 1)), 0)
    c = steps[k]["contacts"]["c"]
    drawn = cc.plot_result(dict(result, steps=[steps[k]]), os.path.join(os.path.dirname(path), "tresca0.png"))
    check_friction_panel("tresca, first step alone", drawn["figure"], drawn, "c", c, "Tresca, g = 5", curves=0)


def test_roller_events(path, events):
    result = cc.read_result(path)
    drawn = cc.plot_result(result, os.path.join(os.path.dirname(path), "roller.png"), events=events)
    iterations = [e for e in events if e.get("type") == "iteration"]
    final = result["steps"][-1]
    for pair in ROLLER_PAIRS:
        c = final["contacts"][pair]
        found = check_friction_panel(f"roller {pair}", drawn["figure"], drawn, pair, c, "Coulomb, mu = 0.2",
                                     curves=min(len(iterations), 12))
        last = [p for p in iterations[-1]["pairs"] if p["name"] == pair][0]
        check(f"roller {pair}: the last event carries the tangential tractions and stick of the file",
              np.allclose(last["tangential_tractions"], c["tangential_traction"])
              and list(last["stick"]) == list(c["stick"]), last.get("stick"))
        if found:
            tax, _ = found
            curves = [line for line in tax.get_lines() if line.get_gid() is None and len(line.get_xdata()) > 2]
            check(f"roller {pair}: the last iteration's curve is the events' tangential traction",
                  curves and np.allclose(curves[-1].get_ydata(), last["tangential_tractions"])
                  and np.allclose(curves[-1].get_xdata(), last["positions"]), curves and curves[-1].get_ydata())
    line = cc.format_iteration(iterations[-1])
    forces = [p["tangential_force"] for p in iterations[-1]["pairs"]]
    check("progress line: t_force of each friction pair", line.count(" t_force ") == 2
          and all(cc.display.num(f, ".5g") in line for f in forces), line)
    compact = cc.compact_iterations(iterations[-1])[0]
    check("live line: t_force of both pairs joined by '/'",
          "t_force " + "/".join(cc.display.num(f, ".5g") for f in forces) in compact, compact)
    r = subprocess.run([sys.executable, CLIENT, "plot", path, "-o", os.path.join(os.path.dirname(path), "cli.png")],
                       capture_output=True, text=True, timeout=120)
    zone = drawn["stick_zones"][ROLLER_PAIRS[0]][0]
    check("cli plot: prints each friction pair's law, tangential force and stick zone",
          r.returncode == 0 and f"{ROLLER_PAIRS[0]}: Coulomb, mu = 0.2, tangential force " in r.stdout
          and f"stick from {zone[0]:g} to {zone[1]:g}" in r.stdout, r.stdout + r.stderr)


def test_frictionless(path, events):
    result = cc.read_result(path)
    drawn = cc.plot_result(result, os.path.join(os.path.dirname(path), "flat.png"), events=events)
    pressure, tangential = panels(drawn["figure"])
    check("frictionless: no tangential panel, no stick zone, nothing in drawn['friction']",
          len(pressure) == 1 and not tangential and drawn["friction"] == {} and drawn["stick_zones"] == {}
          and not any(spans(ax) for ax in drawn["figure"].axes), (len(pressure), len(tangential), drawn["friction"]))
    iteration = [e for e in events if e.get("type") == "iteration"][-1]
    check("frictionless: no t_force in the progress lines",
          "t_force" not in cc.format_iteration(iteration) and "t_force" not in cc.compact_iterations(iteration)[0],
          cc.format_iteration(iteration))


def as_version_2_before_friction(path, out):
    """A copy of result file `path` in the layout of format version 2 as it was before friction
    (docs/results-format.md, "Version 3"): a group per pair under /steps/<k>/contacts with its scalars as
    attributes, no friction attribute and no tangential datasets."""
    shutil.copy(path, out)
    with h5py.File(out, "r+") as f:
        f.attrs["format_version"] = np.int32(2)
        for k in f["steps"]:
            step = f["steps"][k]
            t = {key: item[()] for key, item in step["contacts"].items()}
            del step["contacts"]
            contacts = step.create_group("contacts")
            for p, name in enumerate(step.attrs["pair_names"]):
                name = name.decode() if isinstance(name, bytes) else str(name)
                rows = slice(int(t["offsets"][p]), int(t["offsets"][p + 1]))
                segs = slice(int(t["segment_offsets"][p]), int(t["segment_offsets"][p + 1]))
                g = contacts.create_group(name)
                for a in ("slave_body", "slave_edge", "master_body", "master_edge", "enforcement"):
                    g.attrs[a] = t[a][p].decode()
                g.attrs["theta"], g.attrs["force"], g.attrs["resultant"] = t["theta"][p], t["force"][p], t["resultant"][p]
                for d in ("node", "position", "normal", "arc_length", "weight", "gap", "normal_gap", "pressure",
                          "penetration", "active", "status"):
                    g[d] = t[d][rows]
                g["segments"] = t["segments"][segs] - rows.start
        del f["history/steps/tangential_force"]
    return out


def test_older_file(path, tmp):
    """A friction result as a file written before friction (format version 2): it reads and plots as
    frictionless."""
    old = as_version_2_before_friction(path, os.path.join(tmp, "before_friction.hdf"))
    result = cc.read_result(old)
    c = result["steps"][-1]["contacts"]["c"]
    check("older file: pair_friction is None", cc.results.pair_friction(c) is None, c["attrs"])
    check("older file: the pair's nodes read as in the file it came from",
          np.array_equal(c["pressure"], cc.read_result(path)["steps"][-1]["contacts"]["c"]["pressure"]))
    drawn = cc.plot_result(result, os.path.join(tmp, "before_friction.png"))
    check("older file: plotted without a tangential panel", not panels(drawn["figure"])[1]
          and drawn["friction"] == {}, drawn["friction"])
    # A file with the attribute but not the per-node datasets: the law in the legend, no curve, no span.
    with h5py.File(old, "r+") as f:
        last = f["steps"][str(f["steps"].attrs["count"] - 1)]
        last["contacts/c"].attrs["friction"] = "coulomb"
    drawn = cc.plot_result(cc.read_result(old), os.path.join(tmp, "partial.png"))
    tangential = panels(drawn["figure"])[1]
    check("a friction pair without its datasets: its panel with no final curve and no span",
          len(tangential) == 1 and not gid_lines(tangential[0], "tangential_traction") and not spans(tangential[0]),
          drawn["friction"])


def main():
    tmp = tempfile.mkdtemp(prefix="client-plot-friction-")
    with Server() as server:
        client = cc.Client(f"http://{HOST}:{server.port}")
        pushed, _ = solve(client, pushed_job(), tmp)
        tresca, _ = solve(client, tresca_job(), tmp)
        roller, roller_events = solve(client, roller_job(), tmp)
        flat, flat_events = solve(client, dict(example("flat_patch.json"), name="flat"), tmp)
    test_coulomb_steps(pushed)
    test_tresca(tresca)
    test_roller_events(roller, roller_events)
    test_frictionless(flat, flat_events)
    test_older_file(pushed, tmp)
    shutil.rmtree(tmp, ignore_errors=True)
    finish()


if __name__ == "__main__":
    main()
