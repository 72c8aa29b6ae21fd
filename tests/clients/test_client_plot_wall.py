#!/usr/bin/env python3
"""The client's plot for many bodies and for load paths (issue 31, item 3). A 22 x 22 frictional masonry wall (496
bodies, 946 pairs, two load steps: the precompression, then a shear through the top bricks' `history`, load factor
1 in both), a shrink fit (api/examples/shrink_fit.json: a ring on a shaft, interference by gap.constant) and a half
cylinder pushed sideways in three steps are solved by contact-solve and plotted by the client:

- the wall's `plot` as a command stays under 500 MB (the child's own peak RSS, os.wait4), ends (its time printed,
  bounded only against a hang or a return to reading the whole file), and writes a 1200 x 900 PNG that is drawn on
  (pixel variance, not mostly black); it draws at most 4 pair panels and says how to choose others;
- --pairs / pairs= draws exactly the pairs its patterns select (by pair name, or by slave or master body name,
  fnmatch on the file's names); a pattern that matches nothing is a usage error listing the pairs;
- the overview colours each slave node's stretch by its state: the numbers of stick, slip, open and outside nodes
  in the figure's joint lines equal those counted from the file's `status`, `active` and `stick`;
- the load history of the history-driven wall has one point per step in every line; the base's supports carry
  the top pressure 2 x 22 x 0.24 = 10.56 upwards in both steps and the shear 0.3 x 10.56 sideways in the second;
- the slip of each step and the stick zone of each step (bars) of the pushed cylinder are the file's;
- the shrink fit's pressure is drawn against the angle about the ring's centre (0, 0): the final profile's
  abscissae are atan2(y, x) of the slave nodes to 1e-6 rad (1e-6 of the radius along the arc); its magnification
  draws the ring and the shaft touching where they are in contact (within 1 px, measured between the displaced
  nodes of the two meshes), where the plain 4 % rule would draw them apart, and the figure says so.

Standard library + Debian's numpy, h5py, matplotlib. Prints "N passed, M failed"; exits 1 on any failure."""
import fnmatch
import os
import shutil
import subprocess
import sys
import tempfile
import time

from client_paths import CLIENT, EXAMPLES, SRC  # noqa: E402  (sets the import path)

import h5py  # noqa: E402
import numpy as np  # noqa: E402

import contact_client as cc  # noqa: E402
from harness import CONTACT_SOLVE  # noqa: E402
from checks import check, finish, section  # noqa: E402
from test_client_plot_friction import pushed_job  # noqa: E402

ROWS = BRICKS = 22
SHEAR = 0.3
PRESSURE, LENGTH = 2.0, 0.24  # scripts/make_brick_wall.py: the top pressure and the brick's length
# The plot reads only what it draws: 5-8 s and 130 MB for this wall; reading the whole file, a 16 x 16 wall took
# 238 s and 857 MB. The memory bound tells the two apart on any machine; the time bound, 15-20 times the normal
# time, is broken only by a hang or that return (tests run on loaded 2-core machines; the time is printed).
TIME_LIMIT, MEMORY_LIMIT = 120.0, 500 * 1024 * 1024


def solve(job_path, out):
    r = subprocess.run([CONTACT_SOLVE, job_path, "-o", out, "-q"], capture_output=True, text=True, timeout=300)
    check(f"{os.path.basename(job_path)} solves", r.returncode == 0 and os.path.exists(out), r.stderr[-2000:])
    return out


def make_wall(tmp):
    job = os.path.join(tmp, "wall.json")
    r = subprocess.run([sys.executable, os.path.join(SRC, "scripts", "make_brick_wall.py"), "--rows", str(ROWS),
                        "--bricks", str(BRICKS), "--friction", "0.6", "--shear", str(SHEAR), "-o", job],
                       capture_output=True, text=True, timeout=60)
    check("the 22 x 22 wall is written", r.returncode == 0, r.stderr)
    return solve(job, os.path.join(tmp, "wall.hdf"))


def final_group(f):
    return f["steps"][str(f["steps"].attrs["count"] - 1)]


