#!/usr/bin/python3
"""scripts/setup.sh, docker/Dockerfile and .dockerignore kept in step, without a Docker engine: every setup.sh
mode the Dockerfile and the scripts use exists; the runtime packages provide every shared library the two
binaries load directly (read from their ELF headers and dpkg); the build stage installs no test package and
builds only the two programs; .dockerignore keeps build directories, data, results and .git out of the context
and nothing the build needs; the quick start builds only the CLI and the server, the test command switches the
tests back on.

Prints one line per failure and "N passed, M failed"; exits non-zero on any failure."""
import os
import re
import subprocess
import sys

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
sys.path.insert(0, os.path.join(SRC, "tests"))  # checks.py
from checks import check, finish  # noqa: E402

BASE_IMAGE_PACKAGES = {"libc6", "libgcc-s1", "libstdc++6"}  # in debian:bookworm (apt depends on them)


def read(*path):
    with open(os.path.join(SRC, *path), encoding="utf-8") as f:
        return f.read()


def package_lists(text):
    """{ARRAY_NAME: [packages]} of setup.sh's bash arrays (comments dropped)."""
    lists = {}
    for name, body in re.findall(r"^([A-Z_]+_PACKAGES)=\((.*?)^\)", text, re.S | re.M):
        lists[name] = [w for line in body.splitlines() for w in line.split("#")[0].split()]
    return lists


def needed_libraries(binary):
    """{library name: the file the dynamic linker loads} for the libraries the binary names itself (NEEDED)."""
    dynamic = subprocess.run(["readelf", "-d", binary], capture_output=True, text=True).stdout
    names = re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", dynamic)
    resolved = dict(re.findall(r"^\s*(\S+) => (/\S+)", subprocess.run(["ldd", binary], capture_output=True,
                                                                      text=True).stdout, re.M))
    return {name: resolved.get(name) for name in names}


def owners(paths):
    """{path: the Debian package that installed it} in one dpkg call (with merged /usr, dpkg may know a file under
    /lib or /usr/lib, by its name or by the name its symbolic link points to)."""
    variants = {}
    for path in filter(None, paths):
        real = os.path.realpath(path)
        for candidate in (path, real, "/usr" + path, "/usr" + real, path.replace("/usr/lib/", "/lib/", 1),
                          real.replace("/usr/lib/", "/lib/", 1)):
            variants.setdefault(candidate, path)
    out = subprocess.run(["dpkg", "-S", *variants], capture_output=True, text=True).stdout
    found = {}
    for line in out.splitlines():
        package, _, file = line.partition(": ")
        if file in variants:
            found.setdefault(variants[file], package.split(":")[0].strip())
    return found


def pattern_regex(pattern):
    """A .dockerignore pattern as a regular expression on context-relative paths: '*' and '?' within one path
    element, '**' any number of elements, a trailing '/' dropped (Docker cleans the pattern)."""
    parts = pattern.strip().rstrip("/").split("/")
    out = ""
    for i, part in enumerate(parts):
        if part == "**":
            out += "(?:[^/]+/)*"
            continue
        out += "".join("[^/]*" if c == "*" else "[^/]" if c == "?" else re.escape(c) for c in part)
        out += "/" if i < len(parts) - 1 else ""
    return re.compile("^" + out + "$")


def ignored(path, patterns):
    """Whether the patterns exclude the path or one of its parent directories (which takes its contents). As Docker
    reads them: the last pattern that matches decides, and a pattern starting with '!' takes the path back in."""
    parts = path.split("/")
    prefixes = ["/".join(parts[:k]) for k in range(1, len(parts) + 1)]
    out = False
    for p in patterns:
        negated = p.startswith("!")
        if any(pattern_regex(p[1:] if negated else p).match(prefix) for prefix in prefixes):
            out = not negated
    return out


setup = read("scripts", "setup.sh")
lists = package_lists(setup)
check("setup.sh: build, client, test and runtime lists", {"BUILD_PACKAGES", "CLIENT_PACKAGES", "TEST_PACKAGES",
                                                          "RUNTIME_PACKAGES"} <= set(lists), sorted(lists))
modes = set(re.findall(r"^\s*(--[a-z]+)\)", setup, re.M))
dockerfile = read("docker", "Dockerfile")
used = set(re.findall(r"setup\.sh (--[a-z]+)", dockerfile + read("scripts", "quickstart.sh")))
check("every setup.sh mode the Dockerfile and quickstart.sh use exists", used and used <= modes, (used, modes))
check("the build stage installs the build packages only", "RUN bash /src/scripts/setup.sh --build" in dockerfile)
test_only = set(lists.get("TEST_PACKAGES", [])) & set(lists.get("BUILD_PACKAGES", []) + lists.get("RUNTIME_PACKAGES", []))
check("no test package in the build or runtime lists", not test_only, test_only)
check("the test stage is its own, on demand", re.search(r"^FROM build AS test$", dockerfile, re.M)
      and re.search(r"^FROM debian:bookworm AS runtime$", dockerfile, re.M)
      and dockerfile.rstrip().splitlines()[-1].startswith("ENTRYPOINT"), "stages")
check("the image builds only contact-solve and contactd, without tests and benchmarks",
      "-DCONTACT_BUILD_TESTS=OFF -DCONTACT_BUILD_BENCH=OFF" in dockerfile
      and "--target contact-solve contactd" in dockerfile)
check("the runtime user is non-root in group 0 and /data is group-writable",
      re.search(r"useradd .*--uid 10001 --gid 0", dockerfile) and "chmod 2775 /data" in dockerfile
      and "USER 10001:0" in dockerfile)
check("the Dockerfile documents --user for a host folder", '--user "$(id -u):$(id -g)"' in dockerfile)

runtime = set(lists.get("RUNTIME_PACKAGES", [])) | BASE_IMAGE_PACKAGES
for binary in (os.path.join(BIN, "contact-solve"), os.path.join(BIN, "server", "contactd")):
    libraries = needed_libraries(binary)
    check(f"{os.path.basename(binary)}: its libraries read", len(libraries) >= 4, libraries)
    packages = owners(libraries.values())
    missing = {lib: packages.get(path) for lib, path in libraries.items() if packages.get(path) not in runtime}
    check(f"{os.path.basename(binary)}: the runtime packages provide every library it loads", not missing, missing)

patterns = [line.strip() for line in read(".dockerignore").splitlines() if line.strip() and not line.startswith("#")]
for path in ("build/CMakeCache.txt", "build-debug/x.o", "out/seed_layers.hdf", "contactd-data/jobs/x/state.json",
             ".git/HEAD", "seed.hdf", "clients/contact_client/__pycache__/cli.cpython-311.pyc", "api/examples/x.xmf"):
    check(f".dockerignore leaves out {path}", ignored(path, patterns), patterns)
tracked = subprocess.run(["git", "-C", SRC, "ls-files"], capture_output=True, text=True).stdout.split()
needed = [p for p in tracked if not p.startswith(("docker/", ".ci/", ".dockerignore"))]
dropped = [p for p in needed if ignored(p, patterns)]
check("the context keeps every source file", needed and not dropped, dropped[:20])

quickstart = read("scripts", "quickstart.sh")
check("quickstart.sh builds only the CLI and the server",
      "-DCONTACT_BUILD_TESTS=OFF -DCONTACT_BUILD_BENCH=OFF" in quickstart
      and "--target contact-solve contactd" in quickstart)
check("test.sh switches the tests and benchmarks on", "-DCONTACT_BUILD_TESTS=ON -DCONTACT_BUILD_BENCH=ON"
      in read("scripts", "test.sh"))
finish()
