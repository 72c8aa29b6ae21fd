#!/usr/bin/python3
"""docs/job-format.md against the code: the fields its tables document are exactly the fields the job parser
accepts (contact-solve --validate names them in its "unknown field ...; allowed: ..." errors) and the fields the
schema (api/job.schema.json) declares, object by object; the fields it mentions in prose for the small objects
(material, displacement, penalty, ...) are the parser's; every default it gives as a single JSON value is the
parser's default (read back from the normalised job a solve stores in /input/normalized); its complete small
example is a valid job whose filled-in solver section and contact are the ones the page prints; its list of
examples is api/examples/.

Prints one line per failure and "N passed, M failed"; exits non-zero on any failure."""
import copy
import json
import math
import os
import re
import subprocess
import sys
import tempfile

import h5py

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
CLI = os.path.join(BIN, "contact-solve")
DOC = os.path.join(SRC, "docs", "job-format.md")
EXAMPLES = os.path.join(SRC, "api", "examples")
UNKNOWN = "zz_not_a_field"

sys.path.insert(0, os.path.join(SRC, "tests"))  # checks.py
from checks import check, finish  # noqa: E402


# --- the document -------------------------------------------------------------------------------------------
def sections(text):
    """{heading text: section text up to the next heading of any level}."""
    out, current, lines = {}, "", []
    for line in text.splitlines():
        m = re.match(r"^#{1,6}\s+(.*?)\s*$", line)
        if m:
            out[current] = "\n".join(lines)
            current, lines = m.group(1), []
        else:
            lines.append(line)
    out[current] = "\n".join(lines)
    return out


def split_row(line):
    """The cells of a markdown table row ("|" inside backticks or escaped as "\\|" does not split)."""
    cells, cell, in_code, i = [], "", False, 0
    body = line.strip()[1:-1] if line.strip().endswith("|") else line.strip()[1:]
    while i < len(body):
        c = body[i]
        if c == "\\" and i + 1 < len(body) and body[i + 1] == "|":
            cell += "|"
            i += 2
            continue
        if c == "`":
            in_code = not in_code
        if c == "|" and not in_code:
            cells.append(cell.strip())
            cell = ""
        else:
            cell += c
        i += 1
    cells.append(cell.strip())
    return cells


def tables(section_text):
    """Every table of a section: a list of dicts keyed by the header's cells."""
    found, lines = [], section_text.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].startswith("|") and i + 1 < len(lines) and re.match(r"^\|[\s:|-]+\|?$", lines[i + 1]):
            header = split_row(lines[i])
            rows = []
            i += 2
            while i < len(lines) and lines[i].startswith("|"):
                rows.append(dict(zip(header, split_row(lines[i]))))
                i += 1
            found.append(rows)
        else:
            i += 1
    return found


def field_table(doc, heading):
    """The rows of the section's table whose first column is `field`."""
    for rows in tables(doc.get(heading, "")):
        if rows and "field" in rows[0]:
            return rows
    return None


def names_in(cell):
    return re.findall(r"`([^`]+)`", cell)


def documented_fields(rows):
    """The field names of a table's first column; `gap.geometric` -> gap (and its sub-field separately)."""
    top, sub = set(), {}
    for row in rows:
        for name in names_in(row["field"]):
            head, _, rest = name.partition(".")
            top.add(head)
            if rest:
                sub.setdefault(head, set()).add(rest)
    return top, sub


def single_json_default(cell):
    """The default when the cell is exactly one backticked JSON value, else None (prose, several values)."""
    m = re.fullmatch(r"`([^`]*)`", cell.strip())
    if not m:
        return None
    try:
        return (json.loads(m.group(1)),)
    except ValueError:
        return None


def same(a, b):
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return math.isclose(a, b, rel_tol=1e-12, abs_tol=0)
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b


# --- the parser -----------------------------------------------------------------------------------------------
def run_cli(job, tmp, *args):
    path = os.path.join(tmp, "job.json")
    with open(path, "w") as f:
        json.dump(job, f)
    return subprocess.run([CLI, path, *args], capture_output=True, text=True, timeout=120)


