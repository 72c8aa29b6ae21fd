#!/usr/bin/env python3
"""No valid job crashes contact-solve: small geometries in every relative position (tests/fuzz_geometries.py: one-
and few-element blocks touching, apart, overlapping, nested, pairs mistyped and swapped, bodies held or floating,
with and without friction) each end with an exit code of 0 to 3 (docs: 0 converged, 1 solver error, 2 invalid job,
3 not converged) within a bound only a hang breaks, never with a signal, and one that is not 0 says why.

    test_fuzz_cli.py                    the suite's size (seconds)
    test_fuzz_cli.py --count 400 --seed 7   a longer run; prints the outcomes' counts"""
import argparse
import collections
import json
import os
import signal
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/
from checks import check, finish  # noqa: E402
from fuzz_geometries import jobs  # noqa: E402

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
SOLVE = os.path.join(BIN, "contact-solve")

parser = argparse.ArgumentParser()
parser.add_argument("--count", type=int, default=60)
parser.add_argument("--seed", type=int, default=1)
args = parser.parse_args()

outcomes = collections.Counter()
with tempfile.TemporaryDirectory(prefix="fuzz-cli-") as tmp:
    for job in jobs(args.count, args.seed):
        path = os.path.join(tmp, job["name"] + ".json")
        with open(path, "w") as f:
            json.dump(job, f)
        try:
            r = subprocess.run([SOLVE, path, "-o", os.path.join(tmp, "result.hdf"), "--threads", "2", "-q"],
                               capture_output=True, text=True, timeout=120)
        except subprocess.TimeoutExpired:
            check(f"{job['name']} ends", False, "no end within 120 s: " + json.dumps(job))
            continue
        said = (r.stdout + r.stderr).strip()
        last = said.splitlines()[-1] if said else ""
        name = signal.Signals(-r.returncode).name if r.returncode < 0 else str(r.returncode)
        outcomes[name] += 1
        check(f"{job['name']} ends with an exit code of 0 to 3, not a signal", 0 <= r.returncode <= 3,
              f"exit {name}: {said[-600:]}\n{json.dumps(job)}")
        check(f"{job['name']}: an exit code that is not 0 comes with a message", r.returncode == 0 or last,
              json.dumps(job))
        if "CHOLMOD" in said or "UMFPACK" in said:
            outcomes["library text"] += 1
print("exit codes over %d jobs (seed %d): %s" % (args.count, args.seed, dict(sorted(outcomes.items()))))
finish()
