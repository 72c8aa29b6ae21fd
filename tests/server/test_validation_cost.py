#!/usr/bin/env python3
"""Validation costs what the job is, not a product of its parts (issue 51, item 2).

Two small jobs made validation cost gigabytes:
1. The floating-body check walked a body's contact edge once per pair: a floating strip under many clamped bricks,
   each paired with the strip's top, cost pairs x strip nodes (39 KB of JSON, 4.4 GB). Now each edge of a body is
   walked once.
2. One Gmsh mesh in the job's "meshes" table, named by thousands of bodies: every body's surface was built before
   the job's size was checked (149 s and 864 MB before the 400 for 27.5M unknowns). Now a surface is built once
   however many bodies name it, and the total is checked before any body's mesh is built.

Validation itself is bounded in time too (--max-validation-seconds): a job past it is refused with the time.

3. A long contact (issue 51, item 3): two strips of N cells in contact, a 540-byte job, took N = 16,000 to an OOM
   kill (about 30 GB: the interface problem's dense blocks grow with the square of the contact's nodes) far below
   --max-dofs. Now its memory is estimated before it runs and a job over --max-interface-bytes is refused with the
   estimate and the limit that would admit it; the estimate is checked against a run's measured peak (N = 1,000).

Each bomb is measured against its twin (the same strip with one brick and one pair; the same mesh named by 16 bodies):
the growth of the peak memory of `contact-solve --validate` (its maximum resident set, from wait4) and of contactd
(VmHWM) must stay within a small multiple of the twin's. The bugs made it hundreds of MB more at these sizes; CPU
times are printed, not bounded (a loaded machine)."""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import CONTACT_SOLVE, Server  # noqa: E402
from checks import check, finish, section  # noqa: E402

STRIP_CELLS = 50_000
BRICKS = 200
TABLE_BODIES = 8192
MATERIAL = {"E": 1000.0, "nu": 0.3}


def strip_job(bricks):
    """A strip held in x on its left end, otherwise floating (held by its contacts), under `bricks` bricks clamped
    on their tops, each brick's bottom paired with the strip's top."""
    length = float(STRIP_CELLS)
    bodies = [{"name": "strip", "material": MATERIAL,
               "mesh": {"block": {"corners": [[0, -1], [length, -1], [length, 0], [0, 0]], "nx": STRIP_CELLS,
                                  "ny": 1}},
               "boundary": [{"edge": "left", "displacement": {"x": 0}}]}]
    contacts = []
    width = length / bricks
    for b in range(bricks):
        x0, x1 = b * width, (b + 1) * width
        bodies.append({"name": f"brick{b}", "material": MATERIAL,
                       "mesh": {"block": {"corners": [[x0, 0], [x1, 0], [x1, 1], [x0, 1]], "nx": 2, "ny": 1}},
                       "boundary": [{"edge": "top", "displacement": {"x": 0, "y": -0.001}}]})
        contacts.append({"name": f"b{b}", "slave": f"brick{b}.bottom", "master": "strip.top"})
    # Monolithic: interface_newton would hold a dense block over the strip's 100,002 contact unknowns (80 GB), and
    # the job would be refused for that (item 3 below) before the checks measured here.
    return {"name": "strip-under-bricks", "bodies": bodies, "contacts": contacts, "solver": {"method": "monolithic"}}


