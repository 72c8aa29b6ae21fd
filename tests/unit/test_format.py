#!/usr/bin/env python3
"""The product code (solver/, server/, cli/: every .cpp and .hpp git tracks) is formatted as .clang-format says:
`clang-format --dry-run --Werror` finds nothing to change in any file. To format what you changed:
    clang-format -i $(git diff --name-only -- '*.cpp' '*.hpp')
Debian's clang-format (scripts/setup.sh installs it); another major version formats some lines differently, so the
check runs with the version found, and says which."""
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/
from checks import check, finish, skip  # noqa: E402

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
tool = shutil.which("clang-format")
if not tool:
    skip("clang-format is not installed (scripts/setup.sh installs it)")
print(subprocess.run([tool, "--version"], capture_output=True, text=True).stdout.strip())
listed = subprocess.run(["git", "-C", SRC, "ls-files", "-co", "--exclude-standard", "--", "solver", "server", "cli"],
                        capture_output=True, text=True)
files = [f for f in listed.stdout.split() if f.endswith((".cpp", ".hpp"))]
if listed.returncode != 0 or not files:  # not a git checkout (a source archive): every file below the folders
    files = [os.path.relpath(os.path.join(root, name), SRC) for tree in ("solver", "server", "cli")
             for root, _, names in os.walk(os.path.join(SRC, tree)) for name in names
             if name.endswith((".cpp", ".hpp"))]
check("there are files to check", len(files) > 100, len(files))
for start in range(0, len(files), 50):
    batch = files[start:start + 50]
    run = subprocess.run([tool, "--dry-run", "--Werror", *batch], cwd=SRC, capture_output=True, text=True)
    if run.returncode != 0:
        wrong = sorted({line.split(":")[0] for line in run.stderr.splitlines() if ": error:" in line})
        check(f"files {start + 1}-{start + len(batch)} formatted as .clang-format says", False,
              f"{len(wrong)} files differ: {', '.join(wrong[:10])}\n{run.stderr[:1500]}")
    else:
        check(f"files {start + 1}-{start + len(batch)} formatted as .clang-format says", True)
finish()
