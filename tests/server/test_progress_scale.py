#!/usr/bin/env python3
"""Progress that stays readable and bounded at thousands of pairs (issue 31, item 2).

A 22 x 22 frictional wall (496 bodies, 946 pairs) printed its 946 pairs on every progress line, and the server's
events carried every pair's profiles per iteration (0.7 MB each). Now every event carries the totals over all pairs
(pairs_summary) and bodies (bodies_summary) and lists only the pairs that stand out or that the job selects
(output.progress_pairs); any other pair's last iteration is served on request (GET /v1/jobs/{id}/pairs).

Checked: every event of the wall under 16 KB, whatever its 946 pairs; the totals equal the sums over every pair
fetched one by one from GET /pairs (an independent path: the pairs' own records); the pairs a pattern selects are the
ones fnmatch selects from the job's contact names; the routes' errors; the command line's text lines under 400
characters and its NDJSON lines bounded the same way.

Standard library only; exits non-zero on any failure."""
import fnmatch
import json
import os
import subprocess
import sys
import tempfile
import urllib.parse

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish, section  # noqa: E402
from harness import CONTACT_SOLVE, SRC, Server, read_all_events  # noqa: E402

EVENT_BYTES = 16 * 1024


def wall(directory, rows, selection=None):
    path = os.path.join(directory, f"wall{rows}.json")
    subprocess.run(["/usr/bin/python3", os.path.join(SRC, "scripts", "make_brick_wall.py"), "--rows", str(rows),
                    "--bricks", str(rows), "--friction", "0.6", "--shear", "0.3", "-o", path],
                   check=True, capture_output=True)
    with open(path) as f:
        job = json.load(f)
    if selection is not None:
        job.setdefault("output", {})["progress_pairs"] = selection
        with open(path, "w") as f:
            json.dump(job, f)
    return path, job


def pair_names(job):
    return [c.get("name") or f"{c['slave']}-{c['master']}" for c in job["contacts"]]


def pairs(server, job_id, names):
    return server.get(f"/v1/jobs/{job_id}/pairs?names={urllib.parse.quote(names, safe=',*?[]')}")