def timed_plot(*args):
    """The client's plot as a command: (exit code, stdout, stderr, wall seconds, the child's peak RSS in bytes)."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        t0 = time.monotonic()
        p = subprocess.Popen([sys.executable, CLIENT, "plot", *args], stdout=out, stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
        seconds = time.monotonic() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        return p.returncode, out.read(), err.read(), seconds, usage.ru_maxrss * 1024  # Linux: kilobytes


def check_png(name, path, size):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    if not check(f"{name}: PNG written", os.path.exists(path) and os.path.getsize(path) > 0, path):
        return
    img = mpimg.imread(path)[:, :, :3]
    check(f"{name}: {size[0]} x {size[1]} pixels", img.shape[:2] == (size[1], size[0]), img.shape)
    check(f"{name}: not uniform (pixel variance)", float(img.std()) > 0.05, img.std())
    dark = float((img.max(axis=2) < 0.2).mean())
    check(f"{name}: not mostly black ({dark:.2%} dark pixels)", dark < 0.2, dark)
    colours = len(np.unique((img.reshape(-1, 3) * 255).astype(np.uint8), axis=0))
    check(f"{name}: coloured ({colours} colours)", colours > 50, colours)


def test_wall_command(hdf, tmp):
    png = os.path.join(tmp, "wall.png")
    code, out, err, seconds, rss = timed_plot(hdf, "-o", png)
    print(f"wall plot: {seconds:.1f} s, {rss / 2**20:.0f} MB", flush=True)
    check("wall plot: exit 0", code == 0, out + err)
    check(f"wall plot: no hang, nor the whole file read ({seconds:.1f} s measured; bound {TIME_LIMIT:g} s)",
          seconds < TIME_LIMIT, seconds)
    check(f"wall plot: under {MEMORY_LIMIT / 2**20:.0f} MB ({rss / 2**20:.0f} MB)", rss < MEMORY_LIMIT, rss)
    check_png("wall plot", png, (1200, 900))
    drawn = [line for line in out.splitlines() if ": pressure drawn from" in line]
    check("wall plot: at most 4 pair panels, and it says how to choose others",
          0 < len(drawn) <= cc.plot.MAX_PAIRS and "946 pairs" in out and "--pairs" in out, out)
    check("wall plot: prints the overview's joint states and the load history",
          "overview: 496 bodies, 946 pairs" in out and "load history: 2 steps" in out, out)
    code, out, err, _, _ = timed_plot(hdf, "-o", png, "--pairs", "no_such_pair*")
    check("--pairs that matches nothing: usage error (exit 2) naming the pattern and the pairs",
          code == 2 and err.startswith("error: no pair matches no_such_pair*") and "b0_0.bottom-base.top" in err
          and "(946 in all)" in err and "Traceback" not in err, (code, err))


def file_counts(f):
    """Slave nodes per state over every pair of the final step, from the file's arrays."""
    counts = dict.fromkeys(("outside", "open", "stick", "slip", "contact"), 0)
    c = final_group(f)["contacts"]  # every pair's nodes in one table; `pair` is each row's pair
    status, active, stick = c["status"][()], c["active"][()] == 1, c["stick"][()] == 1
    frictional = (c["friction"].asstr()[()] != "none")[c["pair"][()]]
    outside = np.isin(status, (1, 2, 3))
    counts["outside"] += int(outside.sum())
    counts["open"] += int((~outside & ~active).sum())
    counts["stick"] += int((~outside & active & frictional & stick).sum())
    counts["slip"] += int((~outside & active & frictional & ~stick).sum())
    counts["contact"] += int((~outside & active & ~frictional).sum())
    return counts


def figure_counts(fig):
    """Slave nodes per state in the overview's joint lines (one line per node, told apart by its colour)."""
    import matplotlib.colors
    lines = [c for ax in fig.axes for c in ax.collections if c.get_gid() == "joints"]
    if len(lines) != 1:
        return None
    colours = [tuple(np.round(c, 6)) for c in lines[0].get_colors()]
    out = {}
    for state, name in cc.plot_wall.JOINT_COLOURS.items():
        rgba = tuple(np.round(matplotlib.colors.to_rgba(name), 6))
        out[state] = sum(1 for c in colours if c == rgba)
    return out


