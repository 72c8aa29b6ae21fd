#!/usr/bin/env python3
"""A semicircular arch of 12 voussoirs under its own weight (issue 48, "Must show"): the solver finds its limit
thickness where the classical thrust-line argument puts it (tests/limit_jobs.py, computed independently:
Milankovitch's problem for these voussoirs), and below it names the classical five-hinge mechanism.

- The independent method first: for many voussoirs it gives Milankovitch's t/R = 0.1075 of the continuous arch
  (to 0.5 %).
- 0.3 % thicker than the limit the arch stands (contact-solve exits 0, converged); 0.3 % thinner it fails, and the
  verdict is statics' (no equilibrium), not the solver's: the mechanism is hinging, with four or five hinges, each
  at a springing's or the crown's extrados or at a haunch joint's intrados, where the limit thrust line touches.
- 1.2 times the limit thickness, pushed sideways by a live horizontal body force (a seismic coefficient lambda): the
  collapse analysis's mechanism is the elastic solution's own (read off its last increment and contact sets) and
  is the rigid blocks' statics' one, found independently by the linear program's dual: the same four hinges at the
  same points (where no joint slides, associated and Coulomb friction give the same mechanism).

Exits 1 on any failure."""
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(HERE, "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
CLI = os.path.join(BIN, "contact-solve")
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, ".."))  # tests/: checks.py
import limit_jobs as arch  # noqa: E402
from checks import check, finish  # noqa: E402

N = 12


def solve(t, tmp):
    """contact-solve on the arch of thickness t: (exit code, the final "result" summary of --progress ndjson)."""
    path = os.path.join(tmp, f"arch_{t:.6f}.json")
    with open(path, "w") as f:
        json.dump(arch.arch_job(N, t), f)
    r = subprocess.run([CLI, path, "-o", os.path.join(tmp, "arch.hdf"), "--progress", "ndjson"], capture_output=True,
                       text=True, timeout=300)
    lines = [json.loads(line) for line in r.stdout.splitlines() if line.startswith("{")]
    results = [line for line in lines if line.get("type") == "result"]
    return r.returncode, (results[-1] if results else {})


continuous = arch.limit_thickness(200)
check("the thrust-line method: 200 voussoirs give Milankovitch's t/R = 0.1075 to 0.5 %",
      abs(continuous - 0.1075) <= 0.005 * 0.1075, continuous)
t_min = arch.limit_thickness(N)
ok, ratio = arch.admits_thrust_line(N, t_min * 1.0001)
check("12 voussoirs: the limit line needs friction below the joints' 0.9 (no sliding: Heyman's assumption)",
      ok and ratio < 0.9, ratio)

with tempfile.TemporaryDirectory() as tmp:
    code, above = solve(1.003 * t_min, tmp)
    check("0.3 % above the limit thickness the arch stands", code == 0 and above.get("converged") is True,
          (code, above.get("message", "")[:300]))
    code, below = solve(0.997 * t_min, tmp)
    verdict = below.get("collapse") or {}
    mechanism = verdict.get("mechanism") or {}
    check("0.3 % below it the arch falls, and statics says so (no equilibrium, not the solver)",
          code != 0 and verdict.get("verdict") == "no_equilibrium" and "no equilibrium by statics" in
          below.get("message", ""), (code, verdict.get("verdict"), below.get("message", "")[-300:]))
    hinges = [j for j in mechanism.get("joints", []) if j.get("kind") == "hinge"]
    # (Below the limit no multiple of the weight is carried: every mechanism the weight moves is one, the
    # symmetric five-hinge one and the four-hinge ones alike; the statics names one of them.)
    check("the mechanism is hinging, with four or five hinges", mechanism.get("kind") == "hinging" and
          len(hinges) in (4, 5), mechanism.get("words"))
    # Where the classical line touches: the crown and springings (extrados), the haunches (intrados), mirrored.
    t = 0.997 * t_min
    radius = {"intrados": 1 - t / 2, "extrados": 1 + t / 2}
    expected = []
    for phi, side in arch.hinges_at_limit(N):
        for angle in {phi, math.pi - phi}:
            expected.append((radius[side] * math.cos(angle), radius[side] * math.sin(angle)))
    found = [tuple(j["point"]) for j in hinges]
    matched = all(min(math.dist(e, f) for e in expected) < 1e-9 for f in found)
    check("each hinge is where the limit thrust line touches: springings and crown outside, haunches inside",
          matched and len(found) >= 4, (sorted(expected), sorted(found)))

    job = arch.arch_job(N, 1.2 * t_min)
    for body in job["bodies"]:
        if body["name"].startswith("v"):
            body["body_force"] = {"value": [10, 0], "live": True}
    job["collapse"] = {}
    path = os.path.join(tmp, "arch_collapse.json")
    with open(path, "w") as f:
        json.dump(job, f)
    r = subprocess.run([CLI, path, "-o", os.path.join(tmp, "collapse.hdf"), "--progress", "ndjson"],
                       capture_output=True, text=True, timeout=300)
    results = [json.loads(line) for line in r.stdout.splitlines() if line.startswith('{')]
    results = [line for line in results if line.get("type") == "result"]
    c = (results[-1] if results else {}).get("collapse") or {}
    check("pushed sideways, the arch collapses below the statics bound", r.returncode == 0 and
          c.get("verdict") == "collapse" and c["failed"] <= c["statics_bound"] * (1 + c["tolerance"]),
          (r.returncode, c.get("words", r.stderr[-300:])))
    elastic, statics = c.get("mechanism") or {}, c.get("statics_mechanism") or {}

    def hinges_of(m):
        return sorted((j["pair"], tuple(round(x, 9) for x in j["point"])) for j in m.get("joints", [])
                      if j["kind"] == "hinge")

    check("its mechanism is the elastic solution's, checked admissible", elastic.get("source") == "elastic" and
          elastic.get("check", "").startswith("admissible"), (elastic.get("source"), elastic.get("check")))
    check("the elastic mechanism's four hinges are the statics' (the same joints, the same points)",
          elastic.get("kind") == statics.get("kind") == "hinging" and len(hinges_of(elastic)) == 4 and
          hinges_of(elastic) == hinges_of(statics), (elastic.get("words"), statics.get("words")))
    same_motion = all(
        any(b["body"] == s["body"] and abs(b["omega"] / elastic["bodies"][0]["omega"] -
                                           s["omega"] / statics["bodies"][0]["omega"]) <= 1e-6
            for s in statics.get("bodies", []))
        for b in elastic.get("bodies", [])) and len(elastic.get("bodies", [])) == len(statics.get("bodies", []))
    check("and the same motion: each body turning at the same rate relative to the first", same_motion,
          ([(b["body"], b["omega"]) for b in elastic.get("bodies", [])],
           [(b["body"], b["omega"]) for b in statics.get("bodies", [])]))

finish()
