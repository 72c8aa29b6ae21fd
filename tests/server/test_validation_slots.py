#!/usr/bin/env python3
"""Validation that cannot be made slow for others (issue 22, defects 3 and 4).

Defect 3: jobs with large Gmsh meshes held every validation slot, so that a small valid job waited behind them
(and after 10 s got 503 busy). Bodies over 256 KiB now take at most all validation slots but one: while four
clients validate 32 MB meshes (about 2 s each) on a server with two slots, small jobs are accepted (202, never 503
busy) without waiting for them.

Defect 4: a worker parses its job again before it runs it, and that parse did not look at the cancel token nor
the time limit: a job without contacts whose parse outlived an acknowledged cancel, or the time limit, ended
SUCCEEDED. Now a cancel or the time limit during the worker's parse ends the job CANCELLED, or FAILED with
stop_reason time_limit."""
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import EXAMPLES, Server, flat_patch  # noqa: E402
from checks import check, finish  # noqa: E402


LARGE_NAMES = 600_000  # extra Gmsh physical names: a valid 32 MB job that takes about 2 s to validate
LARGE_CLIENTS = 4
SMALL_JOBS = 10
# A small job is accepted in about 10 ms (printed); the defect made it wait behind the large validations (2 s and
# more each) until 503 busy after 10 s. The 503 is checked by the status; this bound, two hundred times the normal
# time, is broken by a small job waiting its turn behind the large ones, not by a loaded machine (tests run on loaded
# 2-core machines).
AT_ONCE_SECONDS = 2.0
MAX_BYTES = 40_000_000


def large_job(contacts=True):
    """The Gmsh flat patch with LARGE_NAMES more physical names, given as data to both bodies."""
    with open(os.path.join(EXAMPLES, "flat_patch_gmsh.msh")) as f:
        text = f.read()
    extra = "".join(f'{(0, 1, 2)[k % 3]} {100 + k} "extra_{k}"\n' for k in range(LARGE_NAMES))
    header = "$PhysicalNames\n7\n"
    text = text.replace(header, f"$PhysicalNames\n{7 + LARGE_NAMES}\n" + extra, 1)
    with open(os.path.join(EXAMPLES, "flat_patch_gmsh.json")) as f:
        job = json.load(f)
    for body in job["bodies"]:
        body["mesh"]["gmsh"] = {"data": text, "surface": body["name"]}
    if not contacts:
        job["contacts"] = []
    return json.dumps(job).encode()


JSON = {"Content-Type": "application/json"}
body = large_job()

# --- defect 3: small jobs accepted without waiting while large ones validate --------------------------------------
with Server(args=["--max-validations", "2", "--max-large-bodies", str(LARGE_CLIENTS), "--max-request-bytes",
                  str(MAX_BYTES), "--workers", "1"]) as server:
    r = server.request("POST", "/v1/validate", body=body, headers=JSON, timeout=120)
    check("the large job is valid", r.status == 200, r)
    running = [True]
    large = []
    lock = threading.Lock()

    def large_client():
        while running[0]:
            start = time.time()
            r = server.request("POST", "/v1/validate", body=body, headers=JSON, timeout=120)
            with lock:
                large.append((r.status, time.time() - start))

    clients = [threading.Thread(target=large_client) for _ in range(LARGE_CLIENTS)]
    for t in clients:
        t.start()
    time.sleep(1.0)  # the large validations under way
    small = []
    for k in range(SMALL_JOBS):
        start = time.time()
        r = server.submit(flat_patch(name=f"small{k}"))
        small.append((r.status, round(time.time() - start, 3)))
        time.sleep(0.2)
    running[0] = False
    for t in clients:
        t.join(timeout=120)
    print(f"small jobs while {LARGE_CLIENTS} clients validated {len(body) / 1e6:.0f} MB jobs: {small}; "
          f"large validations: {[round(s, 2) for _, s in large]}")
    check("large validations ran meanwhile (200, or 503 busy)", large and all(s in (200, 503) for s, _ in large),
          large)
    check("every small job is accepted (202)", all(s == 202 for s, _ in small), small)
    check(f"no small job waits for the large validations (slowest {max(t for _, t in small):.3f} s measured)",
          all(t < AT_ONCE_SECONDS for _, t in small), small)

# --- defect 4: cancel and time limit while the worker parses ------------------------------------------------------
uncontacted = large_job(contacts=False)
with Server(args=["--max-request-bytes", str(MAX_BYTES), "--workers", "1"]) as server:
    r = server.request("POST", "/v1/jobs", body=uncontacted, headers=JSON, timeout=120)
    check("a large job without contacts is accepted", r.status == 202, r)
    job_id = (r.json() or {}).get("id")
    server.wait_for(job_id, lambda j: j.get("state") == "RUNNING", timeout=60, interval=0.01)
    r = server.request("POST", f"/v1/jobs/{job_id}/cancel", headers=JSON)
    check("its cancel while the worker parses it is acknowledged", r.status == 202, r)
    done = server.wait_done(job_id, timeout=60)
    check("the cancelled job ends CANCELLED (not SUCCEEDED)", done.get("state") == "CANCELLED", done)

with Server(args=["--max-request-bytes", str(MAX_BYTES), "--workers", "1", "--time-limit-seconds", "0.5"]) as server:
    r = server.request("POST", "/v1/jobs", body=uncontacted, headers=JSON, timeout=120)
    job_id = (r.json() or {}).get("id")
    done = server.wait_done(job_id, timeout=60)
    check("a parse longer than the time limit ends FAILED with stop_reason time_limit",
          done.get("state") == "FAILED" and (done.get("error") or {}).get("reason") == "time_limit", done)

finish()