def test_wall_module(hdf, tmp):
    with h5py.File(hdf, "r") as f:
        last = final_group(f)
        names = [str(n) for n in last.attrs["pair_names"]]
        slave_of = dict(zip(names, last["contacts/slave_body"].asstr()[()]))  # a row per pair
        counts = file_counts(f)
        rows = len(f["history/steps/load_factor"])
    patterns = ["b0_3.bottom-base.*", "b21_0"]  # a pair by its name, a brick by its name
    want = [n for n in names if fnmatch.fnmatchcase(n, patterns[0]) or slave_of[n] == "b21_0"]
    drawn = cc.plot_result(hdf, os.path.join(tmp, "chosen.png"), pairs=",".join(patterns))
    fig = drawn["figure"]
    panels = [ax for ax in fig.axes if ax.get_ylabel() == "contact pressure"]
    check("pairs='b0_3.bottom-base.*,b21_0': exactly the pairs they select drawn, one panel each",
          len(want) == 2 and drawn["pairs"] == want and drawn["pairs_matched"] == want and len(panels) == 2
          and all(name in ax.get_title() for name, ax in zip(want, panels)), (want, drawn["pairs"]))
    check("all pairs drawn that match: no note on the choice", drawn["pairs_note"] == "", drawn["pairs_note"])
    try:
        cc.plot_result(hdf, os.path.join(tmp, "none.png"), pairs="nothing_like_this")
        raised = None
    except cc.BadInput as exc:
        raised = str(exc)
    check("a pattern that matches nothing: BadInput listing some pair names and their number",
          raised is not None and "nothing_like_this" in raised and names[0] in raised and "946 in all" in raised,
          raised)
    check("many bodies: the overview replaces the mesh row", drawn["overview"] is not None
          and drawn["overview"]["bodies"] == 496 and drawn["overview"]["pairs"] == 946, drawn["overview"])
    shown = figure_counts(fig)
    check(f"overview: the joint lines' states are the file's ({counts})",
          shown is not None and all(shown[s] == counts[s] for s in counts) and counts["stick"] > 0
          and counts["slip"] > 0, (shown, counts))
    check("overview: the legend counts the nodes of each state",
          drawn["overview"]["nodes"] == dict(counts, contact=0) or drawn["overview"]["nodes"] == counts,
          drawn["overview"]["nodes"])
    check_load_history(drawn, fig, rows)


def check_load_history(drawn, fig, rows):
    path = drawn["load_path"]
    check("history-driven wall (load factor 1 in both steps): a load history against the step, one point per step",
          path is not None and path["x_label"] == "step" and len(path["x"]) == rows == 2
          and list(path["load_factor"]) == [1.0, 1.0], path and path["x"])
    lines = [line for ax in fig.axes for line in ax.get_lines() if line.get_gid() == "load_path"]
    check("load history: every line drawn has one point per step",
          len(lines) >= 3 and all(len(line.get_xdata()) == rows for line in lines), [len(x.get_xdata()) for x in lines])
    base = (path or {}).get("reaction", {}).get("base") if path and path["reaction"] else None
    vertical = PRESSURE * BRICKS * LENGTH
    check(f"load history: the base's supports carry {vertical:g} up in both steps, {SHEAR * vertical:g} sideways "
          "from step 1 (statics)", base is not None and np.allclose(base[:, 1], [vertical, vertical], rtol=1e-6)
          and np.allclose(base[:, 0], [0.0, -SHEAR * vertical], rtol=1e-6, atol=1e-9 * vertical), base)


def test_pushed_steps(tmp):
    import json
    job = os.path.join(tmp, "pushed.json")
    with open(job, "w") as f:
        json.dump(pushed_job(), f)
    result = cc.read_result(solve(job, os.path.join(tmp, "pushed.hdf")))
    drawn = cc.plot_result(result, os.path.join(tmp, "pushed.png"))
    fig, steps = drawn["figure"], result["steps"]
    slip_axes = [ax for ax in fig.axes if ax.get_ylabel() == "slip"]
    check("pushed: one slip panel", len(slip_axes) == 1, len(slip_axes))
    if slip_axes:
        curves = [line for line in slip_axes[0].get_lines() if line.get_gid() is None and len(line.get_xdata()) > 2]
        final = [line for line in slip_axes[0].get_lines() if line.get_gid() == "slip"]
        check("pushed: a slip curve per step, each the step's slip", len(curves) == len(steps) == 3
              and all(np.array_equal(np.asarray(line.get_ydata(), float), cc.plot.slip(s["contacts"]["c"]),
                                     equal_nan=True) for line, s in zip(curves, steps)), len(curves))
        check("pushed: the final slip from the file", len(final) == 1 and np.array_equal(
            np.asarray(final[0].get_ydata(), float), cc.plot.slip(steps[-1]["contacts"]["c"]), equal_nan=True))
    per_step = drawn["stick_zones_per_step"].get("c", [])
    check("pushed: a stick zone for each step", [k for k, _ in per_step] == [0, 1, 2], per_step)
    bars = {}
    for ax in fig.axes:
        for coll in ax.collections:
            if coll.get_gid() == "stick_step":
                for path in coll.get_paths():
                    v = path.vertices
                    bars.setdefault(int(round(v[:, 1].mean())), []).append((v[:, 0].min(), v[:, 0].max()))
    for k, step in enumerate(steps):
        c = step["contacts"]["c"]
        s, stick = np.asarray(c["arc_length"], float), np.asarray(c["stick"]) == 1
        inside = [any(lo - 1e-12 <= x <= hi + 1e-12 for lo, hi in bars.get(k, [])) for x in s]
        check(f"pushed, step {k}: its bars cover its sticking nodes and no other", stick.any()
              and list(inside) == list(stick), (bars.get(k), s[stick]))
    zones = [z for _, z in per_step]
    check("pushed: the stick zone moves from step to step (the figure shows each)", len({tuple(z) for z in zones}) > 1,
          zones)


