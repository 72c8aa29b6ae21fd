#!/usr/bin/python3
"""The Gmsh examples are what their .geo files make: every api/examples/*.geo meshed again by
scripts/make_gmsh_examples.sh (in a copy) gives its checked-in .msh byte for byte, and every .geo has its .msh and
a job that uses it. Needs Debian's gmsh 4.8.4 (the version that made the files; scripts/setup.sh installs it):
exits 77 (CTest: skipped) with a message saying why when gmsh is absent or another version."""
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
EXAMPLES = os.path.join(SRC, "api", "examples")
VERSION = "4.8.4"
sys.path.insert(0, os.path.join(SRC, "tests"))  # checks.py
from checks import check, finish, show_passes, skip  # noqa: E402


def main():
    show_passes()
    geos = sorted(glob.glob(os.path.join(EXAMPLES, "*.geo")))
    check("api/examples has .geo files", bool(geos))
    for geo in geos:
        stem = os.path.splitext(geo)[0]
        check(f"{os.path.basename(geo)} has its .msh", os.path.exists(stem + ".msh"))
        job = stem + ".json"
        uses = False
        if os.path.exists(job):
            with open(job) as f:
                uses = any(b["mesh"].get("gmsh", {}).get("file") == os.path.basename(stem) + ".msh"
                           for b in json.load(f)["bodies"])
        check(f"{os.path.basename(job)} uses {os.path.basename(stem)}.msh", uses)

    gmsh = shutil.which("gmsh")
    if gmsh is None:
        skip("gmsh is not installed (bash scripts/setup.sh installs it); the meshes were not remade")
    r = subprocess.run([gmsh, "--version"], capture_output=True, text=True, timeout=60)  # it prints on stderr
    version = ((r.stdout + r.stderr).strip().splitlines() or [""])[-1]
    if version != VERSION:
        skip(f"gmsh {version} is not {VERSION}, which made the checked-in meshes (other versions mesh differently)")
    with tempfile.TemporaryDirectory() as tmp:
        os.makedirs(os.path.join(tmp, "scripts"))
        shutil.copy(os.path.join(SRC, "scripts", "make_gmsh_examples.sh"), os.path.join(tmp, "scripts"))
        shutil.copytree(EXAMPLES, os.path.join(tmp, "api", "examples"))
        r = subprocess.run(["bash", os.path.join(tmp, "scripts", "make_gmsh_examples.sh")], capture_output=True,
                           text=True, timeout=300)
        check("scripts/make_gmsh_examples.sh runs", r.returncode == 0, r.stderr[-800:])
        for geo in geos:
            name = os.path.splitext(os.path.basename(geo))[0] + ".msh"
            made = os.path.join(tmp, "api", "examples", name)
            with open(os.path.join(EXAMPLES, name), "rb") as a, open(made, "rb") as b:
                check(f"{name} is what its .geo makes (else run scripts/make_gmsh_examples.sh)", a.read() == b.read())
    finish()


if __name__ == "__main__":
    main()
