#!/usr/bin/env python3
"""Hostile and careless requests against a server with a bearer token: each gets the right 4xx with an RFC 9457
problem document (status matching), nothing is created, and the server keeps serving (a real job still runs)."""
import json
import os
import sys
import time
import uuid

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import Server, example, flat_patch  # noqa: E402
from checks import check, finish  # noqa: E402


TOKEN = "s3cret-token-for-tests"
JSON = {"Content-Type": "application/json"}

with Server(token=TOKEN, args=["--workers", "1", "--max-dofs", "100000"]) as server:
    good = json.dumps(example("flat_patch.json")).encode()
    valid_id = server.submit_id(flat_patch(name="known"))
    server.wait_done(valid_id)
    count = 0

    def expect(name, response, status, pointer=None, problem_type=None):
        """The response has `status`, is a problem document, and (optionally) lists `pointer` / has the type."""
        global count
        count += 1
        ok = response.status == status and response.is_problem()
        doc = response.json() or {}
        if ok and pointer is not None:
            ok = any(e.get("pointer") == pointer for e in doc.get("errors", []))
        if ok and problem_type is not None:
            ok = doc.get("type") == problem_type
        check(f"{name} -> {status}", ok, response)
        alive = server.get("/healthz", timeout=10)
        check(f"still serving after: {name}", alive.status == 200, alive)

    def post(body, headers=JSON, path="/v1/jobs", **kw):
        return server.request("POST", path, body=body, headers=headers, **kw)

    # Bodies that are not (acceptable) JSON.
    expect("malformed JSON", post(b'{"bodies": ['), 400, pointer="", problem_type="/problems/invalid-job")
    expect("NaN literal", post(good.replace(b'"E": 210000.0', b'"E": NaN')), 400, pointer="")
    expect("1e308", post(good.replace(b'"E": 210000.0', b'"E": 1e308', 1)), 400, pointer="/bodies/0/material/E")
    expect("1e400", post(good.replace(b'"E": 210000.0', b'"E": 1e400', 1)), 400)
    expect("deep nesting", post(b"[" * 100000 + b"]" * 100000), 400, pointer="")
    expect("deep nesting inside a field", post(good[:-1] + b', "x": ' + b"[" * 5000 + b"]" * 5000 + b"}"), 400)
    expect("unknown field", post(json.dumps(dict(example("flat_patch.json"), colour="red")).encode()), 400,
           pointer="/colour")
    bad = example("flat_patch.json")
    bad["solver"]["gama"] = 0.1
    expect("misspelt field", post(json.dumps(bad).encode()), 400, pointer="/solver/gama")
    expect("top-level array", post(b"[1, 2, 3]"), 400)
    expect("a bare number", post(b"42"), 400)
    expect("empty body", post(b""), 400)
    expect("invalid UTF-8", post(b'{"name": "\xff\xfe", "bodies": []}'), 400)
    expect("duplicate key", post(b'{"name": "a", "name": "b", "bodies": []}'), 400)
    huge = example("flat_patch.json")
    huge["bodies"][0]["mesh"]["block"]["nx"] = 1000000
    expect("more DOFs than --max-dofs", post(json.dumps(huge).encode()), 400, pointer="/bodies")

    # Wrong content type or encoding.
    expect("text/plain", post(good, headers={"Content-Type": "text/plain"}), 415)
    expect("no Content-Type", post(good, headers={}), 415)
    expect("form encoded", post(good, headers={"Content-Type": "application/x-www-form-urlencoded"}), 415)
    expect("Content-Encoding gzip", post(good, headers={"Content-Type": "application/json",
                                                        "Content-Encoding": "gzip"}), 415)

    # Oversize bodies (the default limit is 8 MiB).
    ten_mb = b'{"name": "' + b"x" * (10 * 1000 * 1000) + b'"}'
    expect("10 MB body", post(ten_mb), 413)
    conn = server.connection()
    conn.putrequest("POST", "/v1/jobs")
    conn.putheader("Content-Type", "application/json")
    conn.putheader("Authorization", "Bearer " + TOKEN)
    conn.putheader("Transfer-Encoding", "chunked")
    conn.endheaders()
    try:
        for _ in range(10):
            chunk = b"x" * (1 << 20)
            conn.send(b"%x\r\n%s\r\n" % (len(chunk), chunk))
        conn.send(b"0\r\n\r\n")
    except OSError:
        pass  # the server may close once it has answered
    resp = conn.getresponse()
    from harness import Response
    expect("10 MB chunked body", Response(resp.status, {k.lower(): v for k, v in resp.getheaders()}, resp.read()), 413)
    conn.close()
    raw = server.raw(b"POST /v1/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + TOKEN.encode() +
                     b"\r\nContent-Type: application/json\r\nContent-Length: 1000000000000\r\n\r\n{")
    count += 1
    check("Content-Length of 1 TB -> 413 at once", raw.startswith(b"HTTP/1.1 413") and b"problem+json" in raw, raw[:200])
    raw = server.raw(b"POST /v1/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + TOKEN.encode() +
                     b"\r\nContent-Type: application/json\r\n\r\n", timeout=5)
    count += 1
    check("POST without a length -> 411 at once", raw.startswith(b"HTTP/1.1 411") and b"problem+json" in raw, raw[:200])

    # Ids and paths.
    expect("id with ../", server.get("/v1/jobs/../../etc/passwd"), 404)
    expect("id with encoded ../", server.get("/v1/jobs/..%2F..%2Fetc%2Fpasswd"), 404)
    expect("id '..'", server.get("/v1/jobs/.."), 404)
    expect("result of id '..'", server.get("/v1/jobs/../result"), 404)
    expect("not a UUID", server.get("/v1/jobs/not-a-uuid"), 404)
    expect("upper-case UUID", server.get("/v1/jobs/" + valid_id.upper()), 404)
    expect("unknown UUID", server.get(f"/v1/jobs/{uuid.uuid4()}"), 404)
    expect("events of an unknown job", server.get(f"/v1/jobs/{uuid.uuid4()}/events"), 404)
    expect("delete of an unknown job", server.request("DELETE", f"/v1/jobs/{uuid.uuid4()}"), 404)
    expect("cancel of an unknown job", server.request("POST", f"/v1/jobs/{uuid.uuid4()}/cancel"), 404)
    expect("unknown route", server.get("/v1/nothing"), 404)

    # Wrong methods: 405 with Allow.
    r = server.request("PUT", "/v1/jobs", body=good, headers=JSON)
    expect("PUT /v1/jobs", r, 405)
    check("405 names the allowed methods", "POST" in r.headers.get("allow", ""), r.headers)
    expect("DELETE /v1/jobs", server.request("DELETE", "/v1/jobs"), 405)
    expect("PATCH a job", server.request("PATCH", f"/v1/jobs/{valid_id}", body=b"{}", headers=JSON), 405)
    expect("GET /v1/validate", server.get("/v1/validate"), 405)
    expect("POST to events", server.request("POST", f"/v1/jobs/{valid_id}/events", body=b"{}", headers=JSON), 405)
    expect("GET cancel", server.get(f"/v1/jobs/{valid_id}/cancel"), 405)

    # Authentication: every /v1 route needs the token; health and metrics do not.
    r = server.request("GET", "/v1/jobs", auth=False)
    expect("no token", r, 401)
    check("401 has WWW-Authenticate", r.headers.get("www-authenticate", "").startswith("Bearer"), r.headers)
    expect("wrong token", server.request("GET", "/v1/jobs", headers={"Authorization": "Bearer nope"}), 401)
    expect("token one character short", server.request("GET", "/v1/jobs",
                                                       headers={"Authorization": "Bearer " + TOKEN[:-1]}), 401)
    expect("wrong scheme", server.request("GET", "/v1/jobs", headers={"Authorization": "Basic " + TOKEN}), 401)
    expect("no token on submit", server.request("POST", "/v1/jobs", body=good, headers=JSON, auth=False), 401)
    expect("no token on result", server.request("GET", f"/v1/jobs/{valid_id}/result", auth=False), 401)
    check("token in any case of the scheme", server.request("GET", "/v1/jobs", headers={
        "Authorization": "bearer " + TOKEN}).status == 200)
    check("healthz, readyz, metrics stay open", all(server.request("GET", p, auth=False).status == 200
                                                    for p in ("/healthz", "/readyz", "/metrics")))

    # Bad parameters and headers.
    expect("page_size=abc", server.get("/v1/jobs?page_size=abc"), 400, problem_type="/problems/invalid-request")
    expect("page_size=-1", server.get("/v1/jobs?page_size=-1"), 400)
    expect("page_size=0", server.get("/v1/jobs?page_size=0"), 400)
    expect("forged page_token", server.get("/v1/jobs?page_token=!!not-base64!!"), 400)
    expect("state=DONE", server.get("/v1/jobs?state=DONE"), 400)
    expect("Last-Event-ID abc", server.get(f"/v1/jobs/{valid_id}/events", headers={"Last-Event-ID": "abc"}), 400)
    expect("Idempotency-Key too long", server.submit(flat_patch(), headers={"Idempotency-Key": "k" * 300}), 400)
    expect("Idempotency-Key with a control character",
           server.submit(flat_patch(), headers={"Idempotency-Key": "a\tb"}), 400)
    raw = server.raw(b"HELLO\r\n\r\n", timeout=5)
    count += 1
    check("garbage request line -> 400", raw.startswith(b"HTTP/1.1 400"), raw[:100])

    # Nothing above created a job; a real job still runs.
    jobs = server.get("/v1/jobs?page_size=500").json()["jobs"]
    check("no job created by the hostile requests", [j["id"] for j in jobs] == [valid_id], [j["name"] for j in jobs])
    check("a real job still runs", server.wait_done(server.submit_id(flat_patch()))["state"] == "SUCCEEDED")
    check(f"at least 30 hostile requests ({count})", count >= 30, count)
    print(f"{count} hostile requests")

finish()
