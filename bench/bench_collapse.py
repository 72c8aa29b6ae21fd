#!/usr/bin/env python3
"""The collapse analysis's cost (issue 48, "Benchmark"): for the arch (12 voussoirs at 1.2 times its limit thickness,
gravity dead, a horizontal body force live), the column (three blocks, a horizontal body force live: overturning),
the 68-stone wall (api/examples/masonry_wall.json: its precompression dead, its top shear live) and the generator's
walls (make_brick_wall.py --head-joints --friction 0.6 --collapse: 8 x 8 and 22 x 22, and 6 x 6 of 2:1 stones,
which fail by rocking below the statics bound): lambda_c, its bracket, the statics bound, the trial solves (those
of the bisection), the wall time, and the cost of the last held trial against the first (at half the statics
bound: a step far from the limit), in iterations and seconds. Against each, a plain solve of the same wall (the
22 x 22 at H/V 0.3: the issue's yardstick), and the ratio.

    bench/bench_collapse.py [BUILD_DIR] [--quick] [--verbose]
      --quick: without the 22 x 22 wall; --verbose: each mechanism in words, and its check

Prints a table; ratios from one run (the machine is noisy). Needs h5py (Debian's python3-h5py)."""
import json
import os
import subprocess
import sys
import tempfile
import time

import h5py

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.join(HERE, "..")
args = [a for a in sys.argv[1:] if not a.startswith("--")]
QUICK = "--quick" in sys.argv
VERBOSE = "--verbose" in sys.argv
BUILD = args[0] if args else os.path.join(SRC, "build")
CLI = os.path.join(BUILD, "contact-solve")
sys.path.insert(0, os.path.join(SRC, "tests"))
import limit_jobs as arch  # noqa: E402


def solve(job, tmp, name):
    path = os.path.join(tmp, name + ".json")
    with open(path, "w") as f:
        json.dump(job, f)
    out = os.path.join(tmp, name + ".hdf")
    start = time.monotonic()
    r = subprocess.run([CLI, path, "-o", out, "-q"], capture_output=True, text=True, timeout=3600)
    seconds = time.monotonic() - start
    if not os.path.exists(out):
        return None, seconds, r.stderr[-300:]
    with h5py.File(out, "r") as f:
        if "collapse" not in f:
            return {}, seconds, ""
        g = f["collapse"]
        c = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in g.attrs.items()}
        t = g["trials"]
        c["trials"] = list(zip(t["multiplier"][()], t["held"][()], t["iterations"][()], t["seconds"][()]))
        m = g["mechanism"].attrs
        c["kind"] = m["kind"] + (" (" + m["source"] + ")" if "source" in m else "")
        c["words"] = m["words"]
        c["check"] = m.get("check", "")
        if "statics_mechanism" in g:
            c["statics_kind"] = g["statics_mechanism"].attrs["kind"]
    os.remove(out)
    return c, seconds, ""


def wall(n, tmp, *options):
    path = os.path.join(tmp, f"wall{n}.json")
    subprocess.run([sys.executable, os.path.join(SRC, "scripts", "make_brick_wall.py"), "--rows", str(n), "--bricks",
                    str(n), "--head-joints", "--friction", "0.6", *options, "-o", path], check=True,
                   capture_output=True)
    with open(path) as f:
        return json.load(f)


def masonry_collapse():
    with open(os.path.join(SRC, "api", "examples", "masonry_wall.json")) as f:
        job = json.load(f)
    job["loading"] = {"steps": 1}
    for b in job["bodies"]:
        for c in b["boundary"]:
            c.pop("history", None)
            if "vertex" in c:  # the shear at the top bricks' corners: live
                c["live"] = True
    job["collapse"] = {}
    return job


def arch_collapse():
    t = 1.2 * arch.limit_thickness(12)
    job = arch.arch_job(12, t)
    for b in job["bodies"]:
        if b["name"].startswith("v"):
            b["body_force"] = {"value": [10, 0], "live": True}
    job["collapse"] = {}
    return job


def main():
    cases = [("arch 12 voussoirs, t = 1.2 t_min", arch_collapse(), None),
             ("column of 3 blocks", arch.column(nx=8), None),
             ("68-stone wall (masonry_wall)", masonry_collapse(), None)]
    with tempfile.TemporaryDirectory() as tmp:
        cases.append(("8 x 8 wall", wall(8, tmp, "--collapse"), wall(8, tmp, "--shear", "0.3")))
        cases.append(("6 x 6 wall, 2:1 stones", wall(6, tmp, "--collapse", "--brick-height", "0.12"),
                      wall(6, tmp, "--shear", "0.3", "--brick-height", "0.12")))
        if not QUICK:
            cases.append(("22 x 22 wall", wall(22, tmp, "--collapse"), wall(22, tmp, "--shear", "0.3")))
        print(f"{'case':<34} {'verdict':>8} {'lambda_c':>9} {'bracket':>19} {'bound':>7} {'solves':>6} "
              f"{'bisect':>6} {'time s':>7} {'plain s':>7} {'ratio':>6} {'last/first it.':>14} {'last/first s':>12} "
              f"{'mechanism':>21} {'statics':>11}", flush=True)
        for label, job, plain in cases:
            c, seconds, error = solve(job, tmp, "case")
            if not c:
                print(f"{label:<34} failed: {error}", flush=True)
                continue
            plain_s = solve(plain, tmp, "plain")[1] if plain else float("nan")
            held_trials = [t for t in c["trials"] if t[1]]
            first, last = held_trials[0], held_trials[-1]
            mid = 0.5 * (c["held"] + c["failed"])
            print(f"{label:<34} {c['verdict']:>8} {mid:>9.4f} [{c['held']:.5f}, {c['failed']:.5f}] "
                  f"{c['statics_bound']:>7.4f} {c['solves']:>6} {c['bracket_solves']:>6} {seconds:>7.2f} "
                  f"{plain_s:>7.2f} {seconds / plain_s if plain else float('nan'):>6.1f} "
                  f"{last[2]:>6}/{first[2]:<7} {last[3]:>5.2f}/{first[3]:<6.2f} {c['kind']:>21} "
                  f"{c.get('statics_kind', ''):>11}", flush=True)
            if VERBOSE:
                print(f"    mechanism: {c['words']}\n    check: {c['check']}", flush=True)


if __name__ == "__main__":
    main()
