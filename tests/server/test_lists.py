#!/usr/bin/env python3
"""contactd: the job list stays small whatever the jobs' size (issue 32, item 2).

Each entry of GET /v1/jobs carried the job's whole progress: every pair and every body of the last iteration (0.6 MB
for a 500-body wall), so 60 stored walls listed with page_size=500 gave 21 MB answers. An entry now carries a digest:
up to six pairs and bodies as they are, past that their totals (pairs_summary, bodies_summary), which equal the sums
over the whole progress that GET /v1/jobs/{id} still gives.

Standard library only; exits non-zero on any failure."""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish  # noqa: E402
from harness import Server, example, long_job, read_all_events  # noqa: E402

with Server(args=["--workers", "1"]) as server:
    wall = example("brick_wall.json")  # 69 bodies, 120 contact pairs, frictionless: about a second
    wall_id = server.submit_id(wall)
    patch_id = server.submit_id(example("flat_patch.json"))  # one pair, two bodies: listed as it is
    for job_id in (wall_id, patch_id):
        final = server.wait_done(job_id, timeout=300)
        check(f"{job_id}: SUCCEEDED", final.get("state") == "SUCCEEDED", final)

    # Every pair of the last iteration, from GET /v1/jobs/{id}/pairs (at most 64 an answer: by rows of the wall).
    progress = server.job(wall_id)["progress"]
    full = dict(progress, pairs=[])
    for names in ("b0_*,b1_*,b2_*", "b3_*,b4_*,b5_*", "b6_*,b7_*"):
        answer = server.get(f"/v1/jobs/{wall_id}/pairs?names={names}").json()
        full["pairs"] += answer["pairs"]
    check("GET /pairs gives every pair of the wall, each once", len({p["name"] for p in full["pairs"]}) == 120,
          len(full["pairs"]))
    check("the job's own resource lists every body (69 <= 64? no: their totals) and the pairs that stand out",
          "bodies" not in progress and progress.get("bodies_listed") == "none"
          and progress.get("pairs_listed") == "selected" and 1 <= len(progress.get("pairs", [])) <= 2,
          {k: v for k, v in progress.items() if k not in ("pairs",)})

    listed = {j["id"]: j for j in server.get("/v1/jobs?page_size=500").json()["jobs"]}
    digest = listed[wall_id]["progress"]
    named = {digest.get("pairs_summary", {}).get("max_pressure_pair"), digest.get("pairs_summary", {}).get("most_changed_pair")}
    check("a listed wall has no body array and at most the two pairs its totals name",
          "bodies" not in digest and {p["name"] for p in digest.get("pairs", [])} <= named, list(digest))
    pairs = digest.get("pairs_summary", {})
    bodies = digest.get("bodies_summary", {})
    check("pairs_summary: the count and the sums of the whole progress",
          pairs.get("count") == 120
          and abs(pairs.get("force", 0) - sum(p["force"] for p in full["pairs"])) <= 1e-9 * abs(pairs.get("force", 1))
          and pairs.get("active_nodes") == sum(p["active_nodes"] for p in full["pairs"])
          and pairs.get("max_pressure") == max(p["max_pressure"] for p in full["pairs"]), pairs)
    peak = max(full["pairs"], key=lambda p: p["max_pressure"])
    check("pairs_summary names the pair of the peak pressure", pairs.get("max_pressure_pair") == peak["name"], pairs)
    step = [e for e in read_all_events(server, wall_id) if e.get("type") == "step"][-1]
    check("bodies_summary: the count, and the cells the step event counts",
          bodies.get("count") == 69 and bodies.get("elements") == step["bodies_summary"]["elements"]
          and bodies.get("dofs", 0) > 0, (bodies, step))
    check("the other progress fields are kept", all(digest.get(k) == full.get(k) for k in
                                                   ("iteration", "complementarity", "active_nodes", "elapsed_seconds")),
          digest)
    size_full, size_digest = len(json.dumps(progress)), len(json.dumps(digest))
    check("the digest is small", size_digest < 2000 and size_digest <= size_full, (size_digest, size_full))

    # A poller that sends the ETag back gets 304 and no body while nothing changed (the web page polls every 2 s).
    first = server.get("/v1/jobs?page_size=50")
    tag = first.headers.get("etag", "")
    again = server.get("/v1/jobs?page_size=50", headers={"If-None-Match": tag})
    check("an unchanged list: 304 without a body", tag and again.status == 304 and again.body == b"", again)
    new_id = server.submit_id(example("flat_patch.json"))
    server.wait_done(new_id)
    changed = server.get("/v1/jobs?page_size=50", headers={"If-None-Match": tag})
    check("a changed list: 200 with the new job and a new ETag", changed.status == 200
          and changed.json()["jobs"][0]["id"] == new_id and changed.headers.get("etag") not in ("", tag), changed.status)

    # The ETag is weak and follows the jobs and their states, not a running job's figures (a strong tag changed on
    # every iteration and every second, so a poller never got 304 while a job ran).
    check("the list's ETag is weak", changed.headers.get("etag", "").startswith('W/"'), changed.headers)
    long_id = server.submit_id(long_job(name="runs-while-polled"))
    running = server.wait_for(long_id, lambda j: j["state"] == "RUNNING" and j["iterations"] >= 3, 60)
    first = server.get("/v1/jobs?page_size=50")
    tag = first.headers.get("etag", "")
    server.wait_for(long_id, lambda j: j["iterations"] >= running["iterations"] + 20, 60)
    again = server.get("/v1/jobs?page_size=50", headers={"If-None-Match": tag})
    fresh = server.get("/v1/jobs?page_size=50")
    check("while a job runs: 304 for the same jobs and states, though its iterations moved",
          again.status == 304 and fresh.json()["jobs"][0]["iterations"] > first.json()["jobs"][0]["iterations"],
          (again.status, first.json()["jobs"][0]["iterations"], fresh.json()["jobs"][0]["iterations"]))
    check("... also for the tag sent strong, in a list of tags (weak comparison)",
          server.get("/v1/jobs?page_size=50", headers={"If-None-Match": '"x", ' + tag[2:]}).status == 304)
    server.request("POST", f"/v1/jobs/{long_id}/cancel")
    server.wait_done(long_id)
    after = server.get("/v1/jobs?page_size=50", headers={"If-None-Match": tag})
    check("its state changed (CANCELLED): 200 and a new ETag", after.status == 200 and
          after.headers.get("etag") not in ("", tag) and after.json()["jobs"][0]["state"] == "CANCELLED", after.status)

    small = listed[patch_id]["progress"]
    check("a small job is listed with its pairs and bodies as they are",
          small == server.job(patch_id)["progress"] and len(small.get("pairs", [])) == 1, small)

finish()
