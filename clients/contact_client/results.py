"""Reading what contactd produces: result files (HDF5, docs/results-format.md) into numpy arrays, and saved
progress events."""
import json
import os

from .errors import BadInput

RESULT_FORMAT_VERSION = 2  # docs/results-format.md; 2: mortar contact (per-node multipliers, contact surfaces)


def read_result(path):
    """Reads a result file (docs/results-format.md) into numpy arrays:

    {"attrs": {...root attributes...},
     "body_names": [...], "pair_names": [...],                        # of the final step
     "steps": [{"step": k, "iteration": i, "load_factor": f,
                "bodies": {name: {"points", "cells" (-1 ends a triangle), "cell_types", "quads" (all-quadrilateral
                                  meshes only), "level", "von_mises", "displacement", "stress_cell", ...}},
                "contacts": {pair: {"position", "x", "arc_length", "pressure", "gap", "normal_gap", "active",
                                    "attrs": {...},                    # friction pairs also "tangent",
                                    ...}}}, ...],                      # "tangential_traction", "slip", "stick"
                                                                       # (pair_friction()); in step order, the
                                                                       # last is final
     "history": {"iterations": {"iteration", "fixed_point_residual", "max_pressure" (I, P), ...,
                                "body_names", "pair_names"},
                 "steps": {...}}}
    """
    import h5py
    import numpy as np

    def attr(value):
        if isinstance(value, bytes):
            return value.decode()
        if isinstance(value, np.ndarray):
            if value.dtype.kind in "OSU":
                return [v.decode() if isinstance(v, bytes) else str(v) for v in value.tolist()]
            return value
        if isinstance(value, np.generic):
            return value.item()
        return value

    def group(g):
        out = {}
        for key, item in g.items():
            if isinstance(item, h5py.Dataset):
                if item.dtype.kind in "OS" or h5py.check_string_dtype(item.dtype) is not None:
                    v = item.asstr()[()]
                    out[key] = v if isinstance(v, str) else [str(s) for s in np.asarray(v).tolist()]
                else:
                    out[key] = item[()]
        return out

    result = {"path": os.fspath(path)}
    with h5py.File(path, "r") as f:
        result["attrs"] = {k: attr(v) for k, v in f.attrs.items()}
        if result["attrs"].get("format") != "contact-ddm-result":
            raise BadInput(f"{path}: not a contact-ddm result file")
        if int(result["attrs"].get("format_version", 0)) > RESULT_FORMAT_VERSION:
            raise BadInput(f"{path}: result format version {result['attrs']['format_version']} is newer than "
                           f"this client knows ({RESULT_FORMAT_VERSION})")
        steps = []
        if "steps" in f:
            count = int(f["steps"].attrs.get("count", len(f["steps"])))
            for k in range(count):
                g = f["steps"][str(k)]
                body_names = attr(g.attrs.get("body_names", np.array(list(g["bodies"].keys()), dtype=object)))
                pair_names = attr(g.attrs.get("pair_names", np.array(list(g["contacts"].keys()), dtype=object)))
                step = {"step": k, "iteration": int(g.attrs.get("iteration", 0)),
                        "load_factor": float(g.attrs.get("load_factor", 1.0)), "bodies": {}, "contacts": {},
                        "body_names": list(body_names), "pair_names": list(pair_names)}
                for name in body_names:
                    step["bodies"][name] = group(g["bodies"][name])
                for name in pair_names:
                    c = g["contacts"][name]
                    d = group(c)
                    d["attrs"] = {a: attr(v) for a, v in c.attrs.items()}
                    if "position" in d and len(d["position"]):
                        d["x"] = d["position"][:, 0]
                    step["contacts"][name] = d
                steps.append(step)
        result["steps"] = steps
        result["body_names"] = steps[-1]["body_names"] if steps else []
        result["pair_names"] = steps[-1]["pair_names"] if steps else []
        history = {}
        for name in ("iterations", "steps"):
            if "history" in f and name in f["history"]:
                h = f["history"][name]
                history[name] = group(h)
                for a, v in h.attrs.items():
                    history[name][a] = attr(v)
        result["history"] = history
        if "input" in f and "job" in f["input"]:
            try:
                result["job"] = json.loads(f["input/job"].asstr()[()])
            except ValueError:
                pass
    return result


def pair_friction(c):
    """A pair's friction (c: a pair of read_result()'s steps): None for a frictionless pair and for a file
    written before friction (no `friction` attribute, no tangential datasets); else {"law": "coulomb" or
    "tresca", "coefficient": mu, "bound": g, "tangential_force": the total tangential force, "tangential_traction"
    (k,), "stick" (k,) bool}, the per-node arrays None when the file lacks them."""
    import numpy as np
    attrs = c.get("attrs", {})
    law = attrs.get("friction", "none")
    if law in ("none", "", None):
        return None
    k = len(c.get("pressure", []))

    def per_node(key, dtype):
        v = c.get(key)
        return np.asarray(v, dtype=dtype) if v is not None and len(v) == k else None

    stick = per_node("stick", int)
    return {"law": str(law), "coefficient": float(attrs.get("friction_coefficient", 0.0)),
            "bound": float(attrs.get("friction_bound", 0.0)),
            "tangential_force": float(attrs.get("tangential_force", float("nan"))),
            "tangential_traction": per_node("tangential_traction", float),
            "stick": stick == 1 if stick is not None else None}


def read_events(path):
    """Events saved as NDJSON (watch --events-out, or curl -H 'Accept: application/x-ndjson') or as SSE text
    (curl -N): a list of dicts (raises ValueError for a line that is not JSON)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    if any(line.startswith(("data:", "event:", "id:")) for line in text.splitlines()[:20]):
        parsed = [json.loads(line[5:].strip()) for line in text.splitlines() if line.startswith("data:")]
    else:
        parsed = [json.loads(line) for line in text.splitlines() if line.strip()]
    return [e for e in parsed if isinstance(e, dict)]
