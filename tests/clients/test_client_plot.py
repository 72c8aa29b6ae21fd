#!/usr/bin/env python3
"""The client's plot shows the contact (issue 23, item 6): a small contact zone (api/examples/hertz_cylinder.json,
whose contact is about 1/23 of the slave edge) solved by contactd and plotted by the client fills most of its
pressure panel's horizontal axis (read back from the figure), as a module and as a command, against arc length
(the web page's coordinate) and against x; --xlim LO HI sets exactly those limits, --xlim full gives the whole
edge back, a malformed --xlim is a usage error; the mesh row has a zoom around the contact; cell edges fade on
cells too small on screen to show them.

Starts contactd through tests/server/harness.py. Standard library + Debian's numpy, h5py, matplotlib. Prints
"N passed, M failed"; exits 1 on any failure."""
import os
import re
import subprocess
import sys
import tempfile

from client_paths import CLIENT, EXAMPLES, HERE, SRC  # noqa: E402,F401  (sets the import path)

import numpy as np  # noqa: E402

import contact_client as cc  # noqa: E402
from harness import HOST, Server  # noqa: E402
from checks import check, finish  # noqa: E402

PAIR = "upper.bottom-lower.top"
MOST = 0.6  # "shows it across most of the axis": the contact zone spans more than 60 % of the panel's axis


def solve(client, tmp):
    """hertz_cylinder solved by contactd: (the result read back, its events)."""
    events = []
    job = client.submit(os.path.join(EXAMPLES, "hertz_cylinder.json"))
    final = client.wait(job["id"], on_event=events.append)
    check("hertz_cylinder: SUCCEEDED", final.get("state") == "SUCCEEDED", final)
    path = os.path.join(tmp, "hertz_cylinder.hdf")
    client.download(job["id"], path)
    return cc.read_result(path), events


def fill(zone, xlim):
    """The fraction of the axis xlim (lo, hi) that the contact zone (lo, hi) spans."""
    return (min(zone[1], xlim[1]) - max(zone[0], xlim[0])) / (xlim[1] - xlim[0])


def test_default_zoom(result, events, tmp):
    c = result["steps"][-1]["contacts"][PAIR]
    on = c["pressure"] > 0
    for along, s in (("arc", c["arc_length"]), ("x", c["x"])):
        for with_events in (False, True):
            name = f"along {along}" + (", with the events" if with_events else "")
            drawn = cc.plot_result(result, os.path.join(tmp, f"{along}{with_events}.png"),
                                   events=events if with_events else None, along=along)
            xlim, zone = drawn["pressure_xlim"][PAIR], drawn["contact_zone"][PAIR]
            edge = float(s.max() - s.min())
            check(f"{name}: the contact is a small part of the slave edge (< 1/10)",
                  zone is not None and (zone[1] - zone[0]) < edge / 10, (zone, edge))
            check(f"{name}: the contact zone is that of the final pressure (> 0)",
                  zone == (float(s[on].min()), float(s[on].max())), (zone, s[on].min(), s[on].max()))
            check(f"{name}: the contact zone spans more than {MOST:.0%} of the pressure axis",
                  zone is not None and xlim[0] <= zone[0] and zone[1] <= xlim[1] and fill(zone, xlim) > MOST,
                  (xlim, zone))
            check(f"{name}: the open nodes beyond the contact show (3 of them)",
                  np.sum((s > zone[1]) & (s <= xlim[1])) >= 3, (xlim, zone))
    box = drawn["mesh_zoom"]
    p = c["position"][on]
    mesh = np.concatenate([b["points"] for b in result["steps"][-1]["bodies"].values()])
    check("the mesh row zooms on the contact: the box holds the nodes in contact, at least 3 times smaller "
          "than the mesh", box is not None and box[0] <= p[:, 0].min() and p[:, 0].max() <= box[1]
          and box[2] <= p[:, 1].min() <= box[3] and 3 * (box[1] - box[0]) <= np.ptp(mesh, axis=0).max(), box)


