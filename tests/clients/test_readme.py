#!/usr/bin/env python3
"""The walkthroughs of README.md and docs/server.md run as pasted.

Every ```sh and ```python block of the two files runs, in document order, in one bash session (python blocks
through /usr/bin/python3), against a live contactd, in a scratch directory that holds links to the repository's
api/, clients/, scripts/ and docs/ and to the build directory as build/ (so that the blocks' paths work and what
they write stays there). The session runs with `set -euo pipefail`, and curl fails on an HTTP error answer
(--fail-with-body): a command that fails, an unset variable, a refused request all fail the test, naming the
block. The only change made to the text is the port: the server started here listens on a free port, and
"127.0.0.1:8080" in the blocks is replaced by it.

Blocks preceded by an HTML comment "<!-- readme-test: skip (why) -->" do not run (the quick start, which builds,
and the test command); one marked "<!-- readme-test: server -->" starts contactd, which this test has started
already. The quick start runs too, with --no-build on the build under test, before the blocks (a README block
reads the files it writes). Also checked: README's table of examples lists api/examples/."""
import os
import re
import subprocess
import sys
import tempfile
import time

from client_paths import CLIENT, EXAMPLES, HERE, SRC  # noqa: E402,F401  (sets the import path)
from harness import BIN, Server  # noqa: E402
from checks import check, finish  # noqa: E402

DOCUMENTS = ["README.md", os.path.join("docs", "server.md")]


def blocks(path):
    """(line number, language, text, marker) of every fenced block of a markdown file; marker is the text of a
    "<!-- readme-test: ... -->" comment on the line before the fence, or None."""
    with open(os.path.join(SRC, path), encoding="utf-8") as f:
        lines = f.read().splitlines()
    found, i = [], 0
    while i < len(lines):
        m = re.match(r"^(\s*)```(\w*)\s*$", lines[i])
        if not m:
            i += 1
            continue
        indent, language, start = len(m.group(1)), m.group(2), i
        body = []
        i += 1
        while i < len(lines) and not re.match(r"^\s*```\s*$", lines[i]):
            body.append(lines[i][indent:])
            i += 1
        marker = None
        previous = lines[start - 1].strip() if start > 0 else ""
        mm = re.match(r"^<!-- readme-test: (.*?) -->$", previous)
        if mm:
            marker = mm.group(1)
        found.append((start + 1, language, "\n".join(body) + "\n", marker))
        i += 1
    return found


def session_script(port, runnable):
    """One bash script running every block in order; each announces itself on both streams."""
    parts = ["set -euo pipefail",
             # An HTTP error answer is a failure (the body is still shown).
             "curl() { command curl --fail-with-body \"$@\"; }",
             "export CONTACT_URL=http://127.0.0.1:%d" % port]
    for k, (document, line, language, text) in enumerate(runnable):
        text = text.replace("127.0.0.1:8080", f"127.0.0.1:{port}")
        label = f"{document}:{line} ({language})"
        parts.append(f"echo '@@ block {k}: {label}'; echo '@@ block {k}: {label}' >&2")
        if language == "python":
            parts.append(f"/usr/bin/python3 - <<'README_PYTHON_BLOCK'\n{text}README_PYTHON_BLOCK")
        else:
            parts.append(text)
    parts.append("echo '@@ all blocks ran'")
    return "\n".join(parts) + "\n"


def main():
    runnable, skipped, servers = [], [], 0
    for document in DOCUMENTS:
        for line, language, text, marker in blocks(document):
            if language not in ("sh", "python"):
                continue
            if marker and marker.startswith("skip"):
                skipped.append(f"{document}:{line}")
            elif marker == "server":
                servers += 1
                check(f"{document}:{line}: the server block starts contactd", "build/server/contactd" in text, text)
            else:
                runnable.append((document, line, language, text))
    check("the server is started by a marked block in each document", servers == len(DOCUMENTS), servers)
    check("only the quick start and the test command are skipped", len(skipped) == 2, skipped)
    check("blocks to run", len(runnable) >= 8, len(runnable))

    # README's table of examples is the directory.
    with open(os.path.join(SRC, "README.md"), encoding="utf-8") as f:
        readme = f.read()
    table = readme[readme.index("Examples in `api/examples/`"):]
    table = table[:table.index("\n\n", table.index("|"))]
    listed = set(re.findall(r"`([a-z0-9_]+\.json)`", table))
    files = {n for n in os.listdir(os.path.join(SRC, "api", "examples")) if n.endswith(".json")}
    check("README lists every example of api/examples/", listed == files,
          f"missing {sorted(files - listed)}, not a file {sorted(listed - files)}")

    with tempfile.TemporaryDirectory(prefix="contact-readme-") as tmp:
        for name in ("api", "clients", "scripts", "docs"):
            os.symlink(os.path.join(os.path.abspath(SRC), name), os.path.join(tmp, name))
        os.symlink(os.path.abspath(BIN), os.path.join(tmp, "build"))
        env = {k: v for k, v in os.environ.items()
               if not k.startswith(("CONTACT_URL", "CONTACT_TOKEN", "CONTACTD_"))}

        # The quick start on the build under test (it writes out/ here).
        t0 = time.time()
        r = subprocess.run(["bash", "scripts/quickstart.sh", "--no-build"], cwd=tmp, env=env, capture_output=True,
                           text=True, timeout=300)
        check("the quick start runs (--no-build)", r.returncode == 0, r.stdout[-1500:] + r.stderr[-1500:])
        for name in ("seed_layers.hdf", "seed_layers.xmf", "seed_layers.png"):
            check(f"the quick start writes out/{name}", os.path.isfile(os.path.join(tmp, "out", name)))
        check("the quick start streams the progress and stops the server",
              "end SUCCEEDED (converged)" in r.stderr and "stopped contactd" in r.stdout, r.stdout[-500:])
        print(f"quick start: {time.time() - t0:.1f} s", flush=True)

        with Server() as server:
            t0 = time.time()
            script = os.path.join(tmp, "session.sh")
            with open(script, "w") as f:
                f.write(session_script(server.port, runnable))
            r = subprocess.run(["bash", script], cwd=tmp, env=env, capture_output=True, text=True, timeout=300)
            ran = re.findall(r"^@@ block (\d+): (.*)$", r.stdout, re.M)
            failed_at = ran[-1][1] if ran and r.returncode != 0 else None
            check("every block runs as pasted", r.returncode == 0 and "@@ all blocks ran" in r.stdout,
                  f"exit {r.returncode} in {failed_at}:\n--- stdout\n{r.stdout[-2500:]}\n--- stderr\n{r.stderr[-2500:]}")
            print(f"{len(runnable)} blocks: {time.time() - t0:.1f} s", flush=True)
            if os.environ.get("README_TEST_SHOW"):
                print(r.stdout, r.stderr)
            check("the server is still there", server.proc.poll() is None)
    finish()


if __name__ == "__main__":
    main()
