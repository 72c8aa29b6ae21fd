#!/usr/bin/env python3
"""contactd end to end: submit, stream, download; the result file equals contact-solve's in its numbers; the
rest of the API surface (validate, schema, list with paging, delete, metrics, health)."""
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import (CONTACT_SOLVE, SRC, Server, Stream, example, flat_patch, read_all_events)  # noqa: E402
from checks import check, finish  # noqa: E402


# Every field of the solver's IterationReport, BodyReport and PairReport (solver/include/contact/result.hpp).
ITERATION_FIELDS = {"iteration", "measure", "paper_criterion", "fixed_point_residual", "complementarity",
                    "active_nodes", "active_set_changes", "elapsed_seconds", "gamma", "update", "note", "bodies", "pairs"}
BODY_FIELDS = {"name", "elements", "dofs", "elements_refined"}
PAIR_FIELDS = {"name", "force", "resultant", "max_pressure", "extent_begin", "extent_end", "active_nodes", "changed_nodes",
               "theta", "max_penetration", "positions", "pressures"}
END_FIELDS = {"state", "stop_reason", "message", "converged"}


def compare_h5(a_path, b_path):
    """Every dataset and numeric attribute of the two files, except wall times and the job id, must be equal.
    Returns a list of differences (empty when equal in their numbers)."""
    ignored_attrs = {"job_id", "created", "wall_seconds", "setup_seconds", "factorization_seconds", "host"}
    ignored_sets = {"history/iterations/elapsed_seconds"}
    diffs = []
    with h5py.File(a_path, "r") as a, h5py.File(b_path, "r") as b:
        names_a, names_b = [], []
        a.visit(names_a.append)
        b.visit(names_b.append)
        if sorted(names_a) != sorted(names_b):
            diffs.append(f"members differ: {set(names_a) ^ set(names_b)}")
        compared = 0
        for name in names_a:
            if name not in b or name in ignored_sets or name.startswith("provenance"):
                continue
            x, y = a[name], b[name]
            if isinstance(x, h5py.Dataset):
                if x.dtype.kind in "fiu":
                    # NaN marks "not defined here" (gaps of nodes without a multiplier, pressure on body points).
                    if x.shape != y.shape or not np.array_equal(x[()], y[()], equal_nan=x.dtype.kind == "f"):
                        diffs.append(f"dataset {name} differs")
                    compared += 1
                elif name == "input/job":
                    if json.loads(x.asstr()[()]) != json.loads(y.asstr()[()]):
                        diffs.append("input/job differs")
            for key, value in x.attrs.items():
                if key in ignored_attrs:
                    continue
                other = y.attrs.get(key)
                if isinstance(value, np.ndarray) or isinstance(other, np.ndarray):
                    if not np.array_equal(np.asarray(value), np.asarray(other)):
                        diffs.append(f"attribute {name}@{key} differs")
                elif value != other:
                    diffs.append(f"attribute {name}@{key}: {value!r} != {other!r}")
        for key in ("converged", "stop_reason", "iterations", "format_version", "method"):
            if a.attrs.get(key) != b.attrs.get(key):
                diffs.append(f"root attribute {key}: {a.attrs.get(key)!r} != {b.attrs.get(key)!r}")
        if compared < 10:
            diffs.append(f"only {compared} numeric datasets compared")
    return diffs


