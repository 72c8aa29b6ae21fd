#!/usr/bin/python3
"""The layering rules of docs/architecture.md against the includes of the code. Every `#include "..."` of solver/,
server/ and cli/ (and, for the first rule, of tests/ and bench/) is resolved as the compiler resolves it (the
including file's folder, then the target's include directories) and must

  - reach one file only (a name that two folders could answer, as "contact/x.hpp" once reached a private folder
    called contact/, is refused);
  - stay inside the public headers when it is made by a public header (solver/include/contact/);
  - go from a module to itself or to a module its row of the Layout table allows: the folders and files the
    "may use" column names, and what those may use in turn (the dependencies point one way). Every module may use
    solver/common/; the public headers belong to the module behind them (PUBLIC_HEADERS below).

The rules are read from the table, so the page and this check cannot drift apart: a folder without a row, or a
public header this file does not place, fails.

Prints one line per failure and "N passed, M failed"; exits non-zero on any failure."""
import os
import re
import sys

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SRC = os.path.realpath(SRC)
DOC = os.path.join(SRC, "docs", "architecture.md")

sys.path.insert(0, os.path.join(SRC, "tests"))  # checks.py
from checks import check, finish  # noqa: E402

PUBLIC_DIR = "solver/include/contact"
# The module behind each public header. contact/version.hpp, one declaration (solver_version(), defined in
# solve.cpp) that any module may call, counts as common's: like files.hpp, utc_time.hpp and background_work.hpp it
# includes nothing.
PUBLIC_HEADERS = {
    "mesh.hpp": "mesh", "problem.hpp": "problem", "result.hpp": "result", "solve.hpp": "solve",
    "session.hpp": "session", "job.hpp": "job", "result_file.hpp": "io", "progress_json.hpp": "io",
    "files.hpp": "common", "utc_time.hpp": "common", "background_work.hpp": "common", "version.hpp": "common",
    "work_label.hpp": "common", "warning.hpp": "common",
}
# The library's own files at the top of solver/, by the module (row of the table) they belong to.
ROOT_FILES = {
    "problem.cpp": "problem", "result.cpp": "result", "contact_extent.hpp": "result", "contact_extent.cpp": "result",
    "solve.cpp": "solve", "held_bodies.hpp": "solve", "held_bodies.cpp": "solve",
}
# Include directories of each tree, in the compiler's order (CMakeLists.txt, server/CMakeLists.txt).
# tests/ and bench/ may use everything (contact_solver_internals): only their includes' resolution is checked.
# (The GoogleTests in tests/unit/ and tests/integration/ find the headers they share in tests/.)
INCLUDE_DIRS = {"solver": ["solver/include", "solver"], "server": ["server", "solver/include"],
                "cli": ["solver/include"], "tests": ["solver", "solver/include", "tests"],
                "bench": ["solver", "solver/include"]}
SOURCE = (".cpp", ".hpp", ".h")
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.M)


def rel(path):
    return os.path.relpath(path, SRC).replace(os.sep, "/")


def module_of(path):
    """The module (row of the table) a file of the source tree belongs to, or None outside the checked trees."""
    parts = path.split("/")
    if path.startswith(PUBLIC_DIR + "/"):
        return PUBLIC_HEADERS.get(parts[-1], "?public " + parts[-1])
    if parts[0] == "solver":
        if len(parts) == 2:
            return ROOT_FILES.get(parts[1], "?root " + parts[1])
        if parts[1] == "ddm" and len(parts) > 3 and parts[2] == "interface":
            return "ddm/interface"
        return parts[1]
    if parts[0] == "server":
        return "server" if len(parts) == 2 else "server/" + parts[1]
    if parts[0] == "cli":
        return "cli"
    return None


# --- the rules: the Layout table ------------------------------------------------------------------------------
SOLVER_MODULES = ["ddm/interface", "mesh", "fem", "mortar", "linalg", "bem", "ddm", "adapt", "check", "limit", "job",
                  "io", "parallel", "mpi", "session", "problem", "result", "solve", "common"]
SERVER_MODULES = ["common", "store", "metrics", "jobs", "transport", "http", "routes"]  # (cli: the public headers)


def row_module(cell):
    """The module a row's first cell names: `solver/ddm/`, `solver/result.cpp`, `server/jobs/`, `cli/`, ..."""
    m = re.match(r"\s*`([^`]+)`", cell)
    if not m:
        return None
    path = m.group(1).rstrip("/")
    if path == PUBLIC_DIR:
        return "public"
    if path.startswith("solver/") and path.count("/") == 1 and path.endswith((".cpp", ".hpp")):
        return ROOT_FILES.get(path.split("/")[1])
    if path in ("solver", "server", "cli") or path.startswith(("solver/", "server/")):
        return module_of(path + "/x.cpp")
    return None


# The qualifiers of a "may use" cell that narrow a module it names, read from the text (module: the module named):
#   "`ddm/interface/` in `method.cpp` only"    a file-level exception: only that file of the row's module may
#                                             include the named module's files (FILE_ONLY[row] = {module: file})
#   "io through its public headers"          only the named module's public headers (contact/*.hpp), never its
#                                             private files (PUBLIC_ONLY[row] = {module})
FILE_ONLY_RE = re.compile(r"`([\w/]+?)/?` in `([\w.]+)` only")
PUBLIC_ONLY_RE = re.compile(r"(?<![\w/])([\w/]+) through its public headers")
FILE_ONLY = {}
PUBLIC_ONLY = {}