def solve_normalized(job, tmp, what):
    """The job with every default filled in, as the solver stores it (/input/normalized of its result file)."""
    out = os.path.join(tmp, "normalized.hdf")
    r = run_cli(job, tmp, "-o", out, "-q")
    if not check(f"{what} solves", r.returncode == 0, r.stdout[-400:] + r.stderr[-400:]):
        finish()
    with h5py.File(out, "r") as f:
        return json.loads(f["input/normalized"].asstr()[()])


def parser_fields(job, pointers, tmp):
    """{pointer: the parser's allowed fields there}: an unknown field is put at every pointer (objects of `job`)
    and the parser's error for each names the fields allowed."""
    job = copy.deepcopy(job)
    for pointer in pointers:
        node = job
        for part in [p for p in pointer.split("/") if p]:
            node = node[int(part)] if isinstance(node, list) else node[part]
        node[UNKNOWN] = 1
    r = run_cli(job, tmp, "--validate")
    allowed = {}
    for line in r.stderr.splitlines():
        m = re.match(rf"^(\S*)/{UNKNOWN}: unknown field .*; allowed: (.*)$", line)
        if m:
            allowed[m.group(1)] = set(re.split(r", | and ", m.group(2)))
    missing = [p for p in pointers if p not in allowed]
    check("the parser reports an unknown field at every place probed", not missing, (missing, r.stderr[-800:]))
    return allowed


# --- the schema -------------------------------------------------------------------------------------------------
def schema_properties(schema, path):
    """The property names of the schema object at a "#/..." path; for a oneOf of objects, their union."""
    node = schema
    for part in path.lstrip("#/").split("/"):
        if part:
            node = node[int(part)] if isinstance(node, list) else node[part]
    if "properties" in node:
        return set(node["properties"])
    return set().union(*(set(alt.get("properties", {})) for alt in node.get("oneOf", [])))


