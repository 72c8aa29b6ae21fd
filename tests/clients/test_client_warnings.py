#!/usr/bin/env python3
"""Models that are wrong say so, through the server and the client (issue 49, items 1 and 2): the model checks'
warnings reach every place a user reads (docs/job-format.md, "Warnings").

- A stack whose top block is drawn 5 mm into the block below (an undeclared overlap) and 1 cm above it (a pair open
  everywhere, then a block that falls 1 cm as a rigid body): /v1/validate lists the job's warning with its pointer,
  the normalized job too; the submission's answer has it; once done the job resource and its end event have the
  job's and the answer's; the result file's /warnings and the client's ResultFile.warnings() have them.
- The client: `validate` and `submit --wait` print each as "warning: <pointer>: <message>" on stderr, the exit code
  unchanged; `status` lists them.
- A strict job ("strict": true) with the overlap is refused (400, the warning as an error at its pointer); the
  same stack drawn right gets no warning anywhere.

Standard library + h5py (Debian). Starts contactd through tests/server/harness.py. Exits 1 on any failure."""
import json
import os
import subprocess
import sys
import tempfile

from client_paths import CLIENT  # noqa: E402  (sets the import path)

import contact_client as cc  # noqa: E402
from harness import Server  # noqa: E402
from checks import check, finish, section  # noqa: E402


def stack(lift=0.0):
    """Three blocks on a clamped base under their weight (kN, m), Coulomb joints; the top one lifted by `lift`."""
    def block(name, y0, y1):
        return {"name": name, "material": {"E": 2.5e7, "nu": 0.2},
                "mesh": {"block": {"corners": [[0, y0], [1, y0], [1, y1], [0, y1]], "nx": 8, "ny": 4}},
                "body_force": [0, -25e3]}
    base = block("base", 0, 0.5)
    base["boundary"] = [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]
    return {"name": "stack", "bodies": [base, block("b1", 0.5, 1.0), block("b2", 1.0 + lift, 1.5 + lift)],
            "contacts": [{"slave": "b1.bottom", "master": "base.top", "friction": {"coefficient": 0.6}},
                         {"slave": "b2.bottom", "master": "b1.top", "friction": {"coefficient": 0.6}}]}


def pointers(warnings):
    return [w.get("pointer") for w in warnings or []]


def client(url, *args):
    return subprocess.run([sys.executable, CLIENT, *args], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "CONTACT_URL": url})


def warning_lines(text):
    return [line for line in text.splitlines() if line.startswith("warning: ")]


with Server() as server, tempfile.TemporaryDirectory() as tmp:
    url = f"http://127.0.0.1:{server.port}"

    with section("an overlap: validate and the normalized job"):
        r = server.request("POST", "/v1/validate", json_body=stack(-0.005))
        answer = r.json()
        check("valid, with one warning at the pair", r.status == 200 and pointers(answer.get("warnings")) ==
              ["/contacts/1"], answer.get("warnings"))
        check("the warning says the overlap and the node", "overlap by up to 0.005 " in
              (answer.get("warnings") or [{}])[0].get("message", ""), answer.get("warnings"))
        check("the normalized job lists it, and the pair's default fit",
              pointers(answer.get("normalized", {}).get("warnings")) == ["/contacts/1"] and
              answer["normalized"]["contacts"][1].get("fit") == "touching", answer.get("normalized", {}).get("warnings"))
        path = os.path.join(tmp, "overlap.json")
        with open(path, "w") as f:
            json.dump(stack(-0.005), f)
        v = client(url, "validate", path)
        check("client validate: exit 0, the warning on stderr with its pointer",
              v.returncode == 0 and len(warning_lines(v.stderr)) == 1 and
              warning_lines(v.stderr)[0].startswith("warning: /contacts/1: the edges of pair 'b2.bottom-b1.top'"),
              (v.returncode, v.stderr))

    with section("a gap: submit, the end, the result file"):
        path = os.path.join(tmp, "lifted.json")
        with open(path, "w") as f:
            json.dump(stack(0.01), f)
        out = os.path.join(tmp, "lifted.hdf")
        s = client(url, "submit", "--wait", "-q", "-o", out, path)
        lines = warning_lines(s.stderr)
        check("client submit --wait: exit 0, the job's warning then the answer's",
              s.returncode == 0 and len(lines) == 2 and lines[0].startswith("warning: /contacts/1: ") and
              lines[1].startswith("warning: /bodies/2: body 'b2' is held by its contacts alone"), (s.returncode, lines))
        job_id = s.stdout.strip().splitlines()[0]
        job = server.job(job_id)
        check("the job resource has both", job.get("state") == "SUCCEEDED" and
              pointers(job.get("warnings")) == ["/contacts/1", "/bodies/2"], job.get("warnings"))
        ends = [e for e in cc.Client(url).events(job_id) if e.get("type") == "end"]
        check("the end event has both", len(ends) == 1 and pointers(ends[0].get("warnings")) ==
              ["/contacts/1", "/bodies/2"], ends)
        with cc.ResultFile(out) as f:
            stored = f.warnings()
        check("the result file's /warnings has both, as the job lists them", stored == job.get("warnings"), stored)
        st = client(url, "status", job_id)
        check("client status lists them", st.returncode == 0 and st.stdout.count("warning:") == 2, st.stdout)

    with section("strict, and a stack drawn right"):
        strict = stack(-0.005)
        strict["strict"] = True
        r = server.submit(strict)
        errors = r.json().get("errors", []) if r.status == 400 else []
        check("a strict job with the overlap is refused at the pair", r.status == 400 and
              pointers(errors) == ["/contacts/1"] and "strict" in errors[0].get("message", ""), (r.status, errors))
        r = server.submit(stack())
        job_id = r.json().get("id")
        done = server.wait_done(job_id, 60)
        check("the stack drawn right: no warning at submission, none once done",
              r.json().get("warnings") == [] and done.get("state") == "SUCCEEDED" and done.get("warnings") == [],
              (r.json().get("warnings"), done.get("warnings")))

finish()