def test_xlim(result, tmp):
    drawn = cc.plot_result(result, os.path.join(tmp, "xlim.png"), xlim=(0.05, 0.2))
    check("xlim=(0.05, 0.2) sets exactly those limits", drawn["pressure_xlim"][PAIR] == (0.05, 0.2),
          drawn["pressure_xlim"])
    s = result["steps"][-1]["contacts"][PAIR]["arc_length"]
    drawn = cc.plot_result(result, os.path.join(tmp, "full.png"), xlim="full")
    lo, hi = drawn["pressure_xlim"][PAIR]
    check("xlim='full': the whole slave edge", lo <= s.min() and s.max() <= hi and hi - lo < 1.2 * np.ptp(s),
          (lo, hi, s.min(), s.max()))
    check("xlim='full': no zoom in the mesh row", drawn["mesh_zoom"] is None, drawn["mesh_zoom"])


def run(*args):
    return subprocess.run([sys.executable, CLIENT, *args], capture_output=True, text=True, timeout=120)


def test_cli(hdf, tmp):
    png = os.path.join(tmp, "cli.png")
    r = run("plot", hdf, "-o", png)
    m = re.search(rf"{re.escape(PAIR)}: pressure drawn from arc length (\S+) to (\S+), contact from (\S+) to (\S+)",
                  r.stdout)
    check("cli plot: exit 0, prints the drawn range and the contact zone", r.returncode == 0 and m is not None,
          r.stdout + r.stderr)
    if m:
        lo, hi, zlo, zhi = map(float, m.groups())
        check(f"cli plot: the contact zone spans more than {MOST:.0%} of the axis",
              fill((zlo, zhi), (lo, hi)) > MOST, m.groups())
    r = run("plot", hdf, "-o", png, "--xlim", "-0.1", "0.25", "--along", "x")
    check("cli plot --xlim -0.1 0.25 --along x: exactly those limits",
          r.returncode == 0 and f"{PAIR}: pressure drawn from x -0.1 to 0.25," in r.stdout, r.stdout + r.stderr)
    r = run("plot", hdf, "-o", png, "--xlim", "full")
    check("cli plot --xlim full: exit 0", r.returncode == 0, r.stdout + r.stderr)
    for bad in (["1"], ["2", "1"], ["a", "b"], ["0", "1", "2"]):
        r = run("plot", hdf, "-o", png, "--xlim", *bad)
        check(f"cli plot --xlim {' '.join(bad)}: usage error (exit 2, one line)",
              r.returncode == 2 and r.stderr.startswith("error: --xlim") and "Traceback" not in r.stderr,
              (r.returncode, r.stderr))


def test_edges():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    cells = np.stack([square * size for size in (1.0, 2.0, 5.0, 8.0, 20.0)])
    alpha = cc.plot._edge_opacity(cells, pixels_per_unit=1.0)
    check("cell edges: none on cells up to 2 px, growing to 0.7 from 8 px",
          np.allclose(alpha, [0, 0, 0.35, 0.7, 0.7]), alpha)
    strip = square * [2.0, 40.0]  # 2 px wide, 40 px tall
    triangle = np.array([[0, 0], [20, 0], [0, 20], [0, 0]], dtype=float)  # a triangle repeats its first corner
    alpha = cc.plot._edge_opacity(np.stack([strip, triangle]), pixels_per_unit=1.0)
    check("cell edges: a cell's size is its narrower side (a 2 px strip has none), triangles included",
          alpha[0] == 0 and 0 < alpha[1] <= 0.7, alpha)


def main():
    tmp = tempfile.mkdtemp(prefix="client-plot-")
    with Server() as server:
        result, events = solve(cc.Client(f"http://{HOST}:{server.port}"), tmp)
    test_default_zoom(result, events, tmp)
    test_xlim(result, tmp)
    test_cli(os.path.join(tmp, "hertz_cylinder.hdf"), tmp)
    test_edges()
    finish()


if __name__ == "__main__":
    main()
