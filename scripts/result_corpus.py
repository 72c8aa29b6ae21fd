#!/usr/bin/python3
"""Solve a corpus of jobs that covers every method, enforcement, interface solver, friction, adaptivity, load steps,
walls and MPI, writing <outdir>/<name>.hdf, so that two builds can be compared with compare_results.py. One thread per
process: with several, sums over the bodies are taken in the order the threads finish, and results differ between
two runs of one build in the last bits (the Gmsh examples).

Usage: result_corpus.py CONTACT_SOLVE OUTDIR [--only SUBSTRING]

A refactoring that changes no behaviour leaves every file identical apart from times:
    result_corpus.py old/contact-solve /tmp/a && result_corpus.py new/contact-solve /tmp/b
    compare_results.py /tmp/a /tmp/b"""
import copy
import glob
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(ROOT, "api", "examples")


def example(name):
    with open(os.path.join(EXAMPLES, name + ".json")) as f:
        return json.load(f)


def variant(name, **solver):
    job = example(name)
    job.setdefault("solver", {}).update(solver)
    return job


def wall(rows, head_joints, friction, shear):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "wall.json")
        args = [sys.executable, os.path.join(ROOT, "scripts", "make_brick_wall.py"), "--rows", str(rows), "--bricks",
                str(rows), "-o", path] + (["--head-joints"] if head_joints else [])
        if friction:
            args += ["--friction", str(friction), "--shear", str(shear)]
        subprocess.run(args, check=True, capture_output=True)
        with open(path) as f:
            return json.load(f)


def jobs():
    out = {}
    for path in sorted(glob.glob(os.path.join(EXAMPLES, "*.json"))):
        out[os.path.basename(path)[:-5]] = (json.load(open(path)), os.path.dirname(path), 1)
    add = lambda name, job, ranks=1: out.__setitem__(name, (job, EXAMPLES, ranks))
    add("flat_patch_neumann", variant("flat_patch", method="neumann", enforcement="penalty"))
    add("flat_patch_robin", variant("flat_patch", method="robin", enforcement="penalty"))
    add("flat_patch_monolithic", variant("flat_patch", method="monolithic"))
    add("hertz_al", variant("hertz", enforcement="augmented_lagrangian"))
    add("hertz_neumann_al", variant("hertz", method="neumann", enforcement="augmented_lagrangian"))
    add("hertz_monolithic", variant("hertz", method="monolithic"))
    add("hertz_iterative", variant("hertz", interface={"solver": "iterative"}))
    add("stack3_floating_iterative", variant("stack3_floating", interface={"solver": "iterative"}))
    add("roller_friction_monolithic", variant("roller_friction", method="monolithic"))
    add("roller_friction_iterative", variant("roller_friction", interface={"solver": "iterative"}))
    adaptive_paper = example("seed_layers_adaptive")
    adaptive_paper.setdefault("adaptivity", {})["strategy"] = "paper"
    adaptive_paper.get("solver", {}).pop("method", None)
    adaptive_paper.get("solver", {}).pop("enforcement", None)
    add("seed_layers_adaptive_paper", adaptive_paper)
    adaptive_zz = example("seed_layers_adaptive")
    adaptive_zz["adaptivity"]["indicator"] = "zz"
    add("seed_layers_adaptive_zz", adaptive_zz)
    add("wall8_frictionless", wall(8, False, 0, 0))
    for solver in ("direct", "iterative"):
        job = wall(8, True, 0.6, 0.3)
        job.setdefault("solver", {})["interface"] = {"solver": solver}
        add("wall8_head_friction_" + solver, job)
    job = wall(4, True, 0.6, 0.5)
    job.setdefault("solver", {})["method"] = "monolithic"
    add("wall4_head_friction_monolithic", job)
    add("wall4_refused", wall(4, True, 0.6, 0.65))
    add("stack3_floating_mpi2", example("stack3_floating"), 2)
    add("wall8_head_friction_mpi2", wall(8, True, 0.6, 0.3), 2)
    add("seed_layers_adaptive_mpi2", example("seed_layers_adaptive"), 2)
    return out


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    binary, outdir = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    only = sys.argv[4] if len(sys.argv) > 4 and sys.argv[3] == "--only" else ""
    os.makedirs(outdir, exist_ok=True)
    for name, (job, base, ranks) in jobs().items():
        if only not in name:
            continue
        path = os.path.join(base, f".corpus_{name}.json")  # beside the example: its mesh files are relative
        with open(path, "w") as f:
            json.dump(job, f)
        cmd = [binary, "-q", "--keep-iterate", "--threads", "1", "-o", os.path.join(outdir, name + ".hdf"), path]
        if ranks > 1:
            cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(ranks)] + cmd
        start = time.time()
        run = subprocess.run(cmd, capture_output=True, text=True)
        os.remove(path)
        with open(os.path.join(outdir, name + ".txt"), "w") as f:
            f.write(f"exit {run.returncode}\n{run.stdout}{run.stderr}")
        print(f"{name}: exit {run.returncode}, {time.time() - start:.1f} s", flush=True)


if __name__ == "__main__":
    main()
