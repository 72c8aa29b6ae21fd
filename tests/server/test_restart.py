#!/usr/bin/env python3
"""The job store survives: kill -9 while a job runs, restart on the same data directory: finished jobs and their
result files are intact, the interrupted job runs again to completion, event numbering continues, the
Idempotency-Key is remembered, crash leftovers are cleaned up. Graceful SIGTERM: exit 0 (the time printed, bounded
only against a hang), the running job told to its stream and stored back as QUEUED, run again at the next start."""
import hashlib
import json
import os
import shutil
import sys
import tempfile
import time
import uuid

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import Server, Stream, flat_patch, long_job, read_all_events  # noqa: E402
from checks import check, finish  # noqa: E402


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def wait_iterations(server, job_id, count, timeout=60):
    return server.wait_for(job_id, lambda j: j["state"] == "RUNNING" and j["iterations"] >= count, timeout)


data_dir = tempfile.mkdtemp(prefix="contactd-restart-")
try:
    # --- first life: one finished job, one interrupted by kill -9, one waiting ---------------------------------
    a = Server(data_dir=data_dir, args=["--workers", "1"]).start()
    done_id = a.submit_id(flat_patch(name="finished"))
    check("finished job", a.wait_done(done_id)["state"] == "SUCCEEDED")
    done_dir = os.path.join(data_dir, "jobs", done_id)
    result_hash = sha256(os.path.join(done_dir, "result.hdf"))
    xmf_hash = sha256(os.path.join(done_dir, "result.xmf"))
    done_events = read_all_events(a, done_id)
    done_resource = a.job(done_id)

    # About 1500 iterations of 2 ms: long enough to be killed while running, short enough to finish after.
    r = a.submit(long_job(max_iterations=1500, name="interrupted", iterate=True),
                 headers={"Idempotency-Key": "restart-key"})
    running_id = r.json()["id"]
    waiting_id = a.submit_id(flat_patch(-0.002, name="waiting"))
    state = wait_iterations(a, running_id, 20)
    check("long job running before the kill", state and state["state"] == "RUNNING", state)
    s = Stream(a, running_id, ndjson=True)
    events_before = [s.next_event() for _ in range(10)]
    s.close()
    a.proc.kill()  # SIGKILL: no chance to persist anything
    a.proc.wait(timeout=10)
    a.kill()

    # Leftovers a crash can leave: temporary files, a torn last event line, a directory of a submission never
    # acknowledged (no state.json), an interrupted deletion, and something that is not a job at all.
    with open(os.path.join(done_dir, "state.json.tmp"), "w") as f:
        f.write('{"half": ')
    with open(os.path.join(data_dir, "jobs", running_id, "events.ndjson"), "a") as f:
        f.write('{"seq": 999999, "type": "iter')
    unacked = os.path.join(data_dir, "jobs", str(uuid.uuid4()))
    os.makedirs(unacked)
    with open(os.path.join(unacked, "job.json"), "w") as f:
        f.write("{}")
    deleting = os.path.join(data_dir, "jobs", ".deleted-" + str(uuid.uuid4()))
    os.makedirs(deleting)
    stray = os.path.join(data_dir, "jobs", "not-a-job")
    os.makedirs(stray)

    # --- second life ------------------------------------------------------------------------------------------
    b = Server(data_dir=data_dir, args=["--workers", "1"]).start()
    resource = b.job(done_id)
    check("finished job intact", resource["state"] == "SUCCEEDED" and resource["result_available"] and
          resource["iterations"] == done_resource["iterations"], resource)
    check("its result file unchanged", sha256(os.path.join(done_dir, "result.hdf")) == result_hash)
    check("its sidecar unchanged", sha256(os.path.join(done_dir, "result.xmf")) == xmf_hash)
    r = b.get(f"/v1/jobs/{done_id}/result")
    check("its result downloads", r.status == 200 and hashlib.sha256(r.body).hexdigest() == result_hash)
    check("its events unchanged", read_all_events(b, done_id) == done_events)
    check("temporary file removed", not os.path.exists(os.path.join(done_dir, "state.json.tmp")))
    check("unacknowledged submission removed", not os.path.exists(unacked))
    check("interrupted deletion finished", not os.path.exists(deleting))
    check("foreign directory left alone", os.path.isdir(stray))
    check("unacknowledged submission not listed", len(b.get("/v1/jobs").json()["jobs"]) == 3)

    final = b.wait_done(running_id, timeout=120)
    # It runs to its max_iterations, short of its tolerance: FAILED (not converged), its last iterate kept
    # (asked for: output.iterate).
    check("interrupted job ran again to completion", final and final["state"] == "FAILED" and
          final["stop_reason"] == "max_iterations" and final["iterations"] == 1500 and final["attempts"] == 2
          and final["result_available"], final)
    check("waiting job ran", b.wait_done(waiting_id)["state"] == "SUCCEEDED")
    events = read_all_events(b, running_id)
    seqs = [e["seq"] for e in events]
    check("event numbering continues without gaps or duplicates", seqs == list(range(1, len(seqs) + 1)), seqs[-5:])
    requeue = [e for e in events if e["type"] == "state" and e["state"] == "QUEUED" and "interrupted" in e["message"]]
    check("a state event tells it was re-queued", len(requeue) == 1, [e for e in events if e["type"] == "state"])
    runs = [e for e in events if e["type"] == "state" and e["state"] == "RUNNING"]
    check("two runs", len(runs) == 2 and runs[1]["attempt"] == 2, runs)
    check("events before the kill kept", [e["seq"] for e in events[:10]] == [e["seq"] for e in events_before] and
          events[:10] == events_before)
    after = events[events.index(requeue[0]) + 1:]
    iterations = [e["iteration"] for e in after if e["type"] == "iteration"]
    check("the second run reports iterations 1..1500", iterations == list(range(1, 1501)), iterations[:3])
    check("end event last", events[-1]["type"] == "end" and events[-1]["state"] == "FAILED"
          and events[-1]["stop_reason"] == "max_iterations")
    r = b.get(f"/v1/jobs/{running_id}/result")
    check("its result downloads", r.status == 200 and len(r.body) > 1000, r.status)

    s = Stream(b, running_id, last_event_id=events_before[-1]["seq"], ndjson=True)
    resumed = s.events_until_end()
    s.close()
    check("Last-Event-ID from before the restart resumes", resumed and resumed[0]["seq"] == events_before[-1]["seq"] + 1
          and resumed[-1]["type"] == "end")

    r = b.submit(long_job(max_iterations=1500, name="interrupted", iterate=True),
                 headers={"Idempotency-Key": "restart-key"})
    check("Idempotency-Key remembered across the restart", r.status == 202 and r.json()["id"] == running_id, r)

    # --- graceful shutdown: SIGTERM while a job runs --------------------------------------------------------
    term_id = b.submit_id(long_job(name="terminated"))
    wait_iterations(b, term_id, 5)
    stream = Stream(b, term_id)
    first = stream.next_event()
    # What the shutdown does is checked by what it leaves (the stream told, the job stored back as QUEUED); the
    # time is printed. The server gives its workers 5 s and then exits anyway, so 60 s is broken only by a hang
    # (tests run on loaded 2-core machines).
    code, seconds = b.terminate(timeout=60)
    print(f"SIGTERM with a job running: exited in {seconds:.2f} s", flush=True)
    check(f"SIGTERM: exit 0, no hang ({seconds:.2f} s measured)", code == 0, (code, seconds, b.output()[-1500:]))
    told = []
    while True:
        e = stream.next_event()
        if e is None:
            break
        told.append(e)
    stream.close()
    queued_again = [e for e in told if e["type"] == "state" and e["state"] == "QUEUED"]
    check("the stream was told: state QUEUED, then closed", queued_again and told[-1] is queued_again[-1] and
          not any(e["type"] == "end" for e in told), [e["type"] for e in told][-5:])
    check("the stream ended with a shutdown comment", any("shutting down" in c for c in stream.comments),
          stream.comments[-3:])
    with open(os.path.join(data_dir, "jobs", term_id, "state.json")) as f:
        stored = json.load(f)
    check("stored back as QUEUED", stored["state"] == "QUEUED", stored)
    b.kill()

    c = Server(data_dir=data_dir, args=["--workers", "1"]).start()
    resource = c.wait_for(term_id, lambda j: j["state"] == "RUNNING", timeout=30)
    check("runs again at the next start", resource["state"] == "RUNNING" and resource["attempts"] == 2, resource)
    c.request("POST", f"/v1/jobs/{term_id}/cancel")
    check("and can be cancelled", c.wait_done(term_id)["state"] == "CANCELLED")
    check("nothing else re-ran", c.job(running_id)["attempts"] == 2 and c.job(done_id)["attempts"] == 1)
    c.kill()
finally:
    shutil.rmtree(data_dir, ignore_errors=True)

finish()
