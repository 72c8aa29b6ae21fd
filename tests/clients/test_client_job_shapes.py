#!/usr/bin/env python3
"""The client sends jobs of any shape to the server and shows the server's verdict (issue 22, defect 10): a job
whose "bodies" is not a list ({"bodies": 3}) used to end in "internal error of the client: TypeError" while the
client looked for Gmsh mesh files to put in; it must show the server's validation error with its pointer
/bodies (exit 2), as a command and as a module.

Starts contactd through tests/server/harness.py. Standard library only."""
import json
import os
import subprocess
import sys
import tempfile

from client_paths import CLIENT, EXAMPLES, HERE, SRC  # noqa: E402,F401  (sets the import path)

import contact_client as cc  # noqa: E402
from harness import Server  # noqa: E402
from checks import check, finish  # noqa: E402


# Each job and the pointer the server's error is at.
SHAPES = {
    "bodies a number": ({"bodies": 3}, "/bodies"),
    "bodies a string": ({"bodies": "two blocks"}, "/bodies"),
    "bodies an object": ({"bodies": {"mesh": {"gmsh": {"file": "x.msh"}}}}, "/bodies"),
    "bodies null": ({"bodies": None}, "/bodies"),
    "a body a number": ({"bodies": [3]}, "/bodies/0"),
}


def main():
    tmp = tempfile.mkdtemp(prefix="client-shapes-")
    with Server() as server:
        url = f"http://127.0.0.1:{server.port}"
        client = cc.Client(url)
        for name, (job, pointer) in SHAPES.items():
            path = os.path.join(tmp, name.replace(" ", "_") + ".json")
            with open(path, "w") as f:
                json.dump(job, f)
            for command in ("validate", "submit"):
                r = subprocess.run([sys.executable, CLIENT, command, path, "--url", url], capture_output=True,
                                   text=True, timeout=60)
                check(f"{name}: {command} exits 2 (invalid job)", r.returncode == 2, (r.returncode, r.stderr[-300:]))
                check(f"{name}: {command} shows the server's error at {pointer}",
                      f"error: 400 invalid job: {pointer}: " in r.stderr, r.stderr[-300:])
                check(f"{name}: {command} does not crash", "internal error of the client" not in r.stderr and
                      "Traceback" not in r.stderr, r.stderr[-300:])
            try:
                client.validate(path)
                check(f"{name}: Client.validate raises", False)
            except cc.ApiError as exc:
                check(f"{name}: Client.validate raises ApiError with the pointer {pointer}",
                      exc.status == 400 and any(e.get("pointer") == pointer for e in exc.errors), exc.errors)
    finish()


if __name__ == "__main__":
    main()