def narrowings(cell, server):
    """The file-level exceptions and the public-header-only uses of a "may use" cell."""
    if server:
        return {}, set()
    files = {m.group(1): m.group(2) for m in FILE_ONLY_RE.finditer(cell)}
    public = {m.group(1) for m in PUBLIC_ONLY_RE.finditer(cell) if m.group(1) in SOLVER_MODULES}
    return files, public


def allowed_of(cell, server):
    """The modules a "may use" cell names: module names as words; "the public headers"; "its folders below".
    A module named only with a narrowing (narrowings()) is not among them: its uses are checked apart."""
    names = SERVER_MODULES if server else SOLVER_MODULES
    text = re.sub(r"`[^`]*\(\)`", "", cell)  # function names (`current_exchange()`) are not modules
    text = FILE_ONLY_RE.sub("", text)
    text = PUBLIC_ONLY_RE.sub("", text)
    found = set()
    for name in names:
        if re.search(r"(?<![\w/])" + re.escape(name) + r"(?![\w])", text):
            found.add(("server/" + name) if server else name)
    if server and "public headers" in text:  # (the solver's modules reach a public header's module by name)
        found.add("public")
    if server and "its folders below" in text:
        found |= {"server/" + n for n in SERVER_MODULES}
    return found


def read_rules():
    rules = {}
    with open(DOC) as f:
        for line in f:
            if not line.startswith("| `"):
                continue
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) != 3:
                continue
            module = row_module(cells[0])
            if module in (None, "public"):
                continue
            server = module.startswith("server") or module == "cli"
            rules[module] = allowed_of(cells[2], server) | (set() if server else {"common"})
            FILE_ONLY[module], PUBLIC_ONLY[module] = narrowings(cells[2], server)
    return rules


def closure(rules, module):
    seen, todo = set(), [module]
    while todo:
        for nxt in rules.get(todo.pop(), ()):
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen


# --- the includes ---------------------------------------------------------------------------------------------
def sources(tree):
    for root, dirs, files in os.walk(os.path.join(SRC, tree)):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        for name in sorted(files):
            if name.endswith(SOURCE):
                yield os.path.join(root, name)


def resolve(path, name, tree):
    """Every file the quoted include `name` in `path` can reach, in the compiler's order."""
    places = [os.path.dirname(path)] + [os.path.join(SRC, d) for d in INCLUDE_DIRS[tree]]
    hits = []
    for place in places:
        candidate = os.path.realpath(os.path.join(place, name))
        if os.path.isfile(candidate) and candidate not in hits:
            hits.append(candidate)
    return hits


def main():
    rules = read_rules()
    for module in SOLVER_MODULES + ["server"] + ["server/" + n for n in SERVER_MODULES] + ["cli"]:
        check(f"docs/architecture.md has a row for {module}", module in rules)
    for d in sorted(os.listdir(os.path.join(SRC, "solver"))):
        full = os.path.join(SRC, "solver", d)
        if d == "include":
            continue
        mod = module_of("solver/" + d + ("/x.cpp" if os.path.isdir(full) else ""))
        check(f"solver/{d} belongs to a module with a rule", mod in rules, mod)
    for d in sorted(os.listdir(os.path.join(SRC, "server"))):
        if os.path.isdir(os.path.join(SRC, "server", d)) and d != "web":
            check(f"server/{d}/ has a rule", "server/" + d in rules)
    for name in sorted(os.listdir(os.path.join(SRC, PUBLIC_DIR))):
        check(f"the public header contact/{name} belongs to a module (PUBLIC_HEADERS)", name in PUBLIC_HEADERS)
    for tree in ("solver", "server"):
        check(f"no private folder {tree}/contact/ (\"contact/x.hpp\" names a public header)",
              not os.path.exists(os.path.join(SRC, tree, "contact")))

    reach = {m: closure(rules, m) for m in rules}
    edges = failures = 0
    for tree in ("solver", "server", "cli", "tests", "bench"):
        for path in sources(tree):
            here = rel(path)
            source_module = module_of(here)
            with open(path, encoding="utf-8") as f:
                text = f.read()
            for name in INCLUDE.findall(text):
                hits = resolve(path, name, tree)
                what = f'{here}: #include "{name}"'
                if not check(f"{what} reaches a file of the source tree", hits):
                    continue
                if not check(f"{what} reaches one file only", len(hits) == 1, ", ".join(rel(h) for h in hits)):
                    continue
                target = rel(hits[0])
                if tree in ("tests", "bench"):
                    continue
                if here.startswith(PUBLIC_DIR + "/"):
                    check(f"{what}: a public header includes public headers only", target.startswith(PUBLIC_DIR + "/"))
                    continue
                target_module = "public" if tree != "solver" and target.startswith(PUBLIC_DIR + "/") \
                    else module_of(target)
                edges += 1
                if target_module == source_module:
                    continue
                ok = target_module in reach.get(source_module, set())
                exception = FILE_ONLY.get(source_module, {}).get(target_module)
                if not ok and exception is not None:  # "`module/` in `file` only"
                    ok = os.path.basename(here) == exception
                if not ok and target_module in PUBLIC_ONLY.get(source_module, set()):  # "through its public headers"
                    ok = target.startswith(PUBLIC_DIR + "/")
                failures += not ok
                check(f"{what}: {source_module} may use {target_module} (docs/architecture.md)", ok,
                      f"{source_module} may use {', '.join(sorted(reach.get(source_module, set()))) or 'nothing'}")
    print(f"{edges} includes between files checked, {failures} against the rules")
    finish()


if __name__ == "__main__":
    main()
