#!/usr/bin/python3
"""1 rank against 2 ranks (docs/parallel.md): wall time, peak memory per rank and bytes moved between the ranks,
for the brick wall and the paper's two layers at 1024 x 256 elements per body.

    bench/bench_mpi.py [BUILD_DIR]        (needs mpirun; about a minute on two cores)

Prints one row per (job, ranks) and the ratios 1 rank / 2 ranks, measured in the same run."""
import json
import os
import re
import subprocess
import sys
import tempfile

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
BUILD = sys.argv[1] if len(sys.argv) > 1 else os.path.join(SRC, "build")
CLI = os.path.join(BUILD, "contact-solve")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")


def run(job, ranks, tmp):
    out = os.path.join(tmp, f"r{ranks}.hdf")
    # GNU time per rank: its peak resident set; the solver's own line gives the time and the traffic.
    cmd = ["mpirun", "-n", str(ranks), "/usr/bin/time", "-f", "maxrss_kb %M", CLI, job, "-o", out, "-q", "--threads", "1"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=1800)
    if r.returncode != 0:
        raise SystemExit(f"{job} on {ranks} ranks failed:\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}")
    wall = float(re.search(r"stop: \S+ after \d+ \S+, ([0-9.]+) s", r.stdout).group(1))
    setup = float(re.search(r"\(setup ([0-9.]+) s\)", r.stdout).group(1))
    iterations = int(re.search(r"stop: \S+ after (\d+)", r.stdout).group(1))
    rss = [int(x) / 1024 for x in re.findall(r"maxrss_kb (\d+)", r.stderr)]
    m = re.search(r"mpi: (\d+) exchanges, (\d+) bytes", r.stdout)
    exchanges, moved = (int(m.group(1)), int(m.group(2))) if m else (0, 0)
    return dict(wall=wall, setup=setup, iterations=iterations, rss=rss, exchanges=exchanges, moved=moved)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        wall_job = os.path.join(tmp, "wall.json")
        subprocess.run([sys.executable, os.path.join(SRC, "scripts", "make_brick_wall.py"), "--cells", "32", "-o",
                        wall_job], check=True, capture_output=True)
        with open(os.path.join(SRC, "api", "examples", "seed_layers.json")) as f:
            seed = json.load(f)
        for body in seed["bodies"]:
            body["mesh"]["block"]["nx"], body["mesh"]["block"]["ny"] = 1024, 256
        seed["solver"] = {}  # the defaults: interface Newton, exact contact
        seed_job = os.path.join(tmp, "seed.json")
        with open(seed_job, "w") as f:
            json.dump(seed, f)
        print(f"{'job':<28} {'ranks':>5} {'wall s':>8} {'setup s':>8} {'iter':>5} {'peak MB per rank':>22} "
              f"{'exchanges':>9} {'MB moved':>9}")
        for name, job in (("brick wall (cells 32)", wall_job), ("seed_layers 1024x256", seed_job)):
            rows = {}
            for ranks in (1, 2):
                row = run(job, ranks, tmp)
                rows[ranks] = row
                print(f"{name:<28} {ranks:>5} {row['wall']:>8.2f} {row['setup']:>8.2f} {row['iterations']:>5} "
                      f"{', '.join(f'{x:.0f}' for x in row['rss']):>22} {row['exchanges']:>9} "
                      f"{row['moved'] / 1e6:>9.2f}", flush=True)
            print(f"{name:<28} ratio 1 rank / 2 ranks: wall {rows[1]['wall'] / rows[2]['wall']:.2f}, "
                  f"peak memory per rank {max(rows[1]['rss']) / max(rows[2]['rss']):.2f}", flush=True)


if __name__ == "__main__":
    main()
