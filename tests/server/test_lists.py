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
from harness import Server, example  # noqa: E402

with Server(args=["--workers", "1"]) as server:
    wall = example("brick_wall.json")  # 69 bodies, 120 contact pairs, frictionless: about a second
    wall_id = server.submit_id(wall)
    patch_id = server.submit_id(example("flat_patch.json"))  # one pair, two bodies: listed as it is
    for job_id in (wall_id, patch_id):
        final = server.wait_done(job_id, timeout=300)
        check(f"{job_id}: SUCCEEDED", final.get("state") == "SUCCEEDED", final)

    full = server.job(wall_id)["progress"]
    check("the job's own resource keeps every pair and body", len(full.get("pairs", [])) == 120
          and len(full.get("bodies", [])) == 69, {k: v for k, v in full.items() if k not in ("pairs", "bodies")})

    listed = {j["id"]: j for j in server.get("/v1/jobs?page_size=500").json()["jobs"]}
    digest = listed[wall_id]["progress"]
    check("a listed wall has no pair or body arrays", "pairs" not in digest and "bodies" not in digest, list(digest))
    pairs = digest.get("pairs_summary", {})
    bodies = digest.get("bodies_summary", {})
    check("pairs_summary: the count and the sums of the whole progress",
          pairs.get("count") == 120
          and abs(pairs.get("force", 0) - sum(p["force"] for p in full["pairs"])) <= 1e-9 * abs(pairs.get("force", 1))
          and pairs.get("active_nodes") == sum(p["active_nodes"] for p in full["pairs"])
          and pairs.get("max_pressure") == max(p["max_pressure"] for p in full["pairs"]), pairs)
    peak = max(full["pairs"], key=lambda p: p["max_pressure"])
    check("pairs_summary names the pair of the peak pressure", pairs.get("max_pressure_pair") == peak["name"], pairs)
    check("bodies_summary: the count and the sums",
          bodies.get("count") == 69 and bodies.get("dofs") == sum(b["dofs"] for b in full["bodies"])
          and bodies.get("elements") == sum(b["elements"] for b in full["bodies"]), bodies)
    check("the other progress fields are kept", all(digest.get(k) == full.get(k) for k in
                                                   ("iteration", "complementarity", "active_nodes", "elapsed_seconds")),
          digest)
    size_full, size_digest = len(json.dumps(full)), len(json.dumps(digest))
    check("the digest is small", size_digest < 2000 and size_digest * 20 < size_full, (size_digest, size_full))

    small = listed[patch_id]["progress"]
    check("a small job is listed with its pairs and bodies as they are",
          small == server.job(patch_id)["progress"] and len(small.get("pairs", [])) == 1, small)

finish()
