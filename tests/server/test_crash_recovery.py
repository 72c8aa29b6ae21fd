#!/usr/bin/env python3
"""No valid job takes contactd down, and one that did is not run again.

1. The job that crashed contactd and contact-solve (two clamped one-element blocks side by side, the pair
   b0.top -> b1.bottom whose edges never face each other): refused by validation with the pair named, on
   /v1/validate and at submission; the server stays up.
2. Small geometries in every relative position (tests/fuzz_geometries.py) submitted to one server: each is refused
   (400) or ends (SUCCEEDED, FAILED with a message); the server is alive at the end.
3. A fatal signal on the thread that solves a job (SIGSEGV sent to that thread with tgkill, as a defect of the
   solver would raise it): the server dies of it, the job is marked in its directory, and at the next start that
   job ends FAILED "crashed" naming the signal, without being run again, while the job that ran beside it is
   queued again and finishes."""
import ctypes
import json
import os
import signal
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import Server, flat_patch, long_job  # noqa: E402
from checks import check, finish  # noqa: E402
from fuzz_geometries import jobs  # noqa: E402

NEVER_FACING = {"name": "crash", "bodies": [
    {"name": "b0", "material": {"E": 1, "nu": 0.3},
     "mesh": {"block": {"corners": [[0, 0], [1, 0], [1, 1], [0, 1]], "nx": 1, "ny": 1}},
     "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
    {"name": "b1", "material": {"E": 1, "nu": 0.3},
     "mesh": {"block": {"corners": [[1.5, 0], [2.5, 0], [2.5, 1], [1.5, 1]], "nx": 1, "ny": 1}},
     "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]}],
    "contacts": [{"slave": "b0.top", "master": "b1.bottom"}]}

SYS_TGKILL = 234  # x86_64
libc = ctypes.CDLL(None, use_errno=True)


def thread_cpu_ticks(pid):
    """Each thread's CPU time (utime + stime, in ticks) of process pid."""
    ticks = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            ticks[int(tid)] = int(fields[11]) + int(fields[12])
        except OSError:
            pass
    return ticks


def busiest_thread(pid, seconds=1.0):
    """The thread that used the most CPU over `seconds` (the one solving the only running job)."""
    before = thread_cpu_ticks(pid)
    time.sleep(seconds)
    after = thread_cpu_ticks(pid)
    return max(after, key=lambda tid: after[tid] - before.get(tid, 0))


# --- 1. the job that crashed both ----------------------------------------------------------------------------
with Server() as server:
    r = server.request("POST", "/v1/validate", json_body=NEVER_FACING)
    detail = json.dumps(r.json())
    check("the never-facing pair is refused by /v1/validate", r.status == 400, r)
    check("its error is at /contacts/0 and says the edges never face", "/contacts/0" in detail and
          "never face each other" in detail, detail)
    r = server.submit(NEVER_FACING)
    check("and at submission", r.status == 400, r)
    check("the server is still up", server.get("/healthz").status == 200)

    # --- 2. small geometries in every relative position ------------------------------------------------------
    ids, refused = [], 0
    for job in jobs(24, seed=5):
        r = server.submit(job)
        if r.status == 202:
            ids.append((r.json()["id"], job))
        else:
            refused += 1
            errors = (r.json() or {}).get("errors") or [{}]
            check(f"{job['name']} refused with a problem document naming a field", r.status == 400 and
                  r.is_problem() and all(e.get("pointer", "").startswith("/") for e in errors), r)
    for job_id, job in ids:
        end = server.wait_done(job_id, timeout=120)
        check(f"{job['name']} ends", end is not None and end.get("done"), end)
        if end and end.get("done"):
            check(f"{job['name']} ends SUCCEEDED or FAILED with a message",
                  end["state"] == "SUCCEEDED" or (end["state"] == "FAILED" and end.get("message")), end)
            check(f"{job['name']}: no crash", end.get("stop_reason") not in ("crashed", "interrupted"), end)
    check("some of the geometries ran and some were refused", ids and refused, (len(ids), refused))
    check("the server is alive after them all", server.proc.poll() is None and server.get("/healthz").status == 200)

# --- 3. a job whose solve takes a fatal signal --------------------------------------------------------------
data_dir = tempfile.mkdtemp(prefix="contactd-crash-")
a = Server(data_dir=data_dir, args=["--workers", "2"]).start()
# One thread does the victim's work: with two, the busiest thread over a second may be a pool thread that is between
# two of its per-body tasks (unlabelled, not the job's work) at the instant the signal arrives.
crashing = long_job(max_iterations=100000, name="crashes")
crashing["solver"]["threads"] = 1
victim = a.submit_id(crashing)
check("the job to crash runs", a.wait_for(victim, lambda j: j["state"] == "RUNNING" and j["iterations"] > 5,
                                          timeout=60)["state"] == "RUNNING")
tid = busiest_thread(a.proc.pid)  # only the victim runs: its solve is the busy thread
beside = a.submit_id(long_job(max_iterations=400, name="beside"))
check("a job runs beside it", a.wait_for(beside, lambda j: j["state"] == "RUNNING", timeout=60)["state"] == "RUNNING")
check("tgkill reaches the solving thread", libc.syscall(SYS_TGKILL, a.proc.pid, tid, signal.SIGSEGV) == 0,
      ctypes.get_errno())
code = a.proc.wait(timeout=20)
check("contactd dies of the signal", code == -signal.SIGSEGV, code)
marker = os.path.join(data_dir, "jobs", victim, "crashed")
check("the job is marked with the signal", os.path.exists(marker) and open(marker).read().strip() == "SIGSEGV")
check("the log names the job", victim in a.output() and "SIGSEGV" in a.output(), a.output()[-800:])
a.kill()

b = Server(data_dir=data_dir, args=["--workers", "2"]).start()
crashed = b.job(victim)
check("at the next start the crashed job is FAILED, not queued", crashed["state"] == "FAILED", crashed)
check("its stop reason is 'crashed'", crashed.get("stop_reason") == "crashed", crashed)
check("its message names the signal and says it is not run again",
      "SIGSEGV" in crashed.get("message", "") and "not run again" in crashed.get("message", ""), crashed)
check("it was not started again", crashed.get("attempts") == 1, crashed)
check("the marker is gone once the outcome is stored", not os.path.exists(marker))
end = b.wait_done(beside, timeout=120)
check("the job beside it ran again and finished", end and end["state"] in ("SUCCEEDED", "FAILED") and
      end.get("stop_reason") not in ("crashed", "interrupted"), end)
check("a new job runs on the restarted server", b.wait_done(b.submit_id(flat_patch()))["state"] == "SUCCEEDED")
b.kill()
finish()
