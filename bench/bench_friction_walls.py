#!/usr/bin/python3
"""Friction on many bodies (issue 28): masonry walls held by friction alone (scripts/make_brick_wall.py
--head-joints --friction 0.6 --shear 0.3: head and bed joints, no dowels, precompression then shear), 8 x 8 to
22 x 22 (32 x 32 and 64 x 64 without --quick), each interface solver that takes them, on 1 rank (and 2 under
mpirun without --quick; the ratios are the 1-rank runs'), against the frictionless
dowelled twin of the same size (the generator's default wall), and in the same run the paper's test at 1024 x 256
per body (1.05M unknowns, the default method) as the yardstick. Prints time (the whole command, as a user waits for
it: reading the job, setting up, solving, writing the result; and the solver's own figure), peak memory, the
interface solver's
steps (Newton steps or outer iterations) and MPRGP iterations (the whole run's), and the ratios the issue sets targets for: the
22 x 22 frictional wall in at most 1x the paper's test, within 1 GB; frictional / frictionless on the same wall at
most 5x; 16 x 16 -> 22 x 22 growing at most 2.5x.

Then the walls near the limit, H/V 0.5 (8 x 8 and 16 x 16; 22 x 22 without --quick), with the solver `auto` picks.

    bench/bench_friction_walls.py [BUILD_DIR] [--quick]     (--quick: about two minutes on two cores)"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_walls import QUICK, SRC, print_result, run, seed_job  # noqa: E402  (one runner and one yardstick for the wall benches)


def generated(n, options, solver, tmp):
    path = os.path.join(tmp, f"wall{n}_{'_'.join(o.strip('-') for o in options)}_{solver}.json")
    subprocess.run(["/usr/bin/python3", os.path.join(SRC, "scripts", "make_brick_wall.py"), "--rows", str(n),
                    "--bricks", str(n), *options, "-o", path], check=True, capture_output=True)
    with open(path) as f:
        job = json.load(f)
    job.setdefault("solver", {})["interface"] = {"solver": solver}
    with open(path, "w") as f:
        json.dump(job, f)
    return path, len(job["bodies"])


def main():
    sizes = [8, 16, 22] if QUICK else [8, 16, 22, 32, 64]
    ranks_list = [1] if QUICK or not shutil.which("mpirun") else [1, 2]  # peak memory is per rank
    frictional = ["--head-joints", "--friction", "0.6", "--shear", "0.3"]
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        seed, _ = run(seed_job(tmp), 1, tmp)
        print(f"paper's test 1024 x 256 per body (1.05M unknowns), defaults: {seed['wall']:.2f} s (solve "
              f"{seed['solve']:.2f} s), {seed['rss']:.0f} MB", flush=True)
        print(f"{'wall':>7} {'bodies':>6} {'kind':>12} {'solver':>9} {'ranks':>5} {'time s':>8} {'solve s':>8} "
              f"{'peak MB':>8} {'steps':>5} {'MPRGP it.':>9}", flush=True)
        for n in sizes:
            for kind, options in (("frictionless", []), ("frictional", frictional)):
                for solver in ("direct", "iterative"):
                    if solver == "direct" and n >= (64 if kind == "frictionless" else 32):
                        continue  # the direct solver's dense floating-body block, or its sets' LU, past memory/time
                    job, bodies = generated(n, options, solver, tmp)
                    for ranks in ranks_list:
                        r, error = run(job, ranks, tmp)
                        if ranks == 1:
                            rows[(n, kind, solver)] = r
                        print_result(f"{n:>4}x{n:<2} {bodies:>6} {kind:>12} {solver:>9} {ranks:>5}", r, error,
                                     "{wall:>8.2f} {solve:>8.2f} {rss:>8.0f} {steps:>5} {iterations:>9}")
        # Near the friction limit (issue 28's statics): the free course ends unload the heel, whose bricks slip on
        # both bed joints (an indeterminate slip). Every step must converge, uncut.
        print("\nnear the limit: head joints, mu 0.6, H/V 0.5, the solver `auto` picks", flush=True)
        print(f"{'wall':>7} {'bodies':>6} {'time s':>8} {'peak MB':>8} {'steps':>5} {'MPRGP it.':>9} {'cuts':>4}", flush=True)
        for n in [8, 16] if QUICK else [8, 16, 22]:
            job, bodies = generated(n, ["--head-joints", "--friction", "0.6", "--shear", "0.5"], "auto", tmp)
            r, error = run(job, 1, tmp)
            print_result(f"{n:>4}x{n:<2} {bodies:>6}", r, error, "{wall:>8.2f} {rss:>8.0f} {steps:>5} {iterations:>9} {cuts:>4}")
        # The yardstick again at the end: on a shared machine the speed drifts by 10-20 % within minutes, so the
        # ratios take the mean of the two.
        again, _ = run(seed_job(tmp), 1, tmp)
        print(f"\npaper's test again: {again['wall']:.2f} s (solve {again['solve']:.2f} s); the ratios use the mean, "
              f"{(seed['wall'] + again['wall']) / 2:.2f} s", flush=True)
        seed = dict(seed, wall=(seed['wall'] + again['wall']) / 2)
        print("\nratios (same run):")
        for solver in ("direct", "iterative"):
            a, b = rows.get((22, "frictional", solver)), rows.get((16, "frictional", solver))
            twin = rows.get((22, "frictionless", solver))
            if a:
                print(f"  {solver}: frictional 22x22 / paper's test {a['wall'] / seed['wall']:.2f} (target <= 1), "
                      f"peak {a['rss']:.0f} MB (target <= 1024)")
            if a and b:
                print(f"  {solver}: frictional 22x22 / 16x16 {a['wall'] / b['wall']:.2f} (target <= 2.5)")
            if a and twin:
                print(f"  {solver}: frictional / frictionless 22x22 {a['wall'] / twin['wall']:.2f} (target <= 5)")
            big = rows.get((64, "frictional", solver))
            if big:
                print(f"  {solver}: frictional 64x64 / paper's test {big['wall'] / seed['wall']:.2f} (target <= 3)")
        # Numerical scalability: the products with F over the whole run (every load step's outer x inner).
        its = [rows[(n, "frictional", "iterative")]["iterations"] for n in sizes
               if rows.get((n, "frictional", "iterative"))]
        if len(its) >= 2:
            print(f"  iterative: frictional MPRGP iterations (whole run) {its}, largest / smallest wall "
                  f"{its[-1] / its[0]:.2f} (target <= 2 from 8x8 to 64x64)")


if __name__ == "__main__":
    main()