def table_job(msh_text, bodies):
    """`bodies` bodies, all the one square of the job's "meshes" table, each clamped on its bottom."""
    return {"name": "one-mesh-many-bodies", "meshes": {"square": {"data": msh_text}},
            "bodies": [{"name": f"s{k}", "material": MATERIAL,
                        "mesh": {"gmsh": {"mesh": "square", "surface": "square"}},
                        "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]} for k in range(bodies)]}


def strips_job(cells, friction=False):
    """Two strips of `cells` x 1 cells in contact along their length, the lower clamped, the upper pressed down."""
    length = float(cells)
    job = {"name": f"strips-{cells}", "bodies": [
        {"name": "lower", "material": MATERIAL,
         "mesh": {"block": {"corners": [[0, -1], [length, -1], [length, 0], [0, 0]], "nx": cells, "ny": 1}},
         "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
        {"name": "upper", "material": MATERIAL,
         "mesh": {"block": {"corners": [[0, 0], [length, 0], [length, 1], [0, 1]], "nx": cells, "ny": 1}},
         "boundary": [{"edge": "top", "displacement": {"x": 0, "y": -0.001}}]}],
        "contacts": [{"slave": "upper.bottom", "master": "lower.top"}]}
    if friction:
        job["contacts"][0]["friction"] = {"coefficient": 0.3}
    return job


def estimate_mb(message):
    m = re.search(r"would take about ([0-9.]+) (MB|GB)", message)
    return float(m.group(1)) * (1000.0 if m.group(2) == "GB" else 1.0) if m else None


def square_msh(tmp):
    geo = os.path.join(tmp, "square.geo")
    with open(geo, "w") as f:
        f.write("Point(1)={0,0,0}; Point(2)={1,0,0}; Point(3)={1,1,0}; Point(4)={0,1,0};\n"
                "Line(1)={1,2}; Line(2)={2,3}; Line(3)={3,4}; Line(4)={4,1};\n"
                "Curve Loop(1)={1,2,3,4}; Plane Surface(1)={1};\n"
                "Transfinite Curve{1,2,3,4}=41; Transfinite Surface{1}; Recombine Surface{1};\n"
                'Physical Surface("square")={1}; Physical Curve("bottom")={1}; Physical Curve("right")={2};\n'
                'Physical Curve("top")={3}; Physical Curve("left")={4};\n')
    msh = os.path.join(tmp, "square.msh")
    subprocess.run(["gmsh", "-2", geo, "-format", "msh41", "-o", msh], check=True, capture_output=True, timeout=120)
    with open(msh) as f:
        return f.read()


def validate_cli(job, tmp, name, extra=("--validate",)):
    """contact-solve --validate (or `extra`): (exit code, its output, peak RSS in MB, CPU seconds)."""
    path = os.path.join(tmp, name + ".json")
    with open(path, "w") as f:
        json.dump(job, f)
    proc = subprocess.Popen([CONTACT_SOLVE, path, "--no-mesh-files", "-q", *extra], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT)
    out = proc.stdout.read().decode(errors="replace")
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, out, usage.ru_maxrss / 1024.0, usage.ru_utime + usage.ru_stime


def peak_mb(server):
    with open(f"/proc/{server.proc.pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return 0.0


def compare(label, bomb, twin):
    """The bomb's peak within twice its twin's, plus 40 MB (the bugs: hundreds of MB more at these sizes)."""
    print(f"{label}: peak {bomb:.0f} MB against its twin's {twin:.0f} MB", flush=True)
    check(f"{label}: peak memory within twice the twin's + 40 MB", bomb <= 2.0 * twin + 40.0, (bomb, twin))


tmp = tempfile.mkdtemp(prefix="validation-cost-")
bomb, twin = strip_job(BRICKS), strip_job(1)
print(f"strip bomb: {len(json.dumps(bomb))} bytes of JSON, {len(bomb['contacts'])} pairs on a strip of "
      f"{STRIP_CELLS} cells", flush=True)
gmsh = shutil.which("gmsh")
msh = square_msh(tmp) if gmsh else None

section("contact-solve --validate")
code_t, out_t, rss_t, cpu_t = validate_cli(twin, tmp, "twin")
code_b, out_b, rss_b, cpu_b = validate_cli(bomb, tmp, "bomb")
print(f"CPU: bomb {cpu_b:.2f} s, twin {cpu_t:.2f} s", flush=True)
check("the strip's twin is valid (exit 0)", code_t == 0, out_t[-500:])
check("the strip bomb is valid (exit 0)", code_b == 0, out_b[-500:])
compare("strip bomb (CLI)", rss_b, rss_t)
if msh:
    code_t, out_t, rss_t, cpu_t = validate_cli(table_job(msh, 16), tmp, "table-twin")
    code_b, out_b, rss_b, cpu_b = validate_cli(table_job(msh, TABLE_BODIES), tmp, "table-bomb")
    print(f"CPU: {TABLE_BODIES} bodies {cpu_b:.2f} s, 16 bodies {cpu_t:.2f} s", flush=True)
    check("16 bodies of one table mesh are valid (exit 0)", code_t == 0, out_t[-500:])
    check(f"{TABLE_BODIES} bodies of it: refused (exit 2) for their size, with the total and the limit, naming a few "
          "bodies (not thousands)", code_b == 2 and "27541504 degrees of freedom" in out_b and
          "more than the limit" in out_b and f"and {TABLE_BODIES - 8} more bodies" in out_b and len(out_b) < 2000,
          out_b[-800:])
    compare("table bomb (CLI)", rss_b, rss_t)
else:
    print("no gmsh command: the table bomb is not built (Debian's gmsh)", flush=True)

section("a long contact: its interface memory estimated before it runs")
code, out, rss, _ = validate_cli(strips_job(1000), tmp, "strips-1000", ("--validate", "--max-interface-bytes", "1e6"))
estimate = estimate_mb(out)
check("two strips of 1,000 cells over a 1 MB limit: refused (exit 2) at /contacts with the estimate, the limit "
      "and the limit that would admit it", code == 2 and "/contacts:" in out and estimate is not None and
      "--max-interface-bytes" in out and "would admit it" in out, out[-600:])
code, out, rss, _ = validate_cli(strips_job(1000), tmp, "strips-1000-run", ("-o", os.path.join(tmp, "s.hdf")))
print(f"two strips of 1,000 cells: estimated {estimate} MB, measured peak {rss:.0f} MB", flush=True)
check("... and run, its measured peak is within a factor 2 of the estimate", code == 0 and estimate is not None and
      0.5 <= rss / estimate <= 2.0, (code, rss, estimate, out[-300:]))
code, out, rss, _ = validate_cli(strips_job(16000), tmp, "strips-16000",
                                 ("--validate", "--max-interface-bytes", "4e9"))
print(f"two strips of 16,000 cells: {estimate_mb(out)} MB estimated, validation peak {rss:.0f} MB", flush=True)
check("two strips of 16,000 cells (the OOM kill): refused (exit 2) by the CLI with an estimate of tens of GB, "
      "validation itself small", code == 2 and (estimate_mb(out) or 0) > 20000 and rss < 200, (code, rss, out[-600:]))

section("contactd /v1/validate")
with Server(args=["--max-request-bytes", "67108864"]) as server:
    r = server.request("POST", "/v1/validate", body=json.dumps(twin).encode(),
                       headers={"Content-Type": "application/json"})
    check("the strip's twin: 200", r.status == 200, r)
    base = peak_mb(server)
    start = time.time()
    r = server.request("POST", "/v1/validate", body=json.dumps(bomb).encode(),
                       headers={"Content-Type": "application/json"})
    print(f"strip bomb answered in {time.time() - start:.2f} s", flush=True)
    check("the strip bomb: 200", r.status == 200, r)
    compare("strip bomb (contactd, growth of the peak over the server's after its twin)",
            peak_mb(server) - base, max(base, 1.0))
    if msh:
        start = time.time()
        r = server.request("POST", "/v1/validate", body=json.dumps(table_job(msh, TABLE_BODIES)).encode(),
                           headers={"Content-Type": "application/json"})
        print(f"table bomb answered in {time.time() - start:.2f} s", flush=True)
        check("the table bomb: 400 naming the size and the limit",
              r.status == 400 and "more than the limit" in r.body.decode(errors="replace"), r)
        compare("table bomb (contactd)", peak_mb(server) - base, max(base, 1.0))
    for path in ("/v1/validate", "/v1/jobs"):
        r = server.request("POST", path, body=json.dumps(strips_job(16000)).encode(),
                           headers={"Content-Type": "application/json"})
        text = r.body.decode(errors="replace")
        check(f"POST {path} two strips of 16,000 cells: 400 at /contacts naming contactd --max-interface-bytes",
              r.status == 400 and '"/contacts"' in text and "contactd --max-interface-bytes" in text, r)
    r = server.request("POST", "/v1/validate", body=json.dumps(strips_job(2000, friction=True)).encode(),
                       headers={"Content-Type": "application/json"})
    check("two strips of 2,000 cells with friction (about 2 GB): within the default 4 GB, 200", r.status == 200, r)
    check("the server is up", server.get("/healthz").status == 200)

section("validation under a time budget")
# A job that validation cannot finish within --max-validation-seconds is refused with the time it took, not
# validated for as long as it takes (every check is linear now: a budget of 1 ms stands in for a pathological job).
if msh:
    with Server(args=["--max-request-bytes", "67108864", "--max-validation-seconds", "0.001"]) as server:
        r = server.request("POST", "/v1/validate", body=json.dumps(table_job(msh, TABLE_BODIES)).encode(),
                           headers={"Content-Type": "application/json"})
        text = r.body.decode(errors="replace")
        check("past --max-validation-seconds: 400 naming the time, where it stopped and the flag",
              r.status == 400 and "validation took" in text and "contactd --max-validation-seconds" in text, r)

finish()