def test_shrink_fit(tmp):
    hdf = solve(os.path.join(EXAMPLES, "shrink_fit.json"), os.path.join(tmp, "shrink_fit.hdf"))
    result = cc.read_result(hdf)
    drawn = cc.plot_result(result, os.path.join(tmp, "shrink_fit.png"))
    final = result["steps"][-1]
    check("shrink fit: both pairs drawn against the angle (auto: a circular, conforming contact over 45 degrees)",
          drawn["along"] == {p: "angle" for p in final["pair_names"]}, drawn["along"])
    panels = [ax for ax in drawn["figure"].axes if ax.get_ylabel() == "contact pressure"]
    worst = 0.0
    for ax in panels:
        pair = next(p for p in final["pair_names"] if ax.get_title().startswith(p))
        c = final["contacts"][pair]
        line = next(x for x in ax.get_lines() if str(x.get_label()).startswith("final"))
        expected = np.degrees(np.arctan2(c["position"][:, 1], c["position"][:, 0]))
        worst = max(worst, float(np.max(np.abs(np.radians(np.asarray(line.get_xdata(), float) - expected)))))
    check(f"shrink fit: the abscissae are atan2 about (0, 0) to 1e-6 rad ({worst:.1e})", len(panels) == 2
          and worst < 1e-6, worst)
    check("shrink fit: the axis says degrees", all("degrees" in ax.get_xlabel() for ax in panels))
    check_no_false_gap(result, drawn)


def displayed_gap(final, warp):
    """The largest radial distance between the displaced ring (slave nodes in contact) and the displaced shaft
    (its nodes on r = 500, joined by straight lines), with the displacement times warp."""
    shaft, ring = final["bodies"]["shaft"], final["bodies"]["ring"]
    xy = shaft["points"] + warp * shaft["displacement"]
    on = np.abs(np.hypot(*shaft["points"].T) - 500.0) < 1e-6
    angle = np.arctan2(xy[on, 1], xy[on, 0])
    order = np.argsort(angle)
    angle, master = angle[order], xy[on][order]
    worst = 0.0
    for c in final["contacts"].values():
        nodes = np.asarray(c["node"])[np.asarray(c["active"]) == 1]
        p = ring["points"][nodes] + warp * ring["displacement"][nodes]
        for q in p:
            a = np.arctan2(q[1], q[0])
            i = int(np.clip(np.searchsorted(angle, a), 1, len(angle) - 1))
            m0, m1 = master[i - 1], master[i]
            t = np.cross(m1 - m0, q - m0) / np.linalg.norm(m1 - m0)  # signed distance from the chord (outwards)
            worst = max(worst, float(-t))
    return worst


def check_no_false_gap(result, drawn):
    final = result["steps"][-1]
    warp, ppu = drawn["warp"], drawn["mesh_pixels_per_unit"]
    plain = cc.plot.auto_warp(final)
    check("shrink fit: the plain 4 % rule would draw the closed fit open by more than 5 px",
          displayed_gap(final, plain) * ppu > 5, (plain, displayed_gap(final, plain) * ppu))
    gap = displayed_gap(final, warp) * ppu
    check(f"shrink fit: the magnification chosen (x {warp:g}) draws the contact closed (gap {gap:.2f} px <= 1)",
          0 < warp < plain and gap <= 1.0, (warp, gap))
    texts = [t.get_text() for t in drawn["figure"].texts if t.get_gid() == "magnification"]
    check("shrink fit: the figure states the magnification and why it was lowered",
          len(texts) == 1 and cc.plot.warp_text(warp) in texts[0] and f"x {plain:g} would draw" in texts[0]
          and drawn["warp_note"] in texts[0], texts)


def main():
    tmp = tempfile.mkdtemp(prefix="client-plot-wall-")
    with section("22 x 22 wall"):
        hdf = make_wall(tmp)
        test_wall_command(hdf, tmp)
        test_wall_module(hdf, tmp)
    with section("pushed cylinder"):
        test_pushed_steps(tmp)
    with section("shrink fit"):
        test_shrink_fit(tmp)
    shutil.rmtree(tmp, ignore_errors=True)
    finish()


if __name__ == "__main__":
    main()
