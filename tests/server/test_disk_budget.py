#!/usr/bin/env python3
"""A disk budget over the running jobs (issue 51, item 5): a job starts only when its estimated result fits in what
the data directory has free beside what the running jobs' results will still take. Before, every job started and
the one that filled the disk failed (and took the others' room with it).

The data directory is a 6 MB tmpfs in a private mount namespace (as tests/server/test_disk_full.py). A job whose
result is estimated at about 20 MB (two 60 x 60 blocks, ten load steps kept) stays QUEUED with a message that says
why; a small job submitted after it runs and succeeds meanwhile; once the tmpfs is grown to 96 MB (a remount) the
large job starts and succeeds, its result downloadable. Needs root (mount) and util-linux (unshare, nsenter);
without them it says so and exits 0 (skipped)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import PrivateTmpfs, Server, flat_patch  # noqa: E402
from checks import check, finish  # noqa: E402

disk = PrivateTmpfs("6m", "contactd-budget-")


def blocks(n, steps):
    """Two n x n blocks pressed together, `steps` load steps, every step's fields kept."""
    job = flat_patch(name=f"blocks-{n}")
    for body in job["bodies"]:
        body["mesh"]["block"].update(nx=n, ny=n)
    job["loading"] = {"steps": steps}
    job["output"] = {"steps": "all"}
    return job


try:
    server = Server(data_dir=disk.mount_point, args=["--workers", "1"], prefix=disk.prefix).start()
    large = server.submit_id(blocks(60, 10))
    held = server.wait_for(large, lambda j: "waiting for disk space" in (j.get("message") or ""), 30)
    print("the large job's message:", held.get("message"), flush=True)
    check("a job whose result does not fit stays QUEUED and says why",
          held.get("state") == "QUEUED" and "estimated at" in (held.get("message") or "") and
          "MB free" in (held.get("message") or ""), held)
    small = server.submit_id(flat_patch(name="fits"))
    done = server.wait_done(small, 60)
    check("a small job behind it runs and succeeds meanwhile", done.get("state") == "SUCCEEDED", done)
    check("the large job still waits", server.job(large)["state"] == "QUEUED")

    grown = disk.remount("96m")
    check("the tmpfs grows to 96 MB", grown.returncode == 0, grown.stderr)
    end = server.wait_done(large, 300)
    check("with room, the large job starts and succeeds", end.get("state") == "SUCCEEDED", end)
    check("... its message no longer says it waits", "waiting" not in (end.get("message") or ""), end.get("message"))
    r = server.get(f"/v1/jobs/{large}/result")
    check("... and its result is served whole", r.status == 200 and len(r.body) == end.get("result_bytes"),
          (r.status, len(r.body), end.get("result_bytes")))
    print(f"its result: {end.get('result_bytes', 0) / 1e6:.1f} MB", flush=True)
    server.kill()
finally:
    disk.close()

finish()
