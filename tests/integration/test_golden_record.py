#!/usr/bin/env python3
"""The golden record (tests/data/golden_record.json, written by scripts/golden_record.py) holds: the solvers'
iteration counts, products with F, Newton steps, cuts and key scalars of a set of friction, wall, augmented-
Lagrangian, load-step and adaptive jobs on one thread. A change that moves any of them beyond its band (a count by
10 % or 2, a scalar by 1e-6) fails here with the moves listed. After a deliberate retuning write the record again
(scripts/golden_record.py build/contact-solve --write tests/data/golden_record.json) and let the diff show the
move in review; docs/algorithm.md's "what was tried" parts say why."""
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/
from checks import check, finish  # noqa: E402

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))

run = subprocess.run(["/usr/bin/python3", os.path.join(SRC, "scripts", "golden_record.py"),
                      os.path.join(BIN, "contact-solve"), "--compare",
                      os.path.join(SRC, "tests", "data", "golden_record.json")],
                     capture_output=True, text=True, timeout=900)
print(run.stdout[-6000:], run.stderr[-2000:], flush=True)
moved = [line for line in run.stdout.splitlines() if line.startswith("MOVED ")]
check("every job of the record ran", "jobs," in run.stdout and run.returncode in (0, 1), run.stderr[-1000:])
check("no count or scalar of the record moved beyond its band", run.returncode == 0 and not moved, "\n".join(moved))
finish()
