"""Reading what contactd produces: result files (HDF5, docs/results-format.md) into numpy arrays, and saved
progress events."""
import json
import os

from .errors import BadInput

RESULT_FORMAT_VERSION = 3  # docs/results-format.md; 2: mortar contact (per-node multipliers, contact surfaces);
#                             3: a step's contact pairs as tables (/steps/<k>/contacts), read here into the same dicts

# Format version 3's contact tables (/steps/<k>/contacts): per pair (P rows) and per slave node (N rows, the pairs'
# nodes one after the other from offsets[p]); `segments` holds rows of the node tables. The friction columns of a
# frictionless pair are not returned, as version 2 had none.
_JOINT_COLUMNS = ("centre_of_pressure", "eccentricity", "open_fraction", "slip_fraction", "friction_utilisation")
_PAIR_COLUMNS = ("slave_body", "slave_edge", "master_body", "master_edge", "enforcement", "friction", "theta", "force",
                 "resultant", "friction_coefficient", "friction_bound", "tangential_force") + _JOINT_COLUMNS
_FRICTION_ONLY = {"friction_coefficient", "friction_bound", "tangential_force", "tangent", "tangential_traction",
                  "slip", "stick"}


def _attr(value):
    """An HDF5 attribute as Python: str, a list of str, a numpy array or a scalar."""
    import numpy as np
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "OSU":
            return [v.decode() if isinstance(v, bytes) else str(v) for v in value.tolist()]
        return value
    if isinstance(value, np.generic):
        return value.item()
    return value


def _dataset(item):
    """An HDF5 dataset's value: a numpy array, or str / a list of str for string datasets."""
    import h5py
    import numpy as np
    if item.dtype.kind in "OS" or h5py.check_string_dtype(item.dtype) is not None:
        v = item.asstr()[()]
        return v if isinstance(v, str) else [str(s) for s in np.asarray(v).tolist()]
    return item[()]


def joint_results(pair):
    """A pair as a joint (docs/results-format.md, the contact tables' joint columns), from its nodes: the centre of
    pressure, its eccentricity over the half-length, the open and slipping shares by weight, the friction's
    utilisation; NaN where a value does not apply. The solver's contact::joint_results, for files without them."""
    import numpy as np
    attrs = pair.get("attrs", {})
    w, p, s = (np.asarray(pair[k], dtype=float) for k in ("weight", "pressure", "arc_length"))
    status = np.asarray(pair["status"])
    carried = (status != 1) & (status != 5)
    lo, hi = (s[carried].min(), s[carried].max()) if carried.any() else (np.nan, np.nan)
    rows = w > 0
    W = w[rows].sum()
    pressed = rows & (p > 0)
    N = (w * p)[pressed].sum()
    friction = attrs.get("friction", "none")
    stick = np.asarray(pair["stick"]) if "stick" in pair else None
    nan = float("nan")
    centre = float((w * p * s)[pressed].sum() / N) if N > 0 else nan
    out = {"centre_of_pressure": centre,
           "eccentricity": (centre - 0.5 * (lo + hi)) / (0.5 * (hi - lo)) if N > 0 and hi > lo else nan,
           "open_fraction": float(w[rows & ~(p > 0)].sum() / W) if W > 0 else nan,
           "slip_fraction": float(w[pressed & (stick == 0)].sum() / W) if friction != "none" and stick is not None
           and W > 0 else nan}
    capacity = (attrs.get("friction_coefficient", 0.0) * N if friction == "coulomb"
                else attrs.get("friction_bound", 0.0) * W if friction == "tresca" else 0.0)
    out["friction_utilisation"] = abs(attrs.get("tangential_force", 0.0)) / capacity if capacity > 0 else nan
    return out


