#!/usr/bin/env python3
"""Races between requests on the same job (issue 22, defect 5): concurrent cancel and DELETE of one job answer
202, 204, 404 or 409, never 5xx (the loser of a race learns that the job is gone or not finished), and the store
stays consistent: every job ends deleted, the counts by state match the listing, and a restart finds the same
jobs."""
import os
import sys
import threading

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import Server, flat_patch, long_job  # noqa: E402
from checks import check, finish  # noqa: E402


ROUNDS = 3
JOBS_PER_ROUND = 10
CLIENTS_PER_JOB = 5  # 2 cancel and 3 DELETE: 50 concurrent clients per round
ALLOWED = {202, 204, 404, 409}


def race(server, job_ids):
    """CLIENTS_PER_JOB clients on each job, all released at once: a cancel client posts one cancel, a DELETE
    client deletes until the job is gone (409 while it is not finished: as a client that saw `end` would, it
    tries again at once). Returns [(method, status, body)] of every request."""
    plan = [(job_id, "POST" if k < 2 else "DELETE") for job_id in job_ids for k in range(CLIENTS_PER_JOB)]
    answers = []
    lock = threading.Lock()
    barrier = threading.Barrier(len(plan))

    def one(job_id, method):
        path = f"/v1/jobs/{job_id}/cancel" if method == "POST" else f"/v1/jobs/{job_id}"
        barrier.wait()
        for _ in range(200):
            r = server.request(method, path, headers={"Content-Type": "application/json"})
            with lock:
                answers.append((method, r.status, r.body[:300]))
            if method == "POST" or r.status != 409:
                break

    threads = [threading.Thread(target=one, args=step) for step in plan]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    return answers


with Server(args=["--workers", "1", "--max-queued", "100"]) as server:
    # The worker is busy with a long job: the others stay QUEUED until cancelled.
    busy_id = server.submit_id(long_job(name="busy"))
    server.wait_for(busy_id, lambda j: j.get("state") == "RUNNING", timeout=60)
    kept = {busy_id}
    for round_ in range(ROUNDS):
        job_ids = [server.submit_id(flat_patch(name=f"r{round_}j{k}")) for k in range(JOBS_PER_ROUND)]
        answers = race(server, job_ids)
        check(f"round {round_}: every request answered", len(answers) >= JOBS_PER_ROUND * CLIENTS_PER_JOB,
              len(answers))
        wrong = [a for a in answers if a[1] not in ALLOWED]
        check(f"round {round_}: cancel and DELETE answer 202, 204, 404 or 409, never 5xx", not wrong, wrong[:5])
        for job_id in job_ids:
            r = server.get(f"/v1/jobs/{job_id}")
            check(f"round {round_}: every job is cancelled and deleted (404)", r.status == 404, r)

    r = server.request("POST", f"/v1/jobs/{busy_id}/cancel", headers={"Content-Type": "application/json"})
    check("the long job's cancel is accepted", r.status == 202, r)
    check("the long job ends", server.wait_done(busy_id, timeout=60).get("state") == "CANCELLED")

    listed = {j["id"] for j in server.get("/v1/jobs?page_size=500").json()["jobs"]}
    check("the listing holds exactly the jobs not deleted", listed == kept, (len(listed), len(kept)))
    counted = server.metric('contactd_jobs{state="CANCELLED"}')
    check("the CANCELLED count matches the listing", counted == len(kept), (counted, len(kept)))
    for state in ("QUEUED", "RUNNING", "SUCCEEDED", "FAILED"):
        value = server.metric(f'contactd_jobs{{state="{state}"}}')
        check(f"no job counted {state}", value == 0, value)
    data_dir = server.data_dir
    server.kill()

    with Server(data_dir=data_dir) as again:
        listed = {j["id"] for j in again.get("/v1/jobs?page_size=500").json()["jobs"]}
        check("after a restart the store holds the same jobs", listed == kept, (len(listed), len(kept)))
        ready = again.get("/readyz").json() or {}
        check("after a restart no job is damaged", ready.get("damaged_jobs") == [], ready)

finish()
