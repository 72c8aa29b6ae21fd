#!/usr/bin/env python3
"""An adaptive run's result file: every adaptive step's meshes with refinement level and indicator per cell,
the step history, the XDMF sidecar stepping through them, and the VTKHDF view of the final step; and with the
default output of an adaptive job ("steps": "last"), the last step's fields alone with the whole step history.
Standard library plus Debian's python3-h5py and python3-numpy; exits non-zero on any failure."""
import json
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import h5py
import numpy as np

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
sys.path.insert(0, os.path.join(SRC, "tests"))  # checks.py
from checks import check, finish  # noqa: E402


with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "adaptive.hdf")
    r = subprocess.run([os.path.join(BIN, "contact-solve"), os.path.join(SRC, "api", "examples", "seed_layers_adaptive.json"),
                        "-o", out, "-q"], capture_output=True, text=True, timeout=300)
    check("the adaptive example converges", r.returncode == 0, r.stdout[-500:] + r.stderr)
    with h5py.File(out, "r") as f:
        steps = sorted(f["steps"].keys(), key=int)
        check("several adaptive steps are stored", len(steps) >= 3, str(steps))
        cells = []
        for k in steps:
            lower = f[f"steps/{k}/bodies/lower"]
            n = lower["quads"].shape[0]
            cells.append(n)
            check(f"step {k}: level per cell", lower["level"].shape == (n,), str(lower["level"].shape))
            check(f"step {k}: indicator per cell of the adapted body", "indicator" in lower and lower["indicator"].shape == (n,))
            check(f"step {k}: the upper body does not adapt", f[f"steps/{k}/bodies/upper/quads"].shape[0] == 256)
        check("the adapted mesh grows step by step", all(b > a for a, b in zip(cells, cells[1:])), str(cells))
        final = f[f"steps/{steps[-1]}/bodies/lower"]
        check("the final mesh is refined (levels above 0)", int(np.max(final["level"][:])) > 0)
        hs = f["history/steps"]
        check("/history/steps has one row per step", hs["step"].shape[0] == len(steps), str(hs["step"].shape))
        vtk = f["VTKHDF"]
        n_final = final["quads"].shape[0] + f[f"steps/{steps[-1]}/bodies/upper/quads"].shape[0]
        contacts = f[f"steps/{steps[-1]}/contacts"]
        n_lines = contacts["segments"].shape[0]  # every pair's segments, in one table
        check("VTKHDF holds the final step's cells and contact lines",
              list(vtk["NumberOfCells"][:]) == [f[f"steps/{steps[-1]}/bodies/upper/quads"].shape[0],
                                                 final["quads"].shape[0], n_lines], str(vtk["NumberOfCells"][:]))
        check("VTKHDF carries the refinement level", vtk["CellData/level"].shape[0] == n_final + n_lines)
    xmf = os.path.join(tmp, "adaptive.xmf")
    check("the XDMF sidecar is written", os.path.exists(xmf))
    if os.path.exists(xmf):
        root = ET.parse(xmf).getroot()
        times = [t.get("Value") for t in root.iter("Time")]
        text = open(xmf).read()
        check("the sidecar has one time per step", len(times) >= len(steps), f"{len(times)} times, {len(steps)} steps")
        check("the sidecar references every step's meshes",
              all(f"/steps/{k}/bodies/lower/quads" in text for k in steps))

    # The same job with its output left to the default of an adaptive job: the last step's fields only, the
    # same numbers, and the history of every step.
    with open(os.path.join(SRC, "api", "examples", "seed_layers_adaptive.json")) as f:
        job = json.load(f)
    del job["output"]
    path, last_out = os.path.join(tmp, "last.json"), os.path.join(tmp, "last.hdf")
    with open(path, "w") as f:
        json.dump(job, f)
    r = subprocess.run([os.path.join(BIN, "contact-solve"), path, "-o", last_out, "-q"], capture_output=True, text=True,
                       timeout=300)
    check("the adaptive example with the default output converges", r.returncode == 0, r.stdout[-500:] + r.stderr)
    with h5py.File(out, "r") as every, h5py.File(last_out, "r") as last:
        check("the default keeps one step's fields", list(last["steps"].keys()) == ["0"]
              and last["steps"].attrs["count"] == 1, list(last["steps"].keys()))
        check("it is the last step, by its history row", int(last["steps/0"].attrs["step"]) == len(steps) - 1,
              last["steps/0"].attrs.get("step"))
        for name in ("step", "elements", "dofs", "force", "contact_end"):
            check(f"/history/steps/{name} covers every step, as with every step kept",
                  np.array_equal(last["history/steps"][name][()], every["history/steps"][name][()]), name)
        for path_in in ("bodies/lower/points", "bodies/lower/displacement", "contacts/pressure"):
            check(f"its {path_in} is the last step's", np.array_equal(last["steps/0/" + path_in][()],
                                                                      every[f"steps/{steps[-1]}/" + path_in][()]))

finish()
