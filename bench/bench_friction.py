#!/usr/bin/python3
"""Friction against frictionless (issue 21) on the paper's test (api/examples/seed_layers.json with the default
method, exact contact by interface Newton) at nx x nx/4 elements per body: 512 x 128 (265k unknowns) and
1024 x 256 (1.05M), in four load steps (factors 0.25 ... 1), frictionless and with Coulomb friction mu = 0.3; as the paper has it (the upper
body's top held in x and y: both bodies held alike, the contact sticks everywhere) and with the top free in x (the
upper body's lateral expansion then differs from the lower one's, and the contact slips towards its edge). Prints
per row: wall time, solver time (wall - setup), peak memory, active-set / Newton steps per
load step, and the time ratio to the frictionless row of the same size, all measured in one run.

    bench/bench_friction.py [BUILD_DIR] [--sizes 512,1024]      (about 2 minutes on two cores)
"""
import json
import os
import re
import subprocess
import sys
import tempfile

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
args = [a for a in sys.argv[1:] if not a.startswith("--")]
BUILD = args[0] if args else os.path.join(SRC, "build")
CLI = os.path.join(BUILD, "contact-solve")
SIZES = [512, 1024]
for a in sys.argv[1:]:
    if a.startswith("--sizes="):
        SIZES = [int(x) for x in a.split("=", 1)[1].split(",")]
STEPS = 4


def job(nx, friction, top_free_in_x=False):
    j = json.load(open(os.path.join(SRC, "api", "examples", "seed_layers.json")))
    j.pop("solver", None)  # the default method: interface Newton, exact contact
    for b in j["bodies"]:
        b["mesh"]["block"]["nx"] = nx
        b["mesh"]["block"]["ny"] = nx // 4
    j["loading"] = {"factors": [(k + 1) / STEPS for k in range(STEPS)]}
    if friction:
        j["contacts"][0]["friction"] = {"coefficient": 0.3}
    if top_free_in_x:
        for c in j["bodies"][0]["boundary"]:
            if c.get("edge") == "top":
                c["displacement"].pop("x")
    return j


def run(j, tmp):
    path = os.path.join(tmp, "job.json")
    json.dump(j, open(path, "w"))
    cmd = ["/usr/bin/time", "-f", "maxrss_kb %M", CLI, path, "-o", os.path.join(tmp, "out.hdf")]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    if r.returncode not in (0,):
        return None, (r.stdout[-400:] + r.stderr[-400:]).strip()
    m = re.search(r"stop: \S+ after (\d+) steps?, ([0-9.]+) s \(setup ([0-9.]+) s\)", r.stdout)
    rss = int(re.search(r"maxrss_kb (\d+)", r.stderr).group(1)) / 1024
    stick = re.findall(r"(\d+) of (\d+) nodes in contact sticking", r.stdout)
    return {"steps": int(m.group(1)), "wall": float(m.group(2)), "setup": float(m.group(3)), "mb": rss,
            "stick": stick[-1] if stick else None}, None


def main():
    print(f"{'size':>10} {'case':>24} {'unknowns':>9} {'wall s':>7} {'solve s':>8} {'MB':>6} {'steps/load step':>16}"
          f" {'solve ratio':>11}  stick")
    with tempfile.TemporaryDirectory() as tmp:
        for nx in SIZES:
            unknowns = 2 * 2 * (nx + 1) * (nx // 4 + 1)
            for name, friction, free in [("frictionless", False, False), ("coulomb 0.3", True, False),
                                         ("top free: frictionless", False, True), ("top free: coulomb 0.3", True, True)]:
                if not friction:
                    base = None
                f, err = run(job(nx, friction, free), tmp)
                if f is None:
                    print(f"{nx}x{nx // 4:<5} {name:>24}  failed: {err}")
                    continue
                solve = f["wall"] - f["setup"]
                base = solve if base is None else base
                stick = f"{f['stick'][0]} of {f['stick'][1]}" if f["stick"] else "-"
                print(f"{nx}x{nx // 4:<5} {name:>24} {unknowns:>9} {f['wall']:>7.2f} {solve:>8.2f} {f['mb']:>6.0f}"
                      f" {f['steps'] / STEPS:>16.2f} {solve / base:>11.2f}  {stick}", flush=True)


if __name__ == "__main__":
    main()
