#!/usr/bin/env python3
"""The job store under misuse and damage (issue 10, items 3, 4, 8, 11, 12 and retention from 13):
  - a second server on the same data directory refuses to start (flock), and cannot share the port either;
  - a job that is running each time the server dies ends FAILED after --max-attempts such runs;
  - a job's event log is capped; a server restarts small with a large event log (read as a stream);
  - symbolic links planted in the store are never followed (an events.ndjson link does not truncate its target,
    a result.hdf link is not served);
  - damage is reported by /readyz (degraded, with the job ids) and /metrics and never served: a garbage
    state.json (the job answers 500 corrupt-job, not 404, and its Idempotency-Key stays taken), a garbage event
    line, a corrupt result file;
  - finished jobs are deleted by retention (age, total size), running ones never."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import CONTACTD, Server, Stream, flat_patch, long_job, read_all_events  # noqa: E402
from checks import check, finish  # noqa: E402


def job_dir(server, job_id):
    return os.path.join(server.data_dir, "jobs", job_id)


def readyz(server):
    r = server.get("/readyz")
    return r.status, r.json() or {}


def damaged_ids(server):
    return [d["id"] for d in readyz(server)[1].get("damaged_jobs", [])]


def kill_while_running(server, job_id):
    server.wait_for(job_id, lambda j: j["state"] == "RUNNING" and j["iterations"] >= 3, timeout=60)
    server.proc.kill()
    server.proc.wait(timeout=10)
    server.kill()


# --- one data directory, one server ---------------------------------------------------------------------------
data_dir = tempfile.mkdtemp(prefix="contactd-store-")
try:
    a = Server(data_dir=data_dir, args=["--workers", "1"]).start()
    second = subprocess.run([CONTACTD, "--host", "127.0.0.1", "--port", "0", "--data-dir", data_dir],
                            capture_output=True, text=True, timeout=20)
    check("a second server on the same data directory exits 1", second.returncode == 1, second.returncode)
    check("... saying the directory is in use, and by whom", "in use by another contactd" in second.stderr and
          f"pid {a.proc.pid}" in second.stderr, second.stderr[-400:])
    other = tempfile.mkdtemp(prefix="contactd-store-other-")
    same_port = subprocess.run([CONTACTD, "--host", "127.0.0.1", "--port", str(a.port), "--data-dir", other],
                               capture_output=True, text=True, timeout=20)
    shutil.rmtree(other, ignore_errors=True)
    check("a second server on the same port exits 1 (no SO_REUSEPORT)", same_port.returncode == 1 and
          "cannot listen" in same_port.stderr, same_port.stderr[-300:])

    # --- a poison job: the server dies each time it runs --------------------------------------------------------
    a.kill()
    a = Server(data_dir=data_dir, args=["--workers", "1", "--max-attempts", "2"]).start()
    poison = a.submit_id(long_job(max_iterations=100000, name="poison"))
    kill_while_running(a, poison)
    b = Server(data_dir=data_dir, args=["--workers", "1", "--max-attempts", "2"]).start()
    again = b.wait_for(poison, lambda j: j["state"] == "RUNNING", timeout=30)
    check("interrupted once: it runs again", again["state"] == "RUNNING" and again["interruptions"] == 1 and
          again["attempts"] == 2, again)
    kill_while_running(b, poison)
    c = Server(data_dir=data_dir, args=["--workers", "1", "--max-attempts", "2"]).start()
    final = c.job(poison)
    check("interrupted --max-attempts times: FAILED, stop_reason interrupted", final["state"] == "FAILED" and
          final["stop_reason"] == "interrupted" and "interrupted 2 times" in final["message"], final)
    with open(os.path.join(job_dir(c, poison), "state.json")) as f:
        check("... and so on disk", json.load(f)["state"] == "FAILED")
    events = read_all_events(c, poison)
    check("... with an end event", events and events[-1]["type"] == "end" and events[-1]["state"] == "FAILED",
          events[-1:])
    time.sleep(0.5)
    check("it is not run again", c.job(poison)["attempts"] == 2 and c.metric("contactd_workers_busy") == 0)
    c.kill()
finally:
    shutil.rmtree(data_dir, ignore_errors=True)

# --- the event log's cap, the default time limit --------------------------------------------------------------
with Server(args=["--workers", "1", "--max-event-log-bytes", "65536"]) as server:
    job_id = server.submit_id(long_job(max_iterations=400, name="chatty"))
    final = server.wait_done(job_id, timeout=120)
    size = os.path.getsize(os.path.join(job_dir(server, job_id), "events.ndjson"))
    check("a job over the event-log cap still runs to its end (max_iterations: FAILED, not converged)",
          final["state"] == "FAILED" and final["stop_reason"] == "max_iterations" and final["iterations"] == 400, final)
    check("its events.ndjson stays near the cap (64 KiB + the last few events)", size < 65536 + 16384, size)
    # The job's record has its outcome as soon as it is stored; the server-wide counter follows a moment
    # later (the worker adds to it after the commit): wait for it rather than read it once.
    deadline = time.time() + 10
    while time.time() < deadline and server.metric("contactd_events_dropped_total") != final["events_dropped"]:
        time.sleep(0.05)
    check("the iteration events not recorded are counted", final["events_dropped"] > 0 and
          server.metric("contactd_events_dropped_total") == final["events_dropped"],
          (final["events_dropped"], server.metric("contactd_events_dropped_total")))
    events = read_all_events(server, job_id)
    check("the stream still ends with `end`", events[-1]["type"] == "end" and
          [e["seq"] for e in events] == list(range(1, len(events) + 1)), events[-1:])
help_text = subprocess.run([CONTACTD, "--help"], capture_output=True, text=True).stdout
check("a time limit per run by default (3600 s)", "--time-limit-seconds FLOAT:FLOAT in [0 - 1e+09]=3600" in help_text,
      [l for l in help_text.splitlines() if "time-limit" in l])

# --- restart with a large event log: read as a stream -----------------------------------------------------------
with Server(args=["--workers", "1"]) as server:
    job_id = server.submit_id(flat_patch(name="big-log"))
    server.wait_done(job_id)
    events_path = os.path.join(job_dir(server, job_id), "events.ndjson")
    with open(events_path) as f:
        lines = [json.loads(line) for line in f]
    iteration = next(e for e in lines if e["type"] == "iteration")
    iteration["pairs"][0]["pressures"] = [1.0] * 2000  # a fat event, ~40 kB
    server.kill()
    target = 40 * 1000 * 1000
    with open(events_path, "w") as f:
        seq = 0
        for e in lines[:-1]:
            seq += 1
            f.write(json.dumps(dict(e, seq=seq), separators=(",", ":")) + "\n")
        written = f.tell()
        while written < target:
            seq += 1
            text = json.dumps(dict(iteration, seq=seq), separators=(",", ":")) + "\n"
            f.write(text)
            written += len(text)
        seq += 1
        f.write(json.dumps(dict(lines[-1], seq=seq), separators=(",", ":")) + "\n")
    start = time.time()
    again = Server(data_dir=server.data_dir, args=["--workers", "1"]).start(timeout=60)
    ready = time.time() - start
    peak = again.rss_kb("VmHWM")
    print(f"restart with a {written / 1e6:.0f} MB event log: ready in {ready:.2f} s, peak RSS {peak / 1024:.0f} MB",
          flush=True)
    # Reading the log as a stream is checked by the peak RSS (below): a log held whole in memory shows there, on a
    # machine of any load. The time is printed; its bound only catches a hang (tests run on loaded 2-core machines).
    check(f"a 40 MB event log: ready (no hang; {ready:.2f} s measured)", ready < 30.0, ready)
    check("a 40 MB event log: peak RSS under 40 MB (the log is never held in memory)", peak < 40 * 1024, peak)
    s = Stream(again, job_id, ndjson=True, last_event_id=seq - 3)
    tail = s.events_until_end()
    s.close()
    check("its end is still served", [e["seq"] for e in tail] == [seq - 2, seq - 1, seq], [e["seq"] for e in tail])
    again.kill()
    again.cleanup()

# --- symbolic links and damage ----------------------------------------------------------------------------------
outside = tempfile.mkdtemp(prefix="contactd-outside-")
with Server(args=["--workers", "1"]) as server:
    ids = {name: server.submit_id(flat_patch(name=name)) for name in ("events-link", "result-link", "bad-state",
                                                                      "bad-line", "bad-result", "intact")}
    keyed = server.submit(flat_patch(name="keyed"), headers={"Idempotency-Key": "key-of-a-damaged-job"}).json()["id"]
    for job_id in list(ids.values()) + [keyed]:
        server.wait_done(job_id)
    server.kill()
    precious = os.path.join(outside, "precious.txt")
    with open(precious, "w") as f:
        f.write("not the server's\n" * 1000)
    foreign_hdf = os.path.join(outside, "foreign.hdf")
    shutil.copy(os.path.join(job_dir(server, ids["intact"]), "result.hdf"), foreign_hdf)

    def path(name, file):
        return os.path.join(job_dir(server, ids[name]), file)

    os.remove(path("events-link", "events.ndjson"))
    os.symlink(precious, path("events-link", "events.ndjson"))
    os.remove(path("result-link", "result.hdf"))
    os.symlink(foreign_hdf, path("result-link", "result.hdf"))
    with open(path("bad-state", "state.json"), "w") as f:
        f.write("\x00garbage{")
    with open(os.path.join(job_dir(server, keyed), "state.json"), "w") as f:
        f.write("[]")
    with open(path("bad-line", "events.ndjson")) as f:
        event_lines = f.readlines()
    event_lines[2] = '{"seq":3,"type":"iteration","time":"x",this is not json}\n'  # prefix intact, body not
    with open(path("bad-line", "events.ndjson"), "w") as f:
        f.writelines(event_lines)
    with open(path("bad-result", "result.hdf"), "r+b") as f:
        f.write(b"GARBAGE!")

    again = Server(data_dir=server.data_dir, args=["--workers", "1"]).start()
    with open(precious) as f:
        check("a linked events.ndjson: its target is not truncated", f.read() == "not the server's\n" * 1000)
    r = again.get(f"/v1/jobs/{ids['result-link']}/result")
    check("a linked result.hdf is not served: 500 corrupt-job", r.status == 500 and
          (r.json() or {}).get("type") == "/problems/corrupt-job", r)
    r = again.get(f"/v1/jobs/{ids['bad-result']}/result")
    check("a result.hdf without the HDF5 signature is not served", r.status == 500 and
          (r.json() or {}).get("type") == "/problems/corrupt-job", r)
    r = again.get(f"/v1/jobs/{ids['bad-state']}")
    check("a job with a garbage state.json: 500 corrupt-job, not 404", r.status == 500 and
          (r.json() or {}).get("type") == "/problems/corrupt-job", r)
    r = again.submit(flat_patch(name="keyed"), headers={"Idempotency-Key": "key-of-a-damaged-job"})
    check("its Idempotency-Key is remembered: no second job", r.status == 500 and keyed in r.body.decode(), r)
    events = read_all_events(again, ids["bad-line"])
    check("a garbage event line is never streamed", [e["seq"] for e in events] == [1, 2] and
          b"this is not json" not in json.dumps(events).encode(), [e["seq"] for e in events])
    status, body = readyz(again)
    listed = damaged_ids(again)
    check("/readyz: degraded (200), listing every damaged job", status == 200 and body.get("status") == "degraded" and
          all(ids[n] in listed for n in ("events-link", "result-link", "bad-state", "bad-line", "bad-result")) and
          keyed in listed and ids["intact"] not in listed, body)
    check("/metrics counts them", again.metric("contactd_jobs_damaged") == 6, again.metric("contactd_jobs_damaged"))
    check("the intact job is served as before", again.get(f"/v1/jobs/{ids['intact']}/result").status == 200)
    kept = [f for f in os.listdir(job_dir(server, ids["events-link"])) if f.startswith("events.ndjson.damaged-")]
    check("the linked events.ndjson is moved aside, not deleted", len(kept) == 1 and
          os.path.islink(os.path.join(job_dir(server, ids["events-link"]), kept[0])), kept)
    r = again.request("DELETE", f"/v1/jobs/{ids['bad-state']}")
    check("a damaged job can be deleted", r.status == 204 and ids["bad-state"] not in damaged_ids(again), r)
    again.kill()
    again.cleanup()
shutil.rmtree(outside, ignore_errors=True)

# --- retention --------------------------------------------------------------------------------------------------
with Server(args=["--workers", "1", "--retention-seconds", "1"]) as server:
    old = server.submit_id(flat_patch(name="old"))
    server.wait_done(old)
    running = server.submit_id(long_job(name="running"))
    server.wait_for(running, lambda j: j["state"] == "RUNNING")
    deadline = time.time() + 6
    while time.time() < deadline and server.get(f"/v1/jobs/{old}").status != 404:
        time.sleep(0.2)
    check("--retention-seconds 1: a finished job is deleted", server.get(f"/v1/jobs/{old}").status == 404 and
          not os.path.exists(job_dir(server, old)))
    check("a running job is kept", server.job(running)["state"] == "RUNNING")
    check("deletions are counted", server.metric("contactd_jobs_expired_total") >= 1)
    server.request("POST", f"/v1/jobs/{running}/cancel")

with Server(args=["--workers", "1"]) as server:
    first = server.submit_id(flat_patch(name="measure"))
    server.wait_done(first)
    one_job = sum(os.path.getsize(os.path.join(job_dir(server, first), f)) for f in os.listdir(job_dir(server, first)))
with Server(args=["--workers", "1", "--retention-bytes", str(int(one_job * 2.5))]) as server:
    done = []
    for k in range(3):
        done.append(server.submit_id(flat_patch(name=f"sized-{k}")))
        server.wait_done(done[-1])
    deadline = time.time() + 15
    while time.time() < deadline and server.get(f"/v1/jobs/{done[0]}").status != 404:
        time.sleep(0.2)
    check("--retention-bytes: the oldest finished job goes first",
          [server.get(f"/v1/jobs/{j}").status for j in done] == [404, 200, 200])

finish()
