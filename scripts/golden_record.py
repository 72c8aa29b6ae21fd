#!/usr/bin/python3
"""The golden record of the solvers' iteration counts (deal.II's committed .output files, for the tuning): a small
set of jobs solved on one thread, and for each what its solvers did - active-set or Newton steps, MPRGP products,
augmented-Lagrangian updates, load-step cuts, the numbers its stop message gives (steps, products, faces, cuts) -
and a few key scalars (the last step's contact forces, the unknowns). The friction and FETI policy
(solver/ddm/interface/friction_policy.hpp) is tuned on these runs: a retuning moves the counts, and the record shows
it as a diff in review.

    scripts/golden_record.py CONTACT_SOLVE --write tests/data/golden_record.json   (after a deliberate retuning)
    scripts/golden_record.py CONTACT_SOLVE --compare tests/data/golden_record.json (what the CTest runs)

--compare prints one line per job and per quantity that moved beyond its band, and exits 1 if any did. The bands:
a count may move by 10 % or 2, whichever is more (other compilers and BLAS builds round differently, and a count
can move by a step); a scalar by 1e-6 of its size; a stop reason or the count of numbers in a message not at all."""
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from result_corpus import EXAMPLES, example, variant, wall  # noqa: E402

COUNT_BAND, COUNT_SLACK, SCALAR_BAND = 0.10, 2, 1e-6


def solver(job, **fields):
    job.setdefault("solver", {}).update(fields)
    return job


def jobs():
    """The record's jobs: the friction examples on both interface solvers, 8 x 8 walls with head joints at H/V 0.3
    and 0.5 on both, the frictionless wall, an augmented-Lagrangian run, load steps and an adaptive run."""
    out = {
        "roller_friction_direct": example("roller_friction"),
        "roller_friction_iterative": variant("roller_friction", interface={"solver": "iterative"}),
        "masonry_wall": example("masonry_wall"),
        "wall8_frictionless_direct": solver(wall(8, False, 0, 0), interface={"solver": "direct"}),
        "wall8_frictionless_iterative": solver(wall(8, False, 0, 0), interface={"solver": "iterative"}),
        "hertz_augmented_lagrangian": variant("hertz", enforcement="augmented_lagrangian"),
        "seed_layers_steps": example("seed_layers_steps"),
        "seed_layers_adaptive": example("seed_layers_adaptive"),
    }
    for hv in (0.3, 0.5):
        for kind in ("direct", "iterative"):
            out[f"wall8_head_friction_hv{hv}_{kind}"] = solver(wall(8, True, 0.6, hv), interface={"solver": kind})
    return out


def integers(message):
    """The whole numbers a stop message gives (steps, products, cuts, nodes), in order; not the digits of decimals,
    exponents or names ("8x8", "1e-10", "H/V 0.5")."""
    return [int(m) for m in re.findall(r"(?<![\w.\-+])(\d+)(?![\w.])", message)]


def record_of(path, code):
    import h5py  # Debian's python3-h5py (scripts/setup.sh); imported here so that --help works without it
    out = {"exit": code}
    if not os.path.exists(path):
        return out
    with h5py.File(path, "r") as f:
        a, p = f.attrs, f["provenance"].attrs
        text = lambda v: v.decode() if isinstance(v, bytes) else str(v)
        out["stop_reason"] = text(a["stop_reason"])
        out["iterations"] = int(a["iterations"])
        out["interface_solver"] = text(p["interface_solver"])
        out["interface_iterations"] = int(p["interface_iterations"])
        it = f["history/iterations"]
        out["history_rows"] = int(it["iteration"].shape[0])
        out["updates"] = int(it["update"][-1]) if it["update"].shape[0] else 0
        st = f["history/steps"]
        out["steps"] = int(st["step"].shape[0])
        out["message_numbers"] = integers(text(a["message"]))
        out["message"] = text(a["message"])
        out["force"] = float(sum(st["force"][-1])) if st["force"].shape[0] else 0.0
        if "tangential_force" in st:
            out["tangential_force"] = float(sum(abs(x) for x in st["tangential_force"][-1]))
        out["dofs"] = int(sum(st["dofs"][-1]))
    return out


def absolute_mesh_files(value):
    """The job with every Gmsh "file" (a path relative to api/examples/) made absolute."""
    if isinstance(value, dict):
        return {k: (os.path.join(EXAMPLES, v) if k == "file" and isinstance(v, str) else absolute_mesh_files(v))
                for k, v in value.items()}
    if isinstance(value, list):
        return [absolute_mesh_files(v) for v in value]
    return value


def run_all(binary):
    records = {}
    with tempfile.TemporaryDirectory(prefix="golden-") as tmp:
        for name, job in jobs().items():
            # Written to the temporary folder (not beside the examples, where a test lists the folder's files), its
            # mesh files named by absolute paths.
            path = os.path.join(tmp, name + ".json")
            with open(path, "w") as f:
                json.dump(absolute_mesh_files(job), f)
            result = os.path.join(tmp, name + ".hdf")
            run = subprocess.run([binary, "-q", "--keep-iterate", "--threads", "1", "-o", result, path],
                                 capture_output=True, text=True, timeout=600)
            records[name] = record_of(result, run.returncode)
            print(f"{name}: exit {run.returncode}, {records[name].get('message', run.stderr.strip()[-200:])}",
                  flush=True)
    return records


def differences(old, new):
    """What moved beyond its band, as lines."""
    lines = []
    for name in sorted(set(old) | set(new)):
        a, b = old.get(name), new.get(name)
        if a is None or b is None:
            lines.append(f"{name}: {'new job' if a is None else 'job gone'}")
            continue
        for key in sorted(set(a) | set(b)):
            x, y = a.get(key), b.get(key)
            if key == "message":
                continue  # its numbers are compared; the text is shown with them
            if key == "message_numbers":
                if x is None or y is None or len(x) != len(y) or any(not close_count(u, v) for u, v in zip(x, y)):
                    lines.append(f"{name}: message numbers {x} -> {y} ('{a.get('message')}' -> '{b.get('message')}')")
            elif isinstance(x, bool) or isinstance(x, str) or x is None or y is None:
                if x != y:
                    lines.append(f"{name}: {key} {x!r} -> {y!r}")
            elif isinstance(x, int) and isinstance(y, int):
                if not close_count(x, y):
                    lines.append(f"{name}: {key} {x} -> {y} (band: 10 % or 2)")
            elif abs(x - y) > SCALAR_BAND * max(abs(x), abs(y), 1e-300):
                lines.append(f"{name}: {key} {x!r} -> {y!r} (band: 1e-6 relative)")
    return lines


def close_count(x, y):
    return abs(x - y) <= max(COUNT_SLACK, COUNT_BAND * max(abs(x), abs(y)))


def main():
    if len(sys.argv) != 4 or sys.argv[2] not in ("--write", "--compare"):
        sys.exit(__doc__)
    binary, mode, path = os.path.abspath(sys.argv[1]), sys.argv[2], sys.argv[3]
    records = run_all(binary)
    if mode == "--write":
        with open(path, "w") as f:
            json.dump(records, f, indent=1, sort_keys=True)
            f.write("\n")
        print(f"wrote {path}")
        return 0
    with open(path) as f:
        old = json.load(f)
    moved = differences(old, records)
    for line in moved:
        print("MOVED " + line)
    print(f"{len(records)} jobs, {len(moved)} quantities moved beyond their bands")
    return 1 if moved else 0


if __name__ == "__main__":
    sys.exit(main())
