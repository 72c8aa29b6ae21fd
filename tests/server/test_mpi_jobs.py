#!/usr/bin/env python3
"""contactd running jobs on MPI ranks (--mpi-launcher): a job with parallel.ranks = 2 streams its iterations live,
ends SUCCEEDED and its result equals the same job solved in the server's own process (to 1e-12); a running MPI
job is cancelled like any other (CANCELLED with the iterations done and the result of its last iterate); a
server without a launcher, or a job over --max-ranks, is refused at /parallel/ranks. Exits 77 (skipped) without
mpirun or without an MPI build of contact-solve."""
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import CONTACT_SOLVE, EXAMPLES, Server, Stream, example, long_job  # noqa: E402
from checks import check, finish, skip  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "mpi"))
from compare_results import max_relative_difference  # noqa: E402

import h5py  # noqa: E402


# mpirun as root needs its consent; three ranks on two cores need oversubscription (inherited by the child).
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_rmaps_base_oversubscribe": "1"}

if not shutil.which("mpirun"):
    skip("mpirun not found (Debian's openmpi-bin; scripts/setup.sh installs it)")
with tempfile.TemporaryDirectory() as tmp:
    probe = subprocess.run(["mpirun", "-n", "2", CONTACT_SOLVE, os.path.join(EXAMPLES, "flat_patch.json"), "-o",
                            os.path.join(tmp, "p.hdf"), "-q"], capture_output=True, text=True, timeout=120,
                           env=dict(os.environ, **MPI_ENV))
    if "MPI ranks" not in probe.stdout:
        skip("contact-solve was built without MPI")


def download(server, job_id, path):
    r = server.get(f"/v1/jobs/{job_id}/result")
    with open(path, "wb") as f:
        f.write(r.body)
    return r.status


with tempfile.TemporaryDirectory() as tmp, \
        Server(args=["--mpi-launcher", "mpirun -n {ranks}", "--max-ranks", "3", "--workers", "1"], env=MPI_ENV) as server:
    job = example("stack3.json")
    job["parallel"] = {"ranks": 2}
    job_id = server.submit_id(job)
    stream = Stream(server, job_id)
    events = stream.events_until_end()
    stream.close()
    iterations = [e for e in events if e.get("_event") == "iteration"]
    end = [e for e in events if e.get("_event") == "end"]
    check("an MPI job streams its iterations", len(iterations) > 100, len(iterations))
    check("an MPI job ends SUCCEEDED with its result", end and end[-1].get("state") == "SUCCEEDED"
          and end[-1].get("result_available") is True, end[-1:] or server.output()[-2000:])
    check("an MPI job's step events arrive", any(e.get("_event") == "step" for e in events), [e.get("_event") for e in events][-5:])
    record = server.job(job_id)
    check("the job resource keeps the progress summary", (record.get("progress") or {}).get("iteration", 0) > 100
          and "pressures" not in str(record.get("progress")), record.get("progress"))
    mpi_file = os.path.join(tmp, "mpi.hdf")
    check("the MPI job's result downloads", download(server, job_id, mpi_file) == 200)

    job["parallel"] = {"ranks": 1}  # the same job in the server's process
    local_id = server.submit_id(job)
    server.wait_done(local_id, timeout=120)
    local_file = os.path.join(tmp, "local.hdf")
    download(server, local_id, local_file)
    worst, where, it_local, it_mpi = max_relative_difference(local_file, mpi_file)
    check("MPI job = in-process job to 1e-12", worst <= 1e-12, f"{worst} at {where}")
    check("MPI job and in-process job: same iterations", it_local == it_mpi, (it_local, it_mpi))

    # Cancelled while it runs: SIGUSR1 reaches every rank, which stop together at their next exchange.
    long = long_job(iterate=True)  # its result keeps the iterate the cancel stops on
    long["parallel"] = {"ranks": 2}
    long_id = server.submit_id(long)
    server.wait_for(long_id, lambda j: j.get("state") == "RUNNING" and j.get("iterations", 0) >= 20, timeout=120)
    r = server.request("POST", f"/v1/jobs/{long_id}/cancel", headers={"Content-Type": "application/json"})
    check("cancel of a running MPI job is accepted", r.status in (200, 202), r)
    done = server.wait_done(long_id, timeout=60)
    check("the cancelled MPI job ends CANCELLED", done.get("state") == "CANCELLED", done)
    # With the iterations it did and the result of its last iterate (docs/parallel.md, "Cancellation").
    check("the cancelled MPI job reports the iterations done", done.get("iterations", 0) >= 20
          and f"after {done.get('iterations')} iterations" in done.get("message", ""), done)
    check("the cancelled MPI job's result is available", done.get("result_available") is True, done)
    cancelled_file = os.path.join(tmp, "cancelled.hdf")
    check("the cancelled MPI job's result downloads", download(server, long_id, cancelled_file) == 200)
    try:
        with h5py.File(cancelled_file, "r") as f:
            readable = (f.attrs["stop_reason"], int(f.attrs["iterations"]), len(f["steps"]))
    except (OSError, KeyError) as e:
        readable = str(e)
    check("the cancelled MPI job's result is readable and says so",
          readable == ("cancelled", done.get("iterations"), 1), readable)

    over = example("stack3.json")
    over["parallel"] = {"ranks": 4}
    r = server.submit(over)
    pointers = [e.get("pointer") for e in (r.json() or {}).get("errors", [])]
    check("ranks over --max-ranks: 400 at /parallel/ranks", r.status == 400 and pointers == ["/parallel/ranks"], r)

with Server() as plain:
    job = example("stack3.json")
    job["parallel"] = {"ranks": 2}
    r = plain.submit(job)
    errors = (r.json() or {}).get("errors", [])
    check("a server without a launcher refuses ranks > 1 and says why",
          r.status == 400 and errors and errors[0].get("pointer") == "/parallel/ranks"
          and "--mpi-launcher" in errors[0].get("message", ""), r)

finish()