def main():
    with open(DOC, encoding="utf-8") as f:
        text = f.read()
    doc = sections(text)
    with open(os.path.join(SRC, "api", "job.schema.json")) as f:
        schema = json.load(f)
    with open(os.path.join(EXAMPLES, "seed_layers.json")) as f:
        seed = json.load(f)

    # The complete small example of the page: a valid job (with every object the probes need added).
    m = re.search(r"```json\n(.*?)```", doc.get("A complete small example", ""), re.S)
    check("the page has its complete small example", m is not None)
    small = json.loads(m.group(1)) if m else copy.deepcopy(seed)

    # Every object of a job: (its pointer in a probe job, the table's heading or None for prose, the section
    # that documents it, its schema path). A block-mesh job, an explicit-mesh job and a Gmsh job cover them all.
    block_job = copy.deepcopy(seed)
    block_job["bodies"][0]["mesh"]["block"]["edges"] = {"bottom": {"parabola": {"a": 0.001}},
                                                         "top": {"arc": {"center": [2, -10], "radius": 125 ** 0.5}}}
    block_job["solver"].update(robin={"psi": "active_set"}, augmented_lagrangian={"tolerance": 1e-6})
    block_job["adaptivity"] = {}
    block_job["output"] = {}
    block_objects = [
        ("", "Top level", "Top level", "#"),
        ("/model", "`model`", "`model`", "#/properties/model"),
        ("/bodies/0", "Bodies", "Bodies", "#/$defs/body"),
        ("/bodies/0/material", None, "Bodies", "#/$defs/body/properties/material"),
        ("/bodies/0/mesh", None, "Block mesh", "#/$defs/block_mesh"),
        ("/bodies/0/mesh/block", "Block mesh", "Block mesh", "#/$defs/block_mesh/properties/block"),
        ("/bodies/0/mesh/block/edges/bottom", None, "Block mesh", "#/$defs/curve"),
        ("/bodies/0/mesh/block/edges/bottom/parabola", None, "Block mesh", "#/$defs/curve/oneOf/0/properties/parabola"),
        ("/bodies/0/mesh/block/edges/top/arc", None, "Block mesh", "#/$defs/curve/oneOf/1/properties/arc"),
        ("/bodies/0/boundary/0", None, "Boundary conditions", "#/$defs/boundary_condition"),
        ("/bodies/0/boundary/0/displacement", None, "Boundary conditions",
         "#/$defs/boundary_condition/properties/displacement"),
        ("/contacts/0", "Contacts", "Contacts", "#/$defs/contact"),
        ("/contacts/0/gap", None, "Contacts", "#/$defs/contact/properties/gap"),
        ("/contacts/0/gap/parabola", None, "Contacts", "#/$defs/contact/properties/gap/properties/parabola"),
        ("/solver", "Solver", "Solver", "#/$defs/solver"),
        ("/solver/penalty", None, "Solver", "#/$defs/solver/properties/penalty"),
        ("/solver/robin", None, "Solver", "#/$defs/solver/properties/robin"),
        ("/solver/augmented_lagrangian", None, "Solver", "#/$defs/solver/properties/augmented_lagrangian"),
        ("/adaptivity", "Adaptivity", "Adaptivity", "#/$defs/adaptivity"),
        ("/output", "Output", "Output", "#/properties/output"),
    ]
    explicit_job = copy.deepcopy(small)
    explicit_job["bodies"][0]["mesh"] = {"nodes": [[0, -1], [2, -1], [2, 0], [0, 0]], "quads": [[0, 1, 2, 3]],
                                         "edges": {"bottom": [[0, 1]], "top": [[2, 3]], "left": [[3, 0]]}}
    explicit_objects = [("/bodies/0/mesh", "Explicit mesh", "Explicit mesh", "#/$defs/explicit_mesh")]
    # A Gmsh job (its mesh file by absolute path, the probe job being written elsewhere); the mesh object and the
    # gmsh object are probed separately (an unknown field in the mesh stops the reading of its gmsh object).
    with open(os.path.join(EXAMPLES, "flat_patch_gmsh.json")) as f:
        gmsh_job = json.load(f)
    for body in gmsh_job["bodies"]:
        body["mesh"]["gmsh"]["file"] = os.path.join(EXAMPLES, body["mesh"]["gmsh"]["file"])
    gmsh_objects = [("/bodies/0/mesh/gmsh", "Gmsh mesh", "Gmsh mesh", "#/$defs/gmsh_mesh/properties/gmsh")]
    gmsh_mesh_objects = [("/bodies/0/mesh", None, "Gmsh mesh", "#/$defs/gmsh_mesh")]
    # The same file once in the job's "meshes" table, the bodies naming the entry.
    table_job = copy.deepcopy(gmsh_job)
    table_job["meshes"] = {"m": {"file": gmsh_job["bodies"][0]["mesh"]["gmsh"]["file"]}}
    for body in table_job["bodies"]:
        body["mesh"]["gmsh"] = {"mesh": "m", "surface": body["mesh"]["gmsh"]["surface"]}
    table_objects = [("/meshes/m", None, "Gmsh mesh", "#/properties/meshes/additionalProperties")]

    with tempfile.TemporaryDirectory() as tmp:
        for job, objects in ((block_job, block_objects), (explicit_job, explicit_objects), (gmsh_job, gmsh_objects),
                             (gmsh_job, gmsh_mesh_objects), (table_job, table_objects)):
            check("the probe job is valid", run_cli(job, tmp, "--validate").returncode == 0,
                  run_cli(job, tmp, "--validate").stderr[-600:])
            parser = parser_fields(job, [o[0] for o in objects], tmp)
            for pointer, table, section, schema_path in objects:
                where = pointer or "the top level"
                accepted = parser.get(pointer, set())
                declared = schema_properties(schema, schema_path)
                check(f"{where}: the schema declares what the parser accepts", accepted == declared,
                      f"parser {sorted(accepted)}, schema {sorted(declared)}")
                if table:
                    rows = field_table(doc, table)
                    if not check(f"{where}: docs/job-format.md has a field table under '{table}'", rows is not None):
                        continue
                    documented, _ = documented_fields(rows)
                    check(f"{where}: every field documented under '{table}' is accepted by the parser",
                          documented <= accepted, f"not accepted: {sorted(documented - accepted)}")
                    check(f"{where}: every field the parser accepts is documented under '{table}'",
                          accepted <= documented, f"undocumented: {sorted(accepted - documented)}")
                else:
                    body = doc.get(section, "")
                    mentioned = {a for a in accepted if re.search(rf'[`".]{re.escape(a)}[`"]', body)}
                    check(f"{where}: every field the parser accepts is named under '{section}'",
                          mentioned == accepted, f"not named: {sorted(accepted - mentioned)}")

        # Dotted fields of the Contacts table (gap.geometric, ...) are the gap object's fields.
        _, sub = documented_fields(field_table(doc, "Contacts") or [])
        probe = copy.deepcopy(small)
        probe["contacts"][0]["gap"] = {}
        gap = parser_fields(probe, ["/contacts/0/gap"], tmp).get("/contacts/0/gap", set())
        check("Contacts: the gap.* rows are the gap object's fields", sub.get("gap", set()) == gap,
              f"documented {sorted(sub.get('gap', set()))}, parser {sorted(gap)}")

        # Defaults: solve the page's small example with an adaptivity section (one step, so that it is quick),
        # which fills in its other defaults, and compare every default the tables give as one JSON value with the
        # normalised job.
        given = copy.deepcopy(small)
        given["adaptivity"] = {"max_steps": 1}
        normalized = solve_normalized(given, tmp, "the page's small example with adaptivity")
        places = [("Top level", normalized, given), ("`model`", normalized["model"], given.get("model", {})),
                  ("Bodies", normalized["bodies"][0], given["bodies"][0]),
                  ("Block mesh", normalized["bodies"][0]["mesh"]["block"], given["bodies"][0]["mesh"]["block"]),
                  ("Contacts", normalized["contacts"][0], given["contacts"][0]),
                  ("Solver", normalized["solver"], given.get("solver", {})),
                  ("Adaptivity", normalized["adaptivity"], given["adaptivity"])]
        compared = 0
        for heading, filled, input_object in places:
            for row in field_table(doc, heading) or []:
                default = single_json_default(row.get("default", ""))
                if default is None:
                    continue
                for name in names_in(row["field"]):
                    head, _, rest = name.partition(".")
                    if head in input_object and not rest:
                        continue  # given by the job: its value, not the default
                    value = filled.get(head, KeyError)
                    if rest and isinstance(value, dict):
                        value = value.get(rest, KeyError)
                    if value is KeyError:
                        continue  # not filled in (an optional object left out)
                    compared += 1
                    check(f"default of {heading} {name} is the parser's", same(default[0], value),
                          f"docs {default[0]!r}, parser {value!r}")
        check("defaults compared", compared >= 12, compared)

        # The filled-in solver section and contact the page prints.
        section = doc.get("A complete small example", "")
        m = re.search(r"solver section reads\s*`(\{.*?\})`", section, re.S)
        shown = json.loads(m.group(1)) if m else None
        normalized = solve_normalized(small, tmp, "the page's small example")
        check("the page's filled-in solver section is the parser's", shown is not None
              and same(shown, normalized["solver"]), f"docs {shown}, parser {normalized['solver']}")
        m = re.search(r"the contact is named\s*`\"([^`]*)\"`\s*with gap\s*`(\{.*?\})`", section, re.S)
        contact = normalized["contacts"][0]
        check("the page's contact name and gap are the parser's", m is not None and m.group(1) == contact["name"]
              and same(json.loads(m.group(2)), contact["gap"]), (m and m.groups(), contact))

    # The list of examples is api/examples/.
    listed = set()
    for rows in tables(doc.get("The examples", "")):
        for row in rows:
            listed |= {n for n in names_in(next(iter(row.values()))) if n.endswith(".json")}
    files = {n for n in os.listdir(EXAMPLES) if n.endswith(".json")}
    check("'The examples' lists every file of api/examples/ and no other", listed == files,
          f"missing {sorted(files - listed)}, not a file {sorted(listed - files)}")

    finish()


if __name__ == "__main__":
    main()
