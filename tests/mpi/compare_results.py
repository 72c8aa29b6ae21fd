"""Compare two result files of the same job: displacements and contact pressures of every step.

Used by test_mpi_ranks.py (the same job on 1, 2 and 3 ranks). Returns the largest relative difference, each
field's difference measured against that field's largest magnitude in the first file."""
import h5py
import numpy as np


def _fields(path):
    out = {}
    with h5py.File(path, "r") as f:
        out["iterations"] = int(f.attrs["iterations"])
        for k in sorted(f["steps"].keys(), key=int):
            step = f["steps"][k]
            for name, body in step["bodies"].items():
                out[f"{k}/{name}/displacement"] = body["displacement"][()]
            # The pairs' rows of the contact tables (docs/results-format.md): pair p's from offsets[p].
            t = step["contacts"]
            offsets, friction = t["offsets"][()], t["friction"].asstr()[()]
            pressure, traction = t["pressure"][()], t["tangential_traction"][()]
            for p, name in enumerate(step.attrs["pair_names"]):
                name = name.decode() if isinstance(name, bytes) else str(name)
                rows = slice(int(offsets[p]), int(offsets[p + 1]))
                out[f"{k}/{name}/pressure"] = pressure[rows]
                if friction[p] != "none":
                    out[f"{k}/{name}/tangential_traction"] = traction[rows]
    return out


def max_relative_difference(a_path, b_path):
    a, b = _fields(a_path), _fields(b_path)
    if a.keys() != b.keys():
        raise AssertionError(f"different contents: {sorted(set(a) ^ set(b))[:5]}")
    worst, where = 0.0, ""
    for key, va in a.items():
        if key == "iterations":
            continue
        vb = b[key]
        if va.shape != vb.shape:
            raise AssertionError(f"{key}: shapes {va.shape} and {vb.shape}")
        scale = np.abs(va).max() if va.size else 0.0
        d = float(np.abs(va - vb).max() / scale) if scale > 0 else float(np.abs(vb).max() if vb.size else 0.0)
        if d > worst:
            worst, where = d, key
    return worst, where, a["iterations"], b["iterations"]
