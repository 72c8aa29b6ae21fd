#!/usr/bin/env python3
"""Many clients at once: 50 submissions from 10 threads, each accepted (202) or refused (503 + Retry-After),
none lost or duplicated, every accepted one finishing with its own correct result; a full queue answers 503;
Idempotency-Key: the same key twice gives one job, with another body 422, and concurrent retries one job."""
import io
import os
import sys
import threading
import time

import h5py

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import Server, flat_patch, long_job  # noqa: E402
from checks import check, finish  # noqa: E402


REFERENCE_DISPLACEMENT = -0.001


def pair_force(server, job_id):
    """The contact force stored in the job's result file (downloaded)."""
    r = server.get(f"/v1/jobs/{job_id}/result")
    if r.status != 200:
        return None
    with h5py.File(io.BytesIO(r.body), "r") as f:
        return float(f["steps/0/contacts/force"][0])  # the one pair's row of the contact table


# --- 50 submissions from 10 threads ---------------------------------------------------------------------------
with Server(args=["--workers", "2", "--max-queued", "8"]) as server:
    reference_id = server.submit_id(flat_patch(REFERENCE_DISPLACEMENT, name="reference"))
    server.wait_done(reference_id)
    reference_force = pair_force(server, reference_id)
    check("reference force", reference_force and reference_force > 0, reference_force)

    outcomes = {}  # k -> (status, id or None, retry-after, problem ok)
    lock = threading.Lock()
    barrier = threading.Barrier(10)

    def client(thread):
        barrier.wait()
        for k in range(thread * 5, thread * 5 + 5):
            # Each job its own displacement: its force tells whether it got its own result.
            r = server.submit(flat_patch(REFERENCE_DISPLACEMENT * (1 + k / 10.0), name=f"job{k}"))
            with lock:
                outcomes[k] = (r.status, (r.json() or {}).get("id") if r.status == 202 else None,
                               r.headers.get("retry-after"), r.status == 202 or r.is_problem(),
                               r.headers.get("location"))

    threads = [threading.Thread(target=client, args=(t,)) for t in range(10)]
    start = time.time()
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    check("all 50 answered", len(outcomes) == 50, len(outcomes))
    statuses = [o[0] for o in outcomes.values()]
    accepted = {k: o[1] for k, o in outcomes.items() if o[0] == 202}
    refused = [o for o in outcomes.values() if o[0] == 503]
    print(f"50 concurrent submissions in {time.time() - start:.2f} s: {len(accepted)} accepted, {len(refused)} refused "
          f"(503)")
    check("each accepted or 503", all(s in (202, 503) for s in statuses), statuses)
    check("503s carry Retry-After and a problem", all(o[2] and o[3] for o in refused), refused[:3])
    check("202s carry Location", all(o[4] == f"/v1/jobs/{o[1]}" for o in outcomes.values() if o[0] == 202))
    check("some accepted", len(accepted) >= 8, len(accepted))
    ids = list(accepted.values())
    check("no duplicate ids", len(set(ids)) == len(ids), ids)

    listed = server.get("/v1/jobs?page_size=500").json()["jobs"]
    listed_ids = [j["id"] for j in listed if j["name"] != "reference"]
    check("none lost or duplicated: the list has exactly the accepted ones",
          sorted(listed_ids) == sorted(ids), (len(listed_ids), len(ids)))

    wrong = []
    for k, job_id in accepted.items():
        final = server.wait_done(job_id, timeout=120)
        if final.get("state") != "SUCCEEDED" or final.get("name") != f"job{k}":
            wrong.append((k, final.get("state"), final.get("name")))
            continue
        force = pair_force(server, job_id)
        expected = reference_force * (1 + k / 10.0)  # linear elasticity, zero gap: force proportional to load
        if force is None or abs(force - expected) > 1e-9 * expected:
            wrong.append((k, force, expected))
    check("every accepted job finished with its own correct result", not wrong, wrong[:5])
    check("metrics count them", server.metric("contactd_jobs_submitted_total") == len(accepted) + 1)

# --- a full queue answers 503 with Retry-After ------------------------------------------------------------------
with Server(args=["--workers", "1", "--small-job-workers", "0", "--max-queued", "2"]) as server:  # no lane: the flat patches queue
    running = server.submit_id(long_job())
    server.wait_for(running, lambda j: j["state"] == "RUNNING", timeout=30)
    queued = [server.submit(flat_patch()) for _ in range(2)]
    check("queue takes max-queued jobs", [r.status for r in queued] == [202, 202], queued)
    check("queue_position", [r.json()["queue_position"] for r in queued] == [1, 2], [r.json() for r in queued])
    r = server.submit(flat_patch())
    check("full queue: 503", r.status == 503 and r.is_problem() and r.json()["type"] == "/problems/queue-full", r)
    check("full queue: Retry-After", r.headers.get("retry-after", "").isdigit(), r.headers)
    check("metrics queue length", server.metric("contactd_queue_length") == 2)
    server.request("POST", f"/v1/jobs/{running}/cancel")
    for q in queued:
        check("queued jobs run after the cancel", server.wait_done(q.json()["id"])["state"] == "SUCCEEDED")
    check("accepted again once drained", server.submit(flat_patch()).status == 202)

# --- Idempotency-Key ------------------------------------------------------------------------------------------
with Server(args=["--workers", "2"]) as server:
    job = flat_patch(name="idempotent")
    first = server.submit(job, headers={"Idempotency-Key": "order-42"})
    second = server.submit(job, headers={"Idempotency-Key": "order-42"})
    check("first submission 202", first.status == 202, first)
    check("same key + same body: the same job", second.status == 202 and second.json()["id"] == first.json()["id"] and
          second.headers.get("location") == first.headers.get("location"), second)
    check("replay is marked", second.headers.get("idempotent-replayed") == "true", second.headers)
    other = flat_patch(-0.002, name="idempotent")
    r = server.submit(other, headers={"Idempotency-Key": "order-42"})
    check("same key + other body: 422 problem", r.status == 422 and r.is_problem() and
          r.json()["type"] == "/problems/idempotency-key-reused", r)
    check("one job for the key", len(server.get("/v1/jobs").json()["jobs"]) == 1)

    results = []
    barrier = threading.Barrier(8)

    def retry():
        barrier.wait()
        results.append(server.submit(flat_patch(-0.003, name="race"), headers={"Idempotency-Key": "race-1"}))

    threads = [threading.Thread(target=retry) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    race_ids = {r.json()["id"] for r in results if r.status == 202}
    check("8 concurrent retries with one key: one job", len(results) == 8 and all(r.status == 202 for r in results)
          and len(race_ids) == 1, [r.status for r in results])
    names = [j["name"] for j in server.get("/v1/jobs").json()["jobs"]]
    check("exactly one 'race' job exists", names.count("race") == 1, names)
    check("a key is remembered in the resource", server.job(first.json()["id"])["idempotency_key"] == "order-42")

finish()
