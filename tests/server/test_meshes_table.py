#!/usr/bin/env python3
"""One Gmsh file of a few MB, three bodies (issue 23, item 1): a 3-body job from one 3 MB .msh was refused with 413,
because the client pasted the file's text once per body (3 x 3 MB > 8 MiB), and the result held the text six
times. Now the client sends each file once, in the job's "meshes" table, and the job goes through contactd with
its default limits; the stored job and the result file hold the text once; the 413 a job sent the old way gets
names the request's size, the limit and --max-request-bytes.

The mesh: tests/data/stack3_gmsh.geo meshed by the gmsh command (skipped without it), three stacked blocks with the
middle one fine. Pressed by d along y with x = 0 held on the left, the stack of height 3 is in uniaxial
compression (plane strain, sigma_xx = 0): the contact pressure is p = E d / (3 (1 - nu^2)) on both contacts,
exactly on any mesh."""
import json
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(SRC, "clients"))
sys.path.insert(0, os.path.join(HERE, ".."))  # tests/: checks.py

import h5py  # noqa: E402
import numpy as np  # noqa: E402

import contact_client as cc  # noqa: E402
from harness import Server  # noqa: E402
from checks import check, finish, skip  # noqa: E402

CLIENT = os.path.join(SRC, "clients", "contact_client.py")
LIMIT = 8 * 1024 * 1024  # contactd's default --max-request-bytes
E, NU, D = 2.1e5, 0.3, 0.003

if not shutil.which("gmsh"):
    skip("no gmsh command to mesh tests/data/stack3_gmsh.geo (Debian's gmsh)")

tmp = tempfile.mkdtemp(prefix="meshes-table-")
msh = os.path.join(tmp, "stack.msh")
subprocess.run(["gmsh", "-2", os.path.join(SRC, "tests", "data", "stack3_gmsh.geo"), "-format", "msh41", "-o", msh],
               check=True, capture_output=True, timeout=300)
with open(msh, encoding="utf-8") as f:
    text = f.read()
check("the file is a few MB, too large to send once per body within 8 MiB", LIMIT / 3 < len(text) < LIMIT,
      len(text))


def body(name, boundary):
    return {"name": name, "material": {"E": E, "nu": NU},
            "mesh": {"gmsh": {"file": "stack.msh", "surface": name}}, "boundary": boundary}


left = {"edge": "left", "displacement": {"x": 0}}
job = {"name": "stack3_gmsh",
       "bodies": [body("lower", [left, {"edge": "lower_bottom", "displacement": {"y": 0}}]),
                  body("middle", [left]),  # held by its two contacts in y
                  body("upper", [left, {"edge": "upper_top", "displacement": {"y": -D}}])],
       "contacts": [{"slave": "lower.lower_top", "master": "middle.middle_bottom"},
                    {"slave": "upper.upper_bottom", "master": "middle.middle_top"}]}
job_path = os.path.join(tmp, "job.json")
with open(job_path, "w") as f:
    json.dump(job, f)

with Server() as server:
    url = f"http://127.0.0.1:{server.port}"
    # The old way, the text once per body: 413 naming the size, the limit and the setting.
    old = json.loads(json.dumps(job))
    for b in old["bodies"]:
        b["mesh"]["gmsh"] = {"data": text, "surface": b["name"]}
    old_body = json.dumps(old).encode()
    r = server.request("POST", "/v1/jobs", body=old_body, headers={"Content-Type": "application/json"}, timeout=120)
    problem = r.json() or {}
    detail = problem.get("detail", "")
    check("the text once per body: 413", r.status == 413, r)
    check("the 413 names the request's size, the limit and --max-request-bytes",
          str(len(old_body)) in detail and str(LIMIT) in detail and "--max-request-bytes" in detail
          and '"meshes"' in detail and problem.get("limit_bytes") == LIMIT
          and problem.get("request_bytes") == len(old_body) and problem.get("setting") == "--max-request-bytes",
          problem)

    # The client, as a user runs it: the file goes once into the job's "meshes" table.
    sent = json.loads(cc.Client._job_body(job_path))
    check("the client sends the file once, in the table, the bodies by name",
          list(sent["meshes"]) == ["stack"] and sent["meshes"]["stack"] == {"data": text}
          and all(b["mesh"]["gmsh"] == {"mesh": "stack", "surface": b["name"]} for b in sent["bodies"]),
          {k: v for k, v in sent.items() if k != "meshes"})
    out = subprocess.run([sys.executable, CLIENT, "--url", url, "submit", job_path], capture_output=True, text=True,
                         timeout=120)
    job_id = out.stdout.strip()
    check("submitted through the client with the default limits", out.returncode == 0 and job_id, out)
    client = cc.Client(url)
    final = client.wait(job_id, read_timeout=300)
    check("the job SUCCEEDED", final.get("state") == "SUCCEEDED", final)
    result = os.path.join(tmp, "result.hdf")
    client.download(job_id, result)

    p_ = E * D / (3 * (1 - NU ** 2))
    with h5py.File(result, "r") as h:
        last = h["steps"][str(h["steps"].attrs["count"] - 1)]
        pairs = [n.decode() if isinstance(n, bytes) else str(n) for n in last.attrs["pair_names"]]
        t = last["contacts"]  # every pair's rows in one table: pair p's from offsets[p] to offsets[p + 1]
        for pair in ("lower.lower_top-middle.middle_bottom", "upper.upper_bottom-middle.middle_top"):
            p = pairs.index(pair)
            rows = slice(int(t["offsets"][p]), int(t["offsets"][p + 1]))
            pressure = t["pressure"][rows][t["status"][rows] == 0]
            check(f"{pair}: the uniform pressure E d / (3 (1 - nu^2)) to 1e-6",
                  len(pressure) > 0 and np.abs(pressure / p_ - 1).max() < 1e-6, (p_, pressure.min(), pressure.max()))
            check(f"{pair}: the force p x 2 to 1e-6", abs(t["force"][p] / (2 * p_) - 1) < 1e-6, t["force"][p])
        check("the middle body is the fine one", last["bodies/middle/points"].shape[0] > 30000,
              last["bodies/middle/points"].shape)
        submitted = json.loads(h["input/job"].asstr()[()])
        normalized = json.loads(h["input/normalized"].asstr()[()])
    check("/input/job holds the text once, in its table", submitted["meshes"]["stack"]["data"] == text)
    check("/input/normalized gives its size only", normalized["meshes"]["stack"] == {"data_bytes": len(text.encode())},
          normalized.get("meshes"))
    marker = text.splitlines()[-3].encode()  # a line of the file's $Elements
    with open(result, "rb") as f:
        stored = f.read()
    check("the result file holds the text once", stored.count(b"$MeshFormat") == 1 and stored.count(marker) == 1,
          (stored.count(b"$MeshFormat"), stored.count(marker)))
    with open(os.path.join(server.data_dir, "jobs", job_id, "job.json"), "rb") as f:
        stored_job = f.read()
    check("the stored job holds the text once", stored_job.count(b"$MeshFormat") == 1 and stored_job.count(marker) == 1)
    print(f"{len(text) / 1e6:.1f} MB mesh, request {len(json.dumps(sent)) / 1e6:.1f} MB "
          f"(once per body: {len(old_body) / 1e6:.1f} MB), result {len(stored) / 1e6:.1f} MB", flush=True)

shutil.rmtree(tmp, ignore_errors=True)
finish()
