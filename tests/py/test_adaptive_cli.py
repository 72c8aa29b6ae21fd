#!/usr/bin/env python3
"""contact-solve on an adaptive job as a user meets it (issue 20, item 3): one line per adaptive step (step, cells and
unknowns per body, estimate, time), and SIGTERM during a large boundary-element estimate takes effect within a
second, with the steps so far written. (A signal during a refinement's FE assembly and factorisation waits for it:
docs/job-format.md, "When the loop stops".)"""
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
CLI = os.path.join(BIN, "contact-solve")
EXAMPLES = os.path.join(SRC, "api", "examples")

passed, failed = 0, 0


def check(name, condition, detail=""):
    global passed, failed
    if condition:
        passed += 1
    else:
        failed += 1
        print(f"FAIL {name}: {detail}")


STEP = re.compile(r"^adaptive step +(\d+) +\| aluminium: (\d+) cells, (\d+) unknowns.*\| steel: (\d+) cells, (\d+) unknowns"
                  r".*\| estimate ([0-9.e+-]+).*\| estimating ([0-9.]+)s +([0-9.]+)s$")


def job_file(tmp, **adaptivity):
    with open(os.path.join(EXAMPLES, "two_cylinders_gmsh.json")) as f:
        job = json.load(f)
    job["bodies"][0]["mesh"]["gmsh"]["file"] = os.path.join(EXAMPLES, "two_cylinders_gmsh.msh")
    job["bodies"][1]["mesh"]["gmsh"]["file"] = os.path.join(EXAMPLES, "two_cylinders_gmsh.msh")
    job["adaptivity"].update(adaptivity)
    path = os.path.join(tmp, "job.json")
    with open(path, "w") as f:
        json.dump(job, f)
    return path


with tempfile.TemporaryDirectory() as tmp:
    # The example stops by itself; every step prints one line, in order, with both bodies' cells and unknowns,
    # the estimate, the time the estimate took and the elapsed time.
    r = subprocess.run([CLI, job_file(tmp), "-o", os.path.join(tmp, "full.hdf")], capture_output=True, text=True,
                       timeout=300)
    check("the adaptive example exits 0", r.returncode == 0, r.stderr[-400:])
    steps = [STEP.match(l) for l in r.stdout.splitlines() if l.startswith("adaptive step")]
    check("every adaptive step line has step, cells and unknowns per body, estimate and times",
          len(steps) >= 3 and all(steps), r.stdout[-1500:])
    if all(steps):
        check("one line per step, in order", [int(m.group(1)) for m in steps] == list(range(len(steps))),
              [m.group(1) for m in steps])
        check("the cells grow from step to step", all(int(b.group(2)) > int(a.group(2)) for a, b in zip(steps, steps[1:])))
        stop = [l for l in r.stdout.splitlines() if l.startswith("stop: ")]
        check("it stopped by itself after as many refinement steps as lines less one",
              len(stop) == 1 and f"stopped after {len(steps) - 1} refinement steps" in stop[0], stop)

    # SIGTERM during a large boundary-element estimate: the run without the stop test goes on to large meshes;
    # once adaptive step 4 is reported, the solve on the refined mesh (~60k + 25k unknowns) follows, and right
    # after its line the estimate of step 5 starts (boundary-element solves and ~130k interior points, a few
    # seconds): the signal lands inside it. The solver must stop within a second, write the steps so far and exit.
    out = os.path.join(tmp, "cancelled.hdf")
    p = subprocess.Popen([CLI, job_file(tmp, stop_tolerance=0, max_steps=9), "-o", out], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, bufsize=1)
    started = time.monotonic()
    lines, seen_step_4 = [], False
    for line in p.stdout:
        lines.append(line)
        seen_step_4 = seen_step_4 or line.startswith("adaptive step  4")
        if seen_step_4 and line.startswith("step "):  # the solve on step 5's mesh is done: its estimate runs now
            break
    time.sleep(0.2)
    running = p.poll() is None
    signalled = time.monotonic()
    p.send_signal(signal.SIGTERM)
    rest, stderr = p.communicate(timeout=60)
    exited = time.monotonic()
    stdout = "".join(lines) + rest
    check("still estimating when signalled (else the test measures nothing)", running and seen_step_4, stdout[-400:])
    stop = [l for l in stdout.splitlines() if l.startswith("stop: ")]
    match = re.search(r"stop: cancelled after \d+ steps, ([0-9.]+) s", stop[0]) if stop else None
    check("the stop line says cancelled during adaptive step 5",
          match is not None and "cancelled during adaptive step 5" in stop[0], stop or stdout[-400:])
    if match:
        # The solver's own clock starts after the process (job parsed, meshes read): its stop time minus the
        # signal's time since the process started bounds the latency from above.
        latency = float(match.group(1)) - (signalled - started)
        print(f"  SIGTERM {signalled - started:.2f} s after the start, inside the estimate of step 5: the solver "
              f"stopped {latency:.3f} s later, the process exited {exited - signalled:.2f} s after the signal")
        check("the solver stopped within 1 s of SIGTERM", latency <= 1.0, stop[0])
    check("the process exited within 3 s of SIGTERM (result written)", exited - signalled <= 3.0,
          f"{exited - signalled:.2f} s")
    check("the result so far is written", os.path.exists(out) and os.path.getsize(out) > 0)

print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