with tempfile.TemporaryDirectory() as tmp, Server(args=["--workers", "1"]) as server:
    path22, job22 = wall(tmp, 22)
    names = pair_names(job22)
    with open(path22) as f:
        wall_id = server.submit_id(json.load(f))
    final = server.wait_done(wall_id, timeout=300)
    check("the 22 x 22 frictional wall: SUCCEEDED", final.get("state") == "SUCCEEDED", final)

    section("events bounded whatever the number of pairs")
    events = read_all_events(server, wall_id, ndjson=True)
    iterations = [e for e in events if e.get("type") == "iteration"]
    sizes = [len(json.dumps(e)) for e in events]
    check("the wall streamed its iterations", len(iterations) >= 2, len(iterations))
    check(f"every event under {EVENT_BYTES} bytes", max(sizes) < EVENT_BYTES, max(sizes))
    last = iterations[-1]
    summary = last.get("pairs_summary", {})
    check("every iteration event counts every pair and body",
          all(e.get("pairs_summary", {}).get("count") == 946 and e.get("bodies_summary", {}).get("count") == 496
              for e in iterations), [e.get("pairs_summary") for e in iterations[:1]])
    check("past 16 pairs an event lists only the pairs its totals name", all(
        e.get("pairs_listed") == "selected" and {p["name"] for p in e["pairs"]} <=
        {e["pairs_summary"]["max_pressure_pair"], e["pairs_summary"]["most_changed_pair"]} for e in iterations),
        [[p["name"] for p in e["pairs"]] for e in iterations])
    check("and no body list past 64 bodies", all("bodies" not in e and e.get("bodies_listed") == "none"
                                                  for e in iterations))
    step = [e for e in events if e.get("type") == "step"]
    check("step events: the totals, no body list", step and all("bodies" not in e and
                                                               e["bodies_summary"]["count"] == 496 for e in step), step)

    section("the totals are the sums over every pair")
    every = []
    for k in range(0, len(names), 16):
        answer = pairs(server, wall_id, ",".join(names[k:k + 16]))
        check(f"GET /pairs of names {k}..{k + 15}: 200, final", answer.status == 200
              and answer.json().get("source") == "final", answer.status) if k == 0 else None
        every += answer.json().get("pairs", [])
    check("GET /pairs gives each of the 946 pairs", sorted(p["name"] for p in every) == sorted(names), len(every))
    check("with its profiles", all(len(p.get("positions", [])) == len(p.get("pressures", [])) > 0 for p in every))
    force = sum(p["force"] for p in every)
    check("pairs_summary.force is the sum of the pairs' forces", abs(summary["force"] - force) <= 1e-9 * abs(force),
          (summary["force"], force))
    check("pairs_summary.active_nodes is the sum", summary["active_nodes"] == sum(p["active_nodes"] for p in every))
    check("stick and slip nodes are the sums over the friction pairs",
          summary["stick_nodes"] == sum(p["stick_nodes"] for p in every)
          and summary["slip_nodes"] == sum(p["slip_nodes"] for p in every) and summary["friction_pairs"] == 946,
          summary)
    check("each pair's stick + slip nodes: its nodes in contact by its own profile", all(
        p["stick_nodes"] + p["slip_nodes"] == sum(1 for x in p["pressures"] if x > 0) for p in every))
    peak = max(every, key=lambda p: p["max_pressure"])
    check("max_pressure and its pair", summary["max_pressure"] == peak["max_pressure"]
          and summary["max_pressure_pair"] == peak["name"], (summary["max_pressure_pair"], peak["name"]))
    check("the base shear held: the tangential force is the sum", abs(
        summary["tangential_force"] - sum(p["tangential_force"] for p in every)) <= 1e-9 * max(1.0, abs(force)))

    section("GET /pairs by pattern")
    answer = pairs(server, wall_id, "b21_*")
    expected = [n for n in names if fnmatch.fnmatchcase(n, "b21_*")]
    check("b21_* selects the pairs fnmatch selects from the job's names, in the job's order",
          answer.status == 200 and [p["name"] for p in answer.json()["pairs"]] == expected
          and answer.json()["matched"] == len(expected), (answer.status, len(expected)))
    answer = pairs(server, wall_id, "*")
    check("at most 64 pairs an answer; matched counts them all", answer.status == 200
          and len(answer.json()["pairs"]) == 64 and answer.json()["matched"] == 946, answer.status)
    answer = pairs(server, wall_id, "nothing*")
    check("a pattern matching nothing: 404 no-such-pair", answer.status == 404
          and answer.json().get("type", "").endswith("no-such-pair"), answer.body[:300])
    answer = server.get(f"/v1/jobs/{wall_id}/pairs")
    check("no names: 400 invalid-request", answer.status == 400
          and answer.json().get("type", "").endswith("invalid-request"), answer.body[:300])
    answer = pairs(server, wall_id, ",".join(["b*"] * 17))
    check("17 names: 400", answer.status == 400, answer.status)

    section("the job selects the pairs its progress lists")
    path8, job8 = wall(tmp, 8, ["b7_*", "b0_0.bottom-base.top"])
    with open(path8) as f:
        small_id = server.submit_id(json.load(f))
    check("8 x 8 wall with output.progress_pairs: SUCCEEDED",
          server.wait_done(small_id, timeout=120).get("state") == "SUCCEEDED")
    chosen = {n for n in pair_names(job8) if fnmatch.fnmatchcase(n, "b7_*") or n == "b0_0.bottom-base.top"}
    listed = [e for e in read_all_events(server, small_id, ndjson=True) if e.get("type") == "iteration"]
    check("every iteration lists the selected pairs (and at most the two its totals name)", listed and all(
        chosen <= {p["name"] for p in e["pairs"]} and len({p["name"] for p in e["pairs"]} - chosen) <= 2
        for e in listed), [len(e["pairs"]) for e in listed])
    answer = server.request("POST", "/v1/validate", json_body=dict(job8, output={"progress_pairs": ["b99_*"]}))
    errors = answer.json().get("errors", [])
    check("a pattern matching no pair is refused with its pointer, naming pairs",
          answer.status == 400 and errors and errors[0]["pointer"] == "/output/progress_pairs/0"
          and "matches no contact pair" in errors[0]["message"] and "b0_0.bottom-base.top" in errors[0]["message"],
          errors)

    section("the command line")
    run = subprocess.run([CONTACT_SOLVE, path22, "-o", os.path.join(tmp, "w22.hdf")], capture_output=True,
                         text=True, timeout=300)
    lines = [line for line in run.stdout.splitlines() if line.startswith("step")]
    check("contact-solve: converged", run.returncode == 0, run.stderr[-500:])
    check("its progress lines are under 400 characters and give the totals",
          lines and max(map(len, lines)) < 400 and all("946 pairs: force" in line for line in lines),
          max(map(len, lines)) if lines else run.stdout[:500])
    run = subprocess.run([CONTACT_SOLVE, path22, "-o", os.path.join(tmp, "w22b.hdf"), "--progress", "ndjson"],
                         capture_output=True, text=True, timeout=300)
    lines = [json.loads(line) for line in run.stdout.splitlines() if line.strip()]
    check("--progress ndjson: iteration lines bounded like the events",
          lines and all(len(json.dumps(e)) < EVENT_BYTES for e in lines if e.get("type") == "iteration"),
          [len(json.dumps(e)) for e in lines])
    run = subprocess.run([CONTACT_SOLVE, path22, "-o", os.path.join(tmp, "w22c.hdf"), "--progress-pairs", "b21_1.*"],
                         capture_output=True, text=True, timeout=300)
    lines = [line for line in run.stdout.splitlines() if line.startswith("step")]
    check("--progress-pairs adds the pairs selected to each line", lines and all(
        "| b21_1.bottom-b20_0.top: force" in line for line in lines), lines[:1])

finish()
