#!/usr/bin/env python3
"""A full disk (issue 10, item 7): the data directory (a 12 MB tmpfs in a private mount namespace: room for the
running job's estimated result, which the disk budget of tests/server/test_disk_budget.py wants before it starts)
fills up while a job runs; the job ends FAILED (its result cannot be written), and state.json says FAILED too (the server gives up
its 1 MiB reserve to store that), so a restart does not run it again; its message says why and leaks no memory
address or path; /readyz says the disk filled up.

Streams end (issue 51, item 6): the `end` event of a job that ends on a full disk (cancelled while queued, or failed
while running) is served from memory, and every stream of it closes with that `end`, also the Python client's
wait(); after a restart with the disk still full the streams still close with `end`, and once room returns the next
start writes the missing `end` to events.ndjson.

Needs root (mount) and util-linux (unshare, nsenter): the tmpfs exists only in a namespace held by a `sleep`, and
contactd runs inside it; the test reads the files through /proc/<pid>/root. Without them it says so and exits 0."""
import json
import os
import re
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "clients"))
from harness import PrivateTmpfs, Server, Stream, long_job  # noqa: E402
from checks import check, finish  # noqa: E402

disk = PrivateTmpfs("12m", "contactd-full-")  # skipped (SKIP_RETURN_CODE) where it cannot be mounted
mount_point = disk.mount_point


class NamespacedServer(Server):
    """contactd started inside the tmpfs's mount namespace (nsenter); its files seen through /proc."""

    def __init__(self):
        # Heartbeats rarer than the streams' read timeout: a stream that stays open without an event times out.
        super().__init__(data_dir=mount_point, args=["--workers", "1", "--heartbeat-seconds", "120"],
                         prefix=disk.prefix)

    def file(self, *parts):
        return disk.path(*parts)


def stream_ends(server, job_id, what, ndjson=False):
    """Reads the job's stream from the start; checks that it closes with its `end` event (a read that stays silent
    for 15 s fails). Returns the end event."""
    try:
        stream = Stream(server, job_id, ndjson=ndjson, timeout=15)
        events = stream.events_until_end()
        stream.close()
    except OSError as exc:  # socket.timeout: open without an event
        check(f"{what}: the stream closes with its end event", False, f"no end: {exc!r}")
        return {}
    end = events[-1] if events else {}
    check(f"{what}: the stream closes with its end event", end.get("type") == "end" and
          [e["seq"] for e in events] == sorted({e["seq"] for e in events}), events[-3:])
    return end


def stored_types(server, job_id):
    with open(server.file("jobs", job_id, "events.ndjson")) as f:
        return [json.loads(line)["type"] for line in f if line.strip()]


def fill(server):
    """Writes a filler file until the tmpfs is full."""
    with open(server.file("filler"), "ab", buffering=0) as f:
        try:
            while True:
                f.write(b"\0" * 4096)
        except OSError:
            pass


try:
    a = NamespacedServer().start()
    blocker = a.submit_id(long_job(max_iterations=100000, name="fills-the-disk", iterate=True))
    a.wait_for(blocker, lambda j: j["state"] == "RUNNING" and j["iterations"] >= 5, timeout=60)
    queued = a.submit_id(long_job(name="waits"))
    # Every byte taken (the server's reserve aside); the running job's events now fail to be written.
    fill(a)
    time.sleep(0.3)
    fill(a)
    # More events lost than the log keeps in memory (512) and than a stream reads at once (256): a stream that starts
    # before them must step over them (it stalled there for ever, heartbeats and all).
    at = a.job(blocker)["iterations"]
    a.wait_for(blocker, lambda j: j["iterations"] >= at + 1200, timeout=120)
    r = a.request("POST", f"/v1/jobs/{queued}/cancel")
    check("cancel of a queued job on a full disk: 202 CANCELLED (stored with the reserve)",
          r.status == 202 and (r.json() or {}).get("state") == "CANCELLED", r)
    with open(a.file("jobs", queued, "state.json")) as f:
        check("... and state.json says CANCELLED", json.load(f)["state"] == "CANCELLED")
    end = stream_ends(a, queued, "the job cancelled on a full disk (SSE)")
    check("... its end says CANCELLED", end.get("state") == "CANCELLED", end)
    stream_ends(a, queued, "the same (NDJSON)", ndjson=True)
    import contact_client  # noqa: E402
    client = contact_client.Client(f"http://127.0.0.1:{a.port}", timeout=15)
    waited = client.wait(queued, max_retries=1, read_timeout=15)
    check("the client's wait() returns the ended job", waited.get("state") == "CANCELLED", waited)
    r = a.get("/readyz")
    body = r.json() or {}
    check("/readyz: unavailable, the disk filled up", r.status == 503 and body.get("disk_reserve_used") is True and
          body.get("status") == "unavailable", body)
    check("/metrics: contactd_disk_reserve_used 1", a.metric("contactd_disk_reserve_used") == 1)

    a.request("POST", f"/v1/jobs/{blocker}/cancel")
    final = a.wait_done(blocker, timeout=60)
    check("the running job ends FAILED (its result cannot be written)", final and final["state"] == "FAILED", final)
    message = (final or {}).get("message") or ""
    print("the job's message:", message, flush=True)
    check("its message says why", "result file" in message and "space" in message.lower(), message)
    check("its message leaks no memory address", not re.search(r"0x[0-9a-fA-F]{6,}", message), message)
    check("nor the data directory's path", mount_point not in message, message)
    end = stream_ends(a, blocker, "the job that failed on a full disk, past 1,200 events lost to it")
    check("... its end says FAILED", end.get("state") == "FAILED", end)
    check("... and the lost events are counted", (final or {}).get("events_dropped", 0) >= 1200, final)
    with open(a.file("jobs", blocker, "state.json")) as f:
        stored = json.load(f)
    check("state.json says FAILED too (the API never reports what is not on disk)", stored["state"] == "FAILED",
          stored.get("state"))
    # A result write that hit "no space left" left the HDF5 library holding the file: contactd died of SIGSEGV in
    # it at SIGTERM (issue 51, item 5). Its state was saved; the stop must be clean all the same.
    a.proc.send_signal(signal.SIGTERM)
    try:
        code = a.proc.wait(timeout=60)
    except subprocess.TimeoutExpired:
        code = None
    check("SIGTERM after a write that hit a full disk: contactd stops cleanly (exit 0, no signal)", code == 0,
          (code, a.output()[-1500:]))
    a.kill()

    b = NamespacedServer().start(ready=False)  # not ready: the disk is still full
    time.sleep(1.0)
    again = b.job(blocker)
    check("after a restart it stays FAILED and does not run again", again["state"] == "FAILED" and
          again["attempts"] == 1 and b.metric("contactd_workers_busy") == 0, again)
    check("the cancelled job stays CANCELLED", b.job(queued)["state"] == "CANCELLED")
    for job_id, state in ((queued, "CANCELLED"), (blocker, "FAILED")):
        end = stream_ends(b, job_id, f"after a restart on the full disk, the {state} job")
        check("... with its outcome", end.get("state") == state, end)
    b.kill()

    os.remove(b.file("filler"))  # room again
    c = NamespacedServer().start()
    for job_id, state in ((queued, "CANCELLED"), (blocker, "FAILED")):
        end = stream_ends(c, job_id, f"once room returns, the {state} job")
        check("... and its events.ndjson ends with the end event (written by the start)",
              stored_types(c, job_id)[-1:] == ["end"], stored_types(c, job_id)[-3:])
    c.kill()
finally:
    disk.close()

finish()
