#!/usr/bin/env python3
"""A full disk (issue 10, item 7): the data directory (a 3 MB tmpfs in a private mount namespace) fills up while a
job runs; the job ends FAILED (its result cannot be written), and state.json says FAILED too (the server gives up
its 1 MiB reserve to store that), so a restart does not run it again; its message says why and leaks no memory
address or path; /readyz says the disk filled up.

Needs root (mount) and util-linux (unshare, nsenter): the tmpfs exists only in a namespace held by a `sleep`, and
contactd runs inside it; the test reads the files through /proc/<pid>/root. Without them it says so and exits 0."""
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import Server, long_job  # noqa: E402
from checks import check, finish, skip  # noqa: E402


mount_point = tempfile.mkdtemp(prefix="contactd-full-")
holder = subprocess.Popen(["unshare", "--mount", "--propagation", "private", "sh", "-c",
                           f"mount -t tmpfs -o size=3m tmpfs {mount_point} && echo mounted && exec sleep 600"],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
line = holder.stdout.readline().strip()
if line != "mounted":
    holder.kill()
    reason = f"cannot mount a tmpfs in a private namespace here ({holder.stderr.read().strip()[:200]})"
    os.rmdir(mount_point)
    skip(reason)  # CTest reports it skipped (SKIP_RETURN_CODE)


class NamespacedServer(Server):
    """contactd started inside the holder's mount namespace (nsenter); its files seen through /proc."""

    def __init__(self):
        super().__init__(data_dir=mount_point, args=["--workers", "1"],
                         prefix=["nsenter", "-t", str(holder.pid), "-m", "--"])

    def file(self, *parts):
        return os.path.join(f"/proc/{holder.pid}/root", mount_point.lstrip("/"), *parts)


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
    r = a.request("POST", f"/v1/jobs/{queued}/cancel")
    check("cancel of a queued job on a full disk: 202 CANCELLED (stored with the reserve)",
          r.status == 202 and (r.json() or {}).get("state") == "CANCELLED", r)
    with open(a.file("jobs", queued, "state.json")) as f:
        check("... and state.json says CANCELLED", json.load(f)["state"] == "CANCELLED")
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
    with open(a.file("jobs", blocker, "state.json")) as f:
        stored = json.load(f)
    check("state.json says FAILED too (the API never reports what is not on disk)", stored["state"] == "FAILED",
          stored.get("state"))
    a.proc.kill()
    a.proc.wait(timeout=10)
    a.kill()

    b = NamespacedServer().start(ready=False)  # not ready: the disk is still full
    time.sleep(1.0)
    again = b.job(blocker)
    check("after a restart it stays FAILED and does not run again", again["state"] == "FAILED" and
          again["attempts"] == 1 and b.metric("contactd_workers_busy") == 0, again)
    check("the cancelled job stays CANCELLED", b.job(queued)["state"] == "CANCELLED")
    b.kill()
finally:
    holder.send_signal(signal.SIGKILL)
    holder.wait(timeout=10)
    try:
        os.rmdir(mount_point)
    except OSError:
        pass

finish()
