#!/usr/bin/env python3
"""api/job.schema.json: it is a valid draft 2020-12 schema, every example job validates against it and is
accepted by the job parser (contact-solve --validate), it is closed (additionalProperties false on every
fixed-key object), and bad jobs are rejected for the reason expected, by the schema and by the parser at the same
place. Standard library plus Debian's python3-jsonschema; exits non-zero on any failure.
(docs/job-format.md against the parser and the schema: test_job_format_doc.py.)"""

import copy
import glob
import json
import os
import subprocess
import sys
import tempfile

from jsonschema import Draft202012Validator

SOURCE = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BINARY = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SOURCE, "build"))
CLI = os.path.join(BINARY, "contact-solve")
SCHEMA_PATH = os.path.join(SOURCE, "api", "job.schema.json")
EXAMPLES = sorted(glob.glob(os.path.join(SOURCE, "api", "examples", "*.json")))
EXPECTED_EXAMPLES = {"seed_layers", "seed_layers_curved", "flat_patch", "flat_patch_nonmatching", "hertz", "stack3"}

sys.path.insert(0, os.path.join(SOURCE, "tests"))  # checks.py
from checks import check, finish, show_passes  # noqa: E402

show_passes()


def load(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


schema = load(SCHEMA_PATH)
try:
    Draft202012Validator.check_schema(schema)
    check("schema is a valid draft 2020-12 schema", True)
except Exception as e:  # noqa: BLE001 - report any failure of the meta-schema check
    check("schema is a valid draft 2020-12 schema", False, str(e))
validator = Draft202012Validator(schema)


def errors_of(document):
    return sorted(validator.iter_errors(document), key=lambda e: list(e.absolute_path))


# --- the schema is closed ---------------------------------------------------------------------------------
def open_objects(node, path="#"):
    """Schemas of objects with fixed keys ("properties") that do not forbid other keys."""
    found = []
    if isinstance(node, dict):
        if "properties" in node and node.get("additionalProperties") is not False:
            found.append(path)
        for key, value in node.items():
            found += open_objects(value, f"{path}/{key}")
    elif isinstance(node, list):
        for i, value in enumerate(node):
            found += open_objects(value, f"{path}/{i}")
    return found


check("every object with fixed keys sets additionalProperties false", not open_objects(schema), str(open_objects(schema)))

# --- examples -----------------------------------------------------------------------------------------------
names = {os.path.splitext(os.path.basename(p))[0] for p in EXAMPLES}
check("all six examples are present", EXPECTED_EXAMPLES <= names, f"missing {EXPECTED_EXAMPLES - names}")
for path in EXAMPLES:
    errs = errors_of(load(path))
    check(f"example {os.path.basename(path)} validates", not errs,
          "; ".join(f"{'/'.join(map(str, e.absolute_path))}: {e.message}" for e in errs))
    r = subprocess.run([CLI, path, "--validate"], capture_output=True, text=True, timeout=60)
    check(f"example {os.path.basename(path)} is accepted by the parser", r.returncode == 0, r.stderr[-600:])

# --- bad documents --------------------------------------------------------------------------------------------
base = load(os.path.join(SOURCE, "api", "examples", "seed_layers.json"))


def mutated(change):
    doc = copy.deepcopy(base)
    change(doc)
    return doc


def parser_errors(document):
    """The JSON pointers of the parser's errors for the document (contact-solve --validate, exit code 2)."""
    with tempfile.NamedTemporaryFile("w", suffix=".json") as f:
        # Python writes an infinite float as Infinity, which is not JSON: the text a user would write is 1e400.
        f.write(json.dumps(document).replace("Infinity", "1e400"))
        f.flush()
        r = subprocess.run([CLI, f.name, "--validate"], capture_output=True, text=True, timeout=60)
    if r.returncode != 2:
        return None
    return [line.split(": ", 1)[0] for line in r.stderr.splitlines()[1:] if line.startswith("/")]


def rejected_at(name, change, path, keyword=None):
    """The mutated example is invalid, with an error at `path` (a list of keys and indices), for the schema and
    for the parser (whose error is at that place or inside it)."""
    doc = mutated(change)
    errs = errors_of(doc)
    at = [e for e in errs if list(e.absolute_path) == path and (keyword is None or e.validator == keyword)]
    check(f"rejects {name}", bool(at),
          "errors were: " + ("; ".join(f"{list(e.absolute_path)} {e.validator}: {e.message}" for e in errs) or "none"))
    pointer = "".join(f"/{p}" for p in path)
    found = parser_errors(doc)
    check(f"the parser rejects {name} too, at {pointer or 'the top'}",
          found is not None and any(p == pointer or p.startswith(pointer + "/") for p in found), found)


rejected_at("an unknown top-level field", lambda d: d.update(solvr={}), [], "additionalProperties")
rejected_at("an unknown field inside a block",
            lambda d: d["bodies"][0]["mesh"]["block"].update(nz=3), ["bodies", 0, "mesh"])
rejected_at("nu given as a string", lambda d: d["bodies"][1]["material"].update(nu="0.3"),
            ["bodies", 1, "material", "nu"], "type")
rejected_at("a body without material", lambda d: d["bodies"][0].pop("material"), ["bodies", 0], "required")
rejected_at("nx = 0", lambda d: d["bodies"][0]["mesh"]["block"].update(nx=0), ["bodies", 0, "mesh"])
rejected_at("nx = 2.5", lambda d: d["bodies"][0]["mesh"]["block"].update(nx=2.5), ["bodies", 0, "mesh"])
rejected_at("nu = 0.5", lambda d: d["bodies"][0]["material"].update(nu=0.5),
            ["bodies", 0, "material", "nu"], "exclusiveMaximum")
rejected_at("E = 0", lambda d: d["bodies"][0]["material"].update(E=0), ["bodies", 0, "material", "E"])
rejected_at("a number that overflows a double",
            lambda d: d["bodies"][0]["material"].update(E=float("inf")), ["bodies", 0, "material", "E"])
rejected_at("a body name with a dot", lambda d: d["bodies"][0].update(name="up.per"),
            ["bodies", 0, "name"], "pattern")
rejected_at("a job name with a NUL (issue 22)", lambda d: d.update(name="seed\x00layers"), ["name"], "pattern")
rejected_at("a job name with an escape sequence", lambda d: d.update(name="red \x1b[31m"), ["name"], "pattern")
# Issue 32, item 7: "." and ".." as a contact name (the pair's group in the result file), invisible characters
# (zero-width, bidirectional controls) in the job's name and in names: refused by both, at the name.
rejected_at("a contact named '.'", lambda d: d["contacts"][0].update(name="."), ["contacts", 0, "name"], "pattern")
rejected_at("a contact named '..'", lambda d: d["contacts"][0].update(name=".."), ["contacts", 0, "name"], "pattern")
check("accepts a contact name with dots inside",
      not errors_of(mutated(lambda d: d["contacts"][0].update(name="upper.bottom-lower.top"))))
for char in ("\u200b", "\u200f", "\u202a", "\u202e", "\u2066", "\u2069", "\ufeff"):
    rejected_at(f"a job name with U+{ord(char):04X}", lambda d, c=char: d.update(name=f"seed{c}layers"), ["name"],
                "pattern")
rejected_at("a body name with a right-to-left override", lambda d: d["bodies"][0].update(name="up\u202eper"),
            ["bodies", 0, "name"], "pattern")
check("accepts a job name with printable non-ASCII text",
      not errors_of(mutated(lambda d: d.update(name="Grenzfl\u00e4che \u202f2"))))
rejected_at("a malformed contact reference", lambda d: d["contacts"][0].update(slave="upper"),
            ["contacts", 0, "slave"], "pattern")
rejected_at("an unknown adaptivity indicator", lambda d: d.update(adaptivity={"indicator": "residual"}),
            ["adaptivity", "indicator"], "enum")
check("accepts the paper's adaptivity settings",
      not errors_of(mutated(lambda d: d.update(adaptivity={"indicator": "fem_bem", "delta": 0.1, "bodies": ["lower"],
                                                          "strategy": "paper", "max_level": 6}))))
rejected_at("both theta and c", lambda d: d["solver"].update(penalty={"theta": 1e-7, "c": 0.05}),
            ["solver", "penalty"], "oneOf")
rejected_at("gamma = 2", lambda d: d["solver"].update(gamma=2), ["solver", "gamma"], "oneOf")
rejected_at("gamma = \"fast\"", lambda d: d["solver"].update(gamma="fast"), ["solver", "gamma"], "oneOf")
rejected_at("an unknown acceleration", lambda d: d["solver"].update(acceleration="aitken"), ["solver", "acceleration"], "enum")
rejected_at("an unknown field in robin", lambda d: d["solver"].update(robin={"phi": 1}), ["solver", "robin"],
            "additionalProperties")
check("accepts the fast settings (gamma auto, Anderson, interface Newton, augmented Lagrangian)",
      not errors_of(mutated(lambda d: d["solver"].update(gamma="auto", acceleration="anderson", anderson_depth=6,
                                                          method="interface_newton",
                                                          enforcement="augmented_lagrangian",
                                                          augmented_lagrangian={"tolerance": 1e-8},
                                                          robin={"psi": 1e7}))))
rejected_at("grading towards both bottom and top",
            lambda d: d["bodies"][0]["mesh"]["block"].update(grading={"bottom": 4, "top": 4}), ["bodies", 0, "mesh"])
rejected_at("a condition with both a traction and a force",
            lambda d: d["bodies"][0]["boundary"][2].update(force=[0, 1]), ["bodies", 0, "boundary", 2], "not")
rejected_at("a condition on both an edge and a vertex",
            lambda d: d["bodies"][0]["boundary"][2].update(vertex="top_right"), ["bodies", 0, "boundary", 2], "oneOf")
rejected_at("a traction at a vertex",
            lambda d: d["bodies"][0]["boundary"].__setitem__(2, {"vertex": "top_right", "traction": [0, 1]}),
            ["bodies", 0, "boundary", 2], "not")
rejected_at("free with a displacement",
            lambda d: d["bodies"][0]["boundary"][0].update(free=True), ["bodies", 0, "boundary", 0], "not")
rejected_at("a condition with no kind", lambda d: d["bodies"][0]["boundary"].__setitem__(2, {"edge": "right"}),
            ["bodies", 0, "boundary", 2], "anyOf")
check("accepts forces on an edge and at a vertex, and a displacement with a load on its free component",
      not errors_of(mutated(lambda d: d["bodies"][0].update(boundary=[
          {"edge": "left", "displacement": {"x": 0}, "traction": [0, -1]},
          {"edge": "top", "force": [0, -100]},
          {"vertex": "top_right", "displacement": {"y": 0}, "force": [5, 0]}]))))
rejected_at("loading with both steps and factors", lambda d: d.update(loading={"steps": 2, "factors": [1]}),
            ["loading"], "oneOf")
rejected_at("loading with 0 steps", lambda d: d.update(loading={"steps": 0}), ["loading", "steps"], "minimum")
rejected_at("a negative load factor", lambda d: d.update(loading={"factors": [0.5, -1]}),
            ["loading", "factors", 1], "exclusiveMinimum")
rejected_at("an empty displacement", lambda d: d["bodies"][0]["boundary"][0].update(displacement={}),
            ["bodies", 0, "boundary", 0, "displacement"], "minProperties")
rejected_at("free = false", lambda d: d["bodies"][0]["boundary"].__setitem__(2, {"edge": "right", "free": False}),
            ["bodies", 0, "boundary", 2, "free"], "const")
rejected_at("version 2", lambda d: d.update(version=2), ["version"], "const")
rejected_at("no bodies", lambda d: d.update(bodies=[]), ["bodies"], "minItems")
rejected_at("a quad repeating a node",
            lambda d: d["bodies"][0].update(mesh={"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "quads": [[0, 1, 1, 3]]}),
            ["bodies", 0, "mesh"])
gmsh = {"file": "flat_patch_gmsh.msh", "surface": "lower"}
rejected_at("a gmsh mesh with both file and data",
            lambda d: d["bodies"][0].update(mesh={"gmsh": {**gmsh, "data": "$MeshFormat"}}), ["bodies", 0, "mesh"])
rejected_at("a gmsh mesh without its surface",
            lambda d: d["bodies"][0].update(mesh={"gmsh": {"data": "$MeshFormat"}}), ["bodies", 0, "mesh"])
rejected_at("a gmsh mesh with a block beside it",
            lambda d: d["bodies"][0]["mesh"].update(gmsh=gmsh), ["bodies", 0, "mesh"])

# The defaults the schema documents are the solver's (solver/include/contact/problem.hpp): a spot check of the important ones.
solver_props = schema["$defs"]["solver"]["properties"]
check("documented defaults are the fast and exact ones",
      solver_props["method"]["default"] == "interface_newton" and solver_props["gamma"]["default"] == "auto"
      and solver_props["tolerance"]["default"] == 1e-8 and solver_props["criterion"]["default"] == "residual"
      and solver_props["enforcement"]["default"] == "exact"
      and solver_props["acceleration"]["default"] == "anderson" and solver_props["anderson_depth"]["default"] == 10
      and solver_props["max_iterations"]["default"] == 2000 and solver_props["penalty"]["default"] == {"c": 0.05})
with open(os.path.join(SOURCE, "api", "examples", "seed_layers.json")) as f:
    paper = json.load(f)["solver"]
check("seed_layers.json spells out the paper's scheme (c 0.05, gamma 0.02, eps 0.0015, plain, penalty)",
      paper == {"method": "neumann", "penalty": {"c": 0.05, "length": 1}, "gamma": 0.02, "tolerance": 0.0015,
                "criterion": "paper", "max_iterations": 2000, "initial_guess": "elastic_layer",
                "acceleration": "none", "enforcement": "penalty"}, str(paper))

finish()
