#!/usr/bin/python3
"""Many bodies (issue 19): brick walls of 8 x 8 to 64 x 64 bricks (scripts/make_brick_wall.py --cells 16, the
job's defaults otherwise) solved with each interface solver on 1 and 2 MPI ranks: time (the whole command, result
file included), peak memory per rank,
MPRGP iterations; and, in the same run, the paper's test at 1024 x 256 elements per body (1.05M unknowns, the
default method) as the yardstick of the targets: the 22 x 22 wall in at most 0.5x its time and within 1 GB, time
from 16 x 16 to 22 x 22 growing at most 2.5x.

    bench/bench_walls.py [BUILD_DIR] [--quick]     (needs mpirun for the 2-rank rows; about 3 minutes on two cores)

--quick: walls up to 22 x 22 and 1 rank only. The direct solver is not run on the 64 x 64 wall: its dense Schur
complement on the 8,256 floating rows would take ~4.6 GB (docs/algorithm.md, "The interface solvers")."""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

import h5py

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
args = [a for a in sys.argv[1:] if not a.startswith("--")]
QUICK = "--quick" in sys.argv
BUILD = args[0] if args else os.path.join(SRC, "build")
CLI = os.path.join(BUILD, "contact-solve")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")


def run(job, ranks, tmp):
    out = os.path.join(tmp, "out.hdf")
    cmd = ["/usr/bin/time", "-f", "maxrss_kb %M elapsed %e", CLI, job, "-o", out, "-q"]
    if ranks > 1:
        cmd = ["mpirun", "-n", str(ranks), "/usr/bin/time", "-f", "maxrss_kb %M elapsed %e", CLI, job, "-o", out,
               "-q", "--threads", "1"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=3600)
    if r.returncode != 0:
        return None, f"failed: {r.stdout[-300:]} {r.stderr[-300:]}"
    # wall: what the user waits for, the whole command (reading the job, setting up, solving, writing the result;
    # the slowest rank's); solve: the solver's own figure in its stop line.
    wall = max(float(x) for x in re.findall(r"elapsed ([0-9.]+)", r.stderr))
    solve = float(re.search(r"stop: \S+ after \d+ \S+, ([0-9.]+) s", r.stdout).group(1))
    rss = max(int(x) / 1024 for x in re.findall(r"maxrss_kb (\d+)", r.stderr))
    # MPRGP iterations over the whole run (every load step and outer iteration: the products with F), from the
    # result's provenance; the progress message gives the last step's only.
    with h5py.File(out, "r") as f:
        iterations = int(f["provenance"].attrs.get("interface_iterations", 0))
    m = re.search(r"stop: \S+ after (\d+)", r.stdout)
    steps = int(m.group(1)) if m else 0
    m = re.search(r"cut (\d+) times", r.stdout)  # a frictional load step cut into sub-steps (load_steps.cpp)
    cuts = int(m.group(1)) if m else 0
    return dict(wall=wall, solve=solve, rss=rss, iterations=iterations, steps=steps, cuts=cuts), ""


def print_result(label, r, error, columns):
    """One row of a table: the label, then `columns` (a format of run()'s fields) or the error."""
    print(f"{label} {error[:160]}" if r is None else f"{label} " + columns.format(**r), flush=True)


def wall_job(n, solver, tmp):
    path = os.path.join(tmp, f"wall{n}.json")
    if not os.path.exists(path):
        subprocess.run(["/usr/bin/python3", os.path.join(SRC, "scripts", "make_brick_wall.py"), "--rows", str(n),
                        "--bricks", str(n), "--cells", "16", "-o", path], check=True, capture_output=True)
    with open(path) as f:
        job = json.load(f)
    job.setdefault("solver", {})["interface"] = {"solver": solver}
    out = os.path.join(tmp, f"wall{n}_{solver}.json")
    with open(out, "w") as f:
        json.dump(job, f)
    return out, len(job["bodies"])


def seed_job(tmp):
    with open(os.path.join(SRC, "api", "examples", "seed_layers.json")) as f:
        seed = json.load(f)
    for body in seed["bodies"]:
        body["mesh"]["block"]["nx"], body["mesh"]["block"]["ny"] = 1024, 256
    seed["solver"] = {}  # the defaults: interface Newton, exact contact
    path = os.path.join(tmp, "seed.json")
    with open(path, "w") as f:
        json.dump(seed, f)
    return path


def main():
    ranks_list = [1] if QUICK or not shutil.which("mpirun") else [1, 2]
    sizes = [8, 16, 22] if QUICK else [8, 16, 22, 32, 64]
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        seed, _ = run(seed_job(tmp), 1, tmp)
        print(f"paper's test 1024 x 256 per body (1.05M unknowns), default solver, 1 rank: {seed['wall']:.2f} s, "
              f"{seed['rss']:.0f} MB", flush=True)
        print(f"{'wall':>7} {'bodies':>6} {'solver':>9} {'ranks':>5} {'time s':>8} {'peak MB/rank':>12} "
              f"{'MPRGP it.':>9} {'steps':>5}", flush=True)
        for n in sizes:
            for solver in ("direct", "iterative"):
                if solver == "direct" and n >= 64:
                    continue
                job, bodies = wall_job(n, solver, tmp)
                for ranks in ranks_list:
                    r, error = run(job, ranks, tmp)
                    rows[(n, solver, ranks)] = r
                    print_result(f"{n:>4}x{n:<2} {bodies:>6} {solver:>9} {ranks:>5}", r, error,
                                 "{wall:>8.2f} {rss:>12.0f} {iterations:>9} {steps:>5}")
        print("\nratios (same run):")
        for solver in ("direct", "iterative"):
            a, b = rows.get((22, solver, 1)), rows.get((16, solver, 1))
            if a and b:
                print(f"  {solver}: 22x22 / paper's test time {a['wall'] / seed['wall']:.3f} (target <= 0.5), "
                      f"22x22 peak {a['rss']:.0f} MB (target <= 1024), 22x22 / 16x16 time {a['wall'] / b['wall']:.2f} "
                      f"(target <= 2.5)")
        its = [rows[(n, "iterative", 1)]["iterations"] for n in sizes if rows.get((n, "iterative", 1))]
        if its:
            print(f"  iterative: MPRGP iterations {its}, largest / smallest wall {its[-1] / its[0]:.2f} (target <= 1.5)")


if __name__ == "__main__":
    main()
