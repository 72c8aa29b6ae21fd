#!/usr/bin/env python3
"""The Python client reads each contact pair as a joint (issue 48, item 4, in part): the result file's joint columns
(docs/results-format.md: centre_of_pressure, eccentricity, open_fraction, slip_fraction, friction_utilisation) in
ResultFile.pair's attrs, equal to what statics gives for a block on a base pushed sideways by a body force with a
history (the normal force's line of action moved by H 0.25 / W, friction carrying H), and contact_client.joint_results
derives the same from the pair's nodes (as it does for a file written before the columns).

contact-solve (CONTACT_BINARY_DIR) and Debian's python3-h5py/numpy; exits 1 on any failure."""
import json
import math
import os
import subprocess
import tempfile

from client_paths import SRC  # noqa: E402  (sets the import path)

import contact_client as cc  # noqa: E402
from checks import check, finish  # noqa: E402

BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))


def block(name, y0, y1):
    return {"name": name, "material": {"E": 3e10, "nu": 0.2, "density": 2500},
            "mesh": {"block": {"corners": [[0, y0], [1, y0], [1, y1], [0, y1]], "nx": 8, "ny": 4}}}


H = [0.0, 0.2, 0.4]
base = block("base", 0, 0.5)
base["boundary"] = [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]
top = block("block", 0.5, 1.0)
top["body_force"] = {"value": [25000, 0], "history": H}
job = {"name": "joints", "model": {"gravity": [0, -10]}, "loading": {"factors": [1, 1, 1]}, "bodies": [base, top],
       "contacts": [{"slave": "block.bottom", "master": "base.top", "friction": {"coefficient": 0.5}}]}

with tempfile.TemporaryDirectory() as tmp:
    path, out = os.path.join(tmp, "joints.json"), os.path.join(tmp, "joints.hdf")
    with open(path, "w") as f:
        json.dump(job, f)
    r = subprocess.run([os.path.join(BIN, "contact-solve"), "-q", path, "-o", out], capture_output=True, text=True,
                       timeout=120)
    check("solved", r.returncode == 0, r.stderr[-500:])
    with cc.ResultFile(out) as f:
        for k, h in enumerate(H):
            pair = f.pair(k, f.step(k)["pair_names"][0])
            a = pair["attrs"]
            check(f"step {k}: the centre of pressure at 0.5 + 0.25 H / W", abs(a["centre_of_pressure"] - (0.5 + 0.25 * h))
                  < 1e-8, a.get("centre_of_pressure"))
            check(f"step {k}: friction carries H: utilisation (H / W) / mu",
                  abs(a["friction_utilisation"] - h / 0.5) < 1e-8, a.get("friction_utilisation"))
            derived = cc.joint_results(pair)
            check(f"step {k}: joint_results from the nodes equals the columns",
                  all((math.isnan(derived[key]) and math.isnan(a[key])) or abs(derived[key] - a[key]) < 1e-12
                      for key in derived), (derived, {key: a[key] for key in derived}))

# The plot's default choice of panels: the joints that govern. A slipping joint (utilisation 1) and one about to
# hinge (|e| / (L/2) = 0.95) before a joint carrying more force at 0.3; an open joint (no force) last; among equals
# the larger force.
from contact_client.plot_select import choose_pairs, governing  # noqa: E402

attrs = {"slips": {"force": 1.0, "friction_utilisation": 1.0, "eccentricity": 0.1},
         "hinges": {"force": 2.0, "friction_utilisation": 0.2, "eccentricity": -0.95},
         "heavy": {"force": 50.0, "friction_utilisation": 0.3, "eccentricity": 0.0},
         "slips_more_force": {"force": 3.0, "friction_utilisation": 0.99999, "eccentricity": 0.0},
         "open": {"force": 0.0, "friction_utilisation": float("nan"), "eccentricity": float("nan")}}
scores = {n: governing(a) for n, a in attrs.items()}
check("governing: the larger of utilisation and |eccentricity|, 0 for an open joint",
      scores == {"slips": 1.0, "hinges": 0.95, "heavy": 0.3, "slips_more_force": 0.99999, "open": 0.0}, scores)
names = list(attrs)
drawn, matched, note = choose_pairs(names, None, 3, {n: a["force"] for n, a in attrs.items()}, None, scores)
check("the panels: the slipping joints (the larger force first among equals) and the hinging one, in the result's "
      "order", drawn == ["slips", "hinges", "slips_more_force"] and "govern" in note, (drawn, note))

finish()