with Server() as server, tempfile.TemporaryDirectory() as tmp:
    # --- health, readiness, index, embedded documents ------------------------------------------------------
    r = server.get("/healthz")
    check("healthz 200", r.status == 200 and r.json()["status"] == "ok", r)
    r = server.get("/readyz")
    check("readyz 200 ready", r.status == 200 and r.json()["status"] == "ready", r)
    check("index links", server.get("/").json()["links"]["jobs"] == "/v1/jobs")

    # --- the web page and the examples, compiled into the binary --------------------------------------------
    r = server.get("/", headers={"Accept": "text/html,application/xhtml+xml,*/*;q=0.8"})
    with open(os.path.join(SRC, "server", "web", "index.html"), "rb") as f:
        check("a browser gets the page at /", r.status == 200 and r.content_type.startswith("text/html")
              and r.body == f.read(), r)
    csp = r.headers.get("content-security-policy", "")
    check("the page has a CSP: scripts from the server only, no inline code",
          "script-src 'self'" in csp and "unsafe-inline" not in csp and "frame-ancestors 'none'" in csp, csp)
    check("/ says it varies by Accept", "accept" in r.headers.get("vary", "").lower(), r.headers)
    web_dir = os.path.join(SRC, "server", "web")
    web_files = sorted(os.path.relpath(os.path.join(d, n), web_dir) for d, _, names in os.walk(web_dir) for n in names)
    wrong = []
    for rel in web_files:
        if rel == "index.html":
            continue
        r = server.get("/web/" + rel)
        with open(os.path.join(web_dir, rel), "rb") as f:
            if r.status != 200 or r.body != f.read():
                wrong.append((rel, r.status))
    check("every file of server/web is served byte for byte under /web/", len(web_files) >= 8 and not wrong, wrong)
    r = server.get("/web/app.js")
    check("scripts as text/javascript, nosniff", r.content_type.startswith("text/javascript")
          and r.headers.get("x-content-type-options") == "nosniff", r.headers)
    check("an unchanged file is 304", server.get("/web/app.js", headers={"If-None-Match": r.headers.get("etag", "")})
          .status == 304)
    check("the vendored plotting library's licence is served",
          b"MIT License" in server.get("/web/vendor/uPlot.LICENSE").body)
    r = server.get("/web/index.html")
    check("/web/index.html redirects to the page", r.status == 302 and r.headers.get("location") == "../", r)
    r = server.get("/web/nope.js")
    check("an unknown web file is a 404 problem", r.status == 404 and r.is_problem(), r)
    r = server.get("/v1/examples")
    names = sorted(os.path.splitext(n)[0] for n in os.listdir(os.path.join(SRC, "api", "examples"))
                   if n.endswith(".json"))
    check("/v1/examples lists api/examples", r.status == 200 and [e["name"] for e in r.json()["examples"]] == names,
          r)
    with open(os.path.join(SRC, "api", "examples", "seed_layers.json"), "rb") as f:
        seed_bytes = f.read()
    check("an example is served as its file", server.get("/v1/examples/seed_layers").body == seed_bytes
          and server.get("/v1/examples/seed_layers.json").body == seed_bytes)
    # A Gmsh example is served with its mesh in it, once, in the job's "meshes" table ("data"): the server reads no
    # files for a job, and the bodies name the entry.
    with open(os.path.join(SRC, "api", "examples", "flat_patch_gmsh.msh")) as f:
        msh = f.read()
    served = server.get("/v1/examples/flat_patch_gmsh").json()
    fields = list(example("flat_patch_gmsh.json"))
    check("a Gmsh example is served with its .msh text once, in the meshes table, the bodies naming it",
          served is not None and served.get("meshes") == {"flat_patch_gmsh": {"data": msh}}
          and all(b["mesh"]["gmsh"] == {"mesh": "flat_patch_gmsh", "surface": b["name"]} for b in served["bodies"])
          and list(served) == fields[:fields.index("bodies")] + ["meshes"] + fields[fields.index("bodies"):],
          served and (list(served), served["bodies"][0]["mesh"]))
    r = server.request("POST", "/v1/validate", json_body=served)
    check("the served Gmsh example is valid on the server", r.status == 200 and r.json()["valid"] is True, r)
    r = server.request("POST", "/v1/validate", json_body=example("flat_patch_gmsh.json"))
    check("a Gmsh mesh by file name is refused at its pointer, asking for data",
          r.status == 400 and {e["pointer"] for e in r.json()["errors"]}
          == {"/bodies/0/mesh/gmsh/file", "/bodies/1/mesh/gmsh/file"}
          and "\"data\"" in r.json()["errors"][0]["message"], r)
    r = server.get("/v1/examples/nope")
    check("an unknown example is a 404 problem naming the list", r.status == 404 and r.is_problem()
          and "/v1/examples" in r.json()["detail"], r)
    r = server.get("/v1/schema")
    with open(os.path.join(SRC, "api", "job.schema.json"), "rb") as f:
        check("schema is api/job.schema.json", r.status == 200 and r.body == f.read(), r)
    r = server.get("/v1/openapi.yaml")
    with open(os.path.join(SRC, "api", "openapi.yaml"), "rb") as f:
        check("openapi.yaml is api/openapi.yaml", r.status == 200 and r.body == f.read(), r.status)

    # --- validate -------------------------------------------------------------------------------------------
    r = server.request("POST", "/v1/validate", json_body=example("flat_patch.json"))
    check("validate 200", r.status == 200 and r.json()["valid"] is True and r.json()["dofs"] > 0, r)
    bad = example("flat_patch.json")
    bad["bodies"][1]["material"]["nu"] = 0.5
    bad["bodies"][0]["mesh"]["block"]["nx"] = 0
    bad["solver"]["gama"] = 0.1
    r = server.request("POST", "/v1/validate", json_body=bad)
    pointers = {e["pointer"] for e in (r.json() or {}).get("errors", [])}
    check("validate lists every error with its pointer",
          r.status == 400 and r.is_problem() and
          {"/bodies/1/material/nu", "/bodies/0/mesh/block/nx", "/solver/gama"} <= pointers, r)
    r = server.submit(bad)
    check("submit of an invalid job: 400 with every pointer",
          r.status == 400 and r.is_problem() and r.json()["type"] == "/problems/invalid-job" and
          {"/bodies/1/material/nu", "/bodies/0/mesh/block/nx", "/solver/gama"} <=
          {e["pointer"] for e in r.json()["errors"]}, r)
    check("an invalid job creates no job", server.get("/v1/jobs").json()["jobs"] == [])

    # --- submit, stream, download ---------------------------------------------------------------------------
    job = example("seed_layers.json")
    r = server.submit(job)
    check("submit 202", r.status == 202, r)
    resource = r.json()
    job_id = resource["id"]
    check("Location header", r.headers.get("location") == f"/v1/jobs/{job_id}", r.headers)
    check("job resource fields", {"id", "name", "state", "done", "created", "progress", "timings", "links"} <=
          set(resource) and resource["name"] == "seed_layers" and resource["done"] is False, resource)

    stream = Stream(server, job_id)
    check("SSE content type", stream.status == 200 and stream.content_type.startswith("text/event-stream"),
          stream.content_type)
    events = stream.events_until_end()
    stream.close()
    seqs = [e["seq"] for e in events]
    check("events numbered 1..n in order", seqs == list(range(1, len(events) + 1)), seqs[:20])
    check("SSE id and event lines match seq and type",
          all(e["_id"] == str(e["seq"]) and e["_event"] == e["type"] for e in events))
    check("every event has a time", all(isinstance(e.get("time"), str) and e["time"].endswith("Z") for e in events))
    types = [e["type"] for e in events]
    check("first events: state QUEUED then RUNNING",
          types[:2] == ["state", "state"] and events[0]["state"] == "QUEUED" and events[1]["state"] == "RUNNING",
          events[:2])
    iterations = [e for e in events if e["type"] == "iteration"]
    check("iteration numbers 1..n", [e["iteration"] for e in iterations] == list(range(1, len(iterations) + 1)))
    check("iteration events carry every documented field",
          all(ITERATION_FIELDS <= set(e) for e in iterations) and
          all(BODY_FIELDS <= set(b) for e in iterations for b in e["bodies"]) and
          all(PAIR_FIELDS <= set(p) for e in iterations for p in e["pairs"]), iterations[0] if iterations else None)
    check("pressure profile on every iteration",
          all(len(p["positions"]) == len(p["pressures"]) == 33 for e in iterations for p in e["pairs"]))
    check("then step, then end", types[-2:] == ["step", "end"] and
          types == ["state", "state"] + ["iteration"] * len(iterations) + ["step", "end"], types[-5:])
    end = events[-1]
    check("end event fields", END_FIELDS <= set(end) and end["state"] == "SUCCEEDED" and
          end["stop_reason"] == "converged" and end["converged"] is True, end)

    final = server.job(job_id)
    check("job SUCCEEDED and done", final["state"] == "SUCCEEDED" and final["done"] is True and
          final["converged"] is True and final["result_available"] is True, final)
    check("iterations and progress", final["iterations"] == len(iterations) and
          final["progress"]["iteration"] == len(iterations), final.get("progress"))

    # The same events as NDJSON, and resumption with Last-Event-ID (header and query).
    nd = read_all_events(server, job_id, ndjson=True)
    check("NDJSON replay equals the SSE events",
          [json.dumps(e, sort_keys=True) for e in nd] ==
          [json.dumps({k: v for k, v in e.items() if not k.startswith("_")}, sort_keys=True) for e in events])
    s = Stream(server, job_id, last_event_id=5)
    resumed = s.events_until_end()
    s.close()
    check("Last-Event-ID resumes after that seq", [e["seq"] for e in resumed] == seqs[5:], [e["seq"] for e in resumed][:5])
    s = Stream(server, job_id, ndjson=True, query="?last_event_id=%d" % (len(events) - 1))
    tail = s.events_until_end()
    s.close()
    check("?last_event_id resumes too", [e["type"] for e in tail] == ["end"], tail)

    # Download and compare with contact-solve's file for the same job.
    r = server.get(f"/v1/jobs/{job_id}/result")
    check("result 200 application/x-hdf5", r.status == 200 and r.content_type == "application/x-hdf5", r.headers)
    check("Content-Length", int(r.headers.get("content-length", -1)) == len(r.body) and len(r.body) > 1000)
    etag = r.headers.get("etag")
    check("ETag", bool(etag), r.headers)
    r304 = server.get(f"/v1/jobs/{job_id}/result", headers={"If-None-Match": etag})
    check("If-None-Match gives 304", r304.status == 304, r304)
    server_file = os.path.join(tmp, "server.hdf")
    with open(server_file, "wb") as f:
        f.write(r.body)
    job_file = os.path.join(tmp, "seed_layers.json")
    with open(job_file, "w") as f:
        json.dump(job, f)
    cli_file = os.path.join(tmp, "cli.hdf")
    cli = subprocess.run([CONTACT_SOLVE, job_file, "-o", cli_file, "-q"], capture_output=True, text=True, timeout=120)
    check("contact-solve ran", cli.returncode == 0, cli.stderr)
    diffs = compare_h5(server_file, cli_file) if cli.returncode == 0 else ["no CLI file"]
    check("downloaded file equals contact-solve's in its numbers", not diffs, diffs)
    with h5py.File(server_file, "r") as f:
        check("file names the job id", f.attrs["job_id"] == job_id, f.attrs.get("job_id"))
    r = server.get(f"/v1/jobs/{job_id}/result.xmf")
    check("result.xmf served", r.status == 200 and b"result.hdf:/steps/0/bodies" in r.body, r)

    # --- list and paging ------------------------------------------------------------------------------------
    ids = [job_id]
    for k in range(6):
        ids.append(server.submit_id(flat_patch(-0.001 * (k + 1), name=f"patch{k}")))
    for i in ids:
        server.wait_done(i)
    seen, token, pages = [], "", 0
    while pages < 10:
        r = server.get(f"/v1/jobs?page_size=3&page_token={token}")
        page = r.json()
        seen += [j["id"] for j in page["jobs"]]
        pages += 1
        token = page["next_page_token"]
        if not token:
            break
    check("paging visits every job once, newest first", seen == list(reversed(ids)) and pages == 3, (pages, seen))
    r = server.get("/v1/jobs?state=succeeded&page_size=500")
    check("state filter", r.status == 200 and len(r.json()["jobs"]) == 7 and
          all(j["state"] == "SUCCEEDED" for j in r.json()["jobs"]), r)
    check("state filter with no match", server.get("/v1/jobs?state=RUNNING").json()["jobs"] == [])
    check("page_size above 500 is coerced", server.get("/v1/jobs?page_size=100000").status == 200)

    # --- metrics --------------------------------------------------------------------------------------------
    text = server.get("/metrics").body.decode()
    check("metrics: jobs by state", 'contactd_jobs{state="SUCCEEDED"} 7' in text, text[:800])
    check("metrics: submitted", server.metric("contactd_jobs_submitted_total") == 7)
    check("metrics: iterations", (server.metric("contactd_iterations_total") or 0) >= len(iterations))
    check("metrics: solve seconds", (server.metric("contactd_solve_seconds_total") or 0) > 0)
    check("metrics: requests by code", 'contactd_http_requests_total{code="202"} 7' in text)
    check("metrics: queue length and streams", server.metric("contactd_queue_length") == 0 and
          server.metric("contactd_stream_clients") == 0, text)

    # --- delete ---------------------------------------------------------------------------------------------
    job_dir = os.path.join(server.data_dir, "jobs", ids[1])
    check("job directory exists", os.path.isdir(job_dir))
    r = server.request("DELETE", f"/v1/jobs/{ids[1]}")
    check("DELETE 204", r.status == 204, r)
    check("deleted job is 404", server.get(f"/v1/jobs/{ids[1]}").status == 404)
    check("deleted job's files are gone", not os.path.exists(job_dir), os.listdir(os.path.dirname(job_dir)))
    check("DELETE again 404", server.request("DELETE", f"/v1/jobs/{ids[1]}").status == 404)
    # A client that deletes as soon as it sees `end` must not get 409: the server waits for the job to settle
    # (its `end` event is visible a moment before the event log is synced). Repeated to catch the race.
    statuses = []
    for i in range(15):
        jid = server.submit(flat_patch(name=f"race-{i}")).json()["id"]
        events = read_all_events(server, jid)
        statuses.append((events[-1]["type"] if events else None, server.request("DELETE", f"/v1/jobs/{jid}").status))
    check("DELETE right after the end event succeeds", all(s == ("end", 204) for s in statuses), statuses)
    check("still listed: the others", len(server.get("/v1/jobs").json()["jobs"]) == 6)

    # The data directory holds what docs/server.md says.
    files = sorted(os.listdir(os.path.join(server.data_dir, "jobs", job_id)))
    check("data dir layout", files == ["events.ndjson", "job.json", "pairs.json", "result.hdf", "result.xmf", "state.json"], files)
    with open(os.path.join(server.data_dir, "jobs", job_id, "job.json"), "rb") as f:
        check("job.json is the body as submitted", f.read() == json.dumps(job).encode())
    with open(os.path.join(server.data_dir, "jobs", job_id, "events.ndjson")) as f:
        lines = [json.loads(l) for l in f]
    check("events.ndjson holds every event", [e["seq"] for e in lines] == seqs)

    # Every path of api/openapi.yaml exists on the server (no 404 for the route itself).
    with open(os.path.join(SRC, "api", "openapi.yaml")) as f:
        paths = re.findall(r"^  (/[^:\s]+):\s*$", f.read(), re.M)
    missing = []
    for path in paths:
        concrete = path.replace("{id}", job_id).replace("{type}", "invalid-job").replace("{name}", "flat_patch")
        concrete = concrete.replace("{path}", "app.js")
        r = server.get(concrete)
        if r.status == 404:
            missing.append(path)
    check("every documented path is served", len(paths) >= 13 and not missing, (paths, missing))
    check("./job.schema.json resolves next to /v1/openapi.yaml", server.get("/v1/job.schema.json").body ==
          server.get("/v1/schema").body)

    # The Gmsh example as served solves on the server (last: the checks above count the jobs).
    gmsh_id = server.submit_id(server.get("/v1/examples/flat_patch_gmsh").json())
    done = server.wait_done(gmsh_id)
    check("the served Gmsh example solves on the server", done and done["state"] == "SUCCEEDED", done)

    check("server still alive", server.proc.poll() is None)

finish()