class ResultFile:
    """A result file (docs/results-format.md) open for reading only what is asked: a wall of 496 bodies kept for 2
    steps holds some 13 000 body datasets, and h5py takes about 0.25 ms for each, where a plot needs a tenth of
    them. A step's contact tables (format version 3) are read once each and sliced per pair. Use it as a context
    manager:

        with ResultFile("wall.hdf") as f:
            last = f.step(f.count - 1)                       # {"step", "iteration", "load_factor", "body_names",
                                                             #  "pair_names", "bodies": {}, "contacts": {}}
            base = f.body(f.count - 1, "base", ("points", "displacement"))
            c = f.pair(f.count - 1, last["pair_names"][0], ("pressure", "stick"))   # with "attrs" and "x"

    count is the number of step groups kept (/steps@count), attrs the root attributes."""

    def __init__(self, path):
        import h5py
        self._h5py = h5py
        self.path = os.fspath(path)
        self._tables, self._pair_index, self._node_keys = {}, {}, {}
        self._f = h5py.File(self.path, "r")
        try:
            self.attrs = {k: _attr(v) for k, v in self._f.attrs.items()}
            if self.attrs.get("format") != "contact-ddm-result":
                raise BadInput(f"{path}: not a contact-ddm result file")
            if int(self.attrs.get("format_version", 0)) > RESULT_FORMAT_VERSION:
                raise BadInput(f"{path}: result format version {self.attrs['format_version']} is newer than "
                               f"this client knows ({RESULT_FORMAT_VERSION})")
            steps = self._f.get("steps")
            self.count = int(steps.attrs.get("count", len(steps))) if steps is not None else 0
        except BaseException:
            self._f.close()
            raise

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        self._f.close()

    def _group(self, k):
        return self._f["steps"][str(k)]

    def step(self, k):
        """Step group k's attributes, with empty "bodies" and "contacts" to fill: {"step": k, "iteration",
        "load_factor", "body_names", "pair_names", "bodies": {}, "contacts": {}}."""
        import numpy as np
        g = self._group(k)
        body_names = _attr(g.attrs.get("body_names", np.array(list(g["bodies"].keys()), dtype=object)))
        pair_names = _attr(g.attrs.get("pair_names", np.array(list(g["contacts"].keys()), dtype=object)))
        return {"step": k, "iteration": int(g.attrs.get("iteration", 0)),
                "load_factor": float(g.attrs.get("load_factor", 1.0)), "bodies": {}, "contacts": {},
                "body_names": list(body_names), "pair_names": list(pair_names)}

    def body(self, k, name, keys=None, attrs=False):
        """Body `name` of step group k: {dataset: array} for the datasets `keys` it has (None: all), and its
        attributes under "attrs" when `attrs`."""
        g = self._group(k)["bodies"][name]
        out = {key: _dataset(g[key]) for key in (g.keys() if keys is None else keys) if key in g}
        if attrs:
            out["attrs"] = {a: _attr(v) for a, v in g.attrs.items()}
        return out

    def body_attrs(self, k, name):
        return {a: _attr(v) for a, v in self._group(k)["bodies"][name].attrs.items()}

    def pair(self, k, name, keys=None):
        """Pair `name` of step group k: {dataset: array} for the datasets `keys` it has (None: all), its
        attributes under "attrs", and "x" (the slave nodes' x) when "position" is read. The same dict from a
        version 3 file (the step's contact tables: `segments` then count the pair's own rows, as in version 2) as
        from a version 2 file (a group per pair)."""
        contacts = self._group(k)["contacts"]
        if "offsets" in contacts and isinstance(contacts["offsets"], self._h5py.Dataset):
            out = self._table_pair(k, contacts, name, keys)
        else:
            g = contacts[name]
            out = {key: _dataset(g[key]) for key in (g.keys() if keys is None else keys) if key in g}
            out["attrs"] = {a: _attr(v) for a, v in g.attrs.items()}
        if "position" in out and len(out["position"]):
            out["x"] = out["position"][:, 0]
        if "centre_of_pressure" not in out["attrs"] and all(key in out for key in ("weight", "pressure", "arc_length",
                                                                                 "status")):
            out["attrs"].update(joint_results(out))  # a file written before the joint columns: derived
        return out

    def _table(self, k, contacts, key):
        """A whole table of step group k's contacts, read once (a plot of every pair reads each table once)."""
        cache = self._tables.setdefault(k, {})
        if key not in cache:
            cache[key] = _dataset(contacts[key])
        return cache[key]

    def _table_pair(self, k, contacts, name, keys):
        names = self._pair_index.get(k)
        if names is None:
            names = self._pair_index[k] = {n: p for p, n in enumerate(self.step(k)["pair_names"])}
        if name not in names:
            raise KeyError(f"step {k} has no contact pair {name!r}")
        p = names[name]
        frictional = self._table(k, contacts, "friction")[p] != "none"
        attrs = {}
        for key in _PAIR_COLUMNS:
            if key in contacts and (frictional or key not in _FRICTION_ONLY):
                v = self._table(k, contacts, key)[p]
                attrs[key] = v if isinstance(v, str) else _attr(v)
        offsets = self._table(k, contacts, "offsets")
        begin, end = int(offsets[p]), int(offsets[p + 1])
        per_node = self._node_keys.get(k)
        if per_node is None:  # the step's per-node tables, listed once (h5py opens every member to list it)
            per_node = self._node_keys[k] = [key for key, item in contacts.items()
                                              if isinstance(item, self._h5py.Dataset) and key not in _PAIR_COLUMNS
                                              and key not in ("offsets", "segment_offsets", "pair")]
        out = {}
        for key in (per_node if keys is None else keys):
            if key not in per_node or (key in _FRICTION_ONLY and not frictional):
                continue
            if key == "segments":
                s_off = self._table(k, contacts, "segment_offsets")
                out[key] = self._table(k, contacts, key)[int(s_off[p]):int(s_off[p + 1])] - begin
            else:
                out[key] = self._table(k, contacts, key)[begin:end]
        out["attrs"] = attrs
        return out

    def history(self, name):
        """/history/<name> ("iterations" or "steps"): its datasets and attributes in one dict ({} without)."""
        h = self._f.get("history")
        if h is None or name not in h:
            return {}
        out = {key: _dataset(item) for key, item in h[name].items()}
        out.update({a: _attr(v) for a, v in h[name].attrs.items()})
        return out

    def warnings(self):
        """What the model checks found (/warnings; docs/job-format.md, "Warnings"): [{"pointer", "message"}], empty
        for a file written before the checks."""
        if "warnings" not in self._f:
            return []
        w = self._f["warnings"]
        return [{"pointer": p, "message": m} for p, m in zip(_dataset(w["pointer"]), _dataset(w["message"]))]

    def collapse(self):
        """A collapse analysis's answer, or the statics' verdict on a failed step (/collapse; docs/results-format.md):
        {"verdict", "held", "failed", "statics_bound", "solves", "words", ..., "trials": {"multiplier", "held",
        "iterations", "seconds", "displacement"}, "mechanism": {"kind", "words", "source", "check",
        "body_names", "body_velocity", "body_omega", "body_reference", "body_centre", "pair_names", "joint_kind",
        "joint_point", ...}}, or None for a file without one."""
        if "collapse" not in self._f:
            return None
        g = self._f["collapse"]
        out = {k: _attr(v) for k, v in g.attrs.items()}
        # "mechanism": the collapse's (its "source": "elastic", the elastic solution's own, or "statics"; its
        # "check"); "statics_mechanism": the rigid-block statics' at its bound (files from before it: absent).
        for name in ("mechanism", "statics_mechanism"):
            if name not in g:
                continue
            m = g[name]
            out[name] = {k: _attr(v) for k, v in m.attrs.items()}
            out[name].update({k: _dataset(item) for k, item in m.items()})
        # Every trial: "multiplier", "held", "iterations", "seconds" and, at those that held, the live loads'
        # "displacement" (NaN elsewhere): the capacity curve's points.
        if "trials" in g:
            out["trials"] = {k: _dataset(item) for k, item in g["trials"].items()}
        return out

    def job(self, key="job"):
        """The job as submitted (key "job") or with its defaults filled in ("normalized"), or None."""
        try:
            return json.loads(self._f["input"][key].asstr()[()])
        except (KeyError, ValueError):
            return None


def read_result(path):
    """Reads a result file (docs/results-format.md) into numpy arrays, all of it (ResultFile reads parts):

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
                 "steps": {...}},
     "warnings": [{"pointer", "message"}, ...]}                       # the model checks' (ResultFile.warnings)
    """
    result = {"path": os.fspath(path)}
    with ResultFile(path) as f:
        result["attrs"] = f.attrs
        steps = []
        for k in range(f.count):
            step = f.step(k)
            for name in step["body_names"]:
                step["bodies"][name] = f.body(k, name)
            for name in step["pair_names"]:
                step["contacts"][name] = f.pair(k, name)
            steps.append(step)
        result["steps"] = steps
        result["body_names"] = steps[-1]["body_names"] if steps else []
        result["pair_names"] = steps[-1]["pair_names"] if steps else []
        history = {name: f.history(name) for name in ("iterations", "steps")}
        result["history"] = {name: h for name, h in history.items() if h}
        result["warnings"] = f.warnings()
        job = f.job()
        if job is not None:
            result["job"] = job
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
