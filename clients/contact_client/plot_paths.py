"""The load path of a stepped result as curves: the force-load curve of a load-stepped job (increasing load
factors), and the load history of any job with several steps, whatever its load factors (a job driven by its
conditions' `history` has load factor 1 in every step)."""


def _history_columns(h, key, names, rows):
    """/history/steps's (S, P) dataset `key` as {pair: (S,)} for the pairs `names` (None where absent)."""
    import numpy as np
    columns = list(h.get("pair_names", []))
    data = h.get(key)
    if data is None:
        return {name: None for name in names}
    data = np.asarray(data, dtype=float).reshape(rows, -1)
    return {name: data[:, columns.index(name)] if name in columns and columns.index(name) < data.shape[1]
            else None for name in names}


def load_curve(result, pairs=None):
    """The force-load curve of a load-stepped result (Fig. 4 of the paper as a curve), from /history/steps:
    {"load_factor": (S,), "pairs": {pair: {"force": (S,), "width": (S,)}}}, the width being contact_end -
    contact_begin (the half-width of a symmetric half model), for the pairs named in `pairs` (None: every pair).
    None unless the file holds more than one step at increasing load factors (an adaptive run's steps all share
    load factor 1; load_path() serves a job driven by `history`)."""
    import numpy as np
    h = result.get("history", {}).get("steps", {})
    lf = np.asarray(h.get("load_factor", []), dtype=float)
    if lf.ndim != 1 or len(lf) < 2 or not np.all(np.diff(lf) > 0):
        return None
    names = [n for n in h.get("pair_names", []) if pairs is None or n in pairs]
    force = _history_columns(h, "force", names, len(lf))
    begin = _history_columns(h, "contact_begin", names, len(lf))
    end = _history_columns(h, "contact_end", names, len(lf))
    out = {}
    for name in names:
        if force[name] is not None:
            width = end[name] - begin[name] if begin[name] is not None and end[name] is not None else \
                np.zeros(len(lf))
            out[name] = {"force": force[name], "width": width}
    return {"load_factor": lf, "pairs": out}


def _support_reactions(result, rows):
    """{body: (S, 2)}: the force the supports of each supported body exert in each step (the sum of its
    `reaction`), from the step groups when the file keeps all S of them; None otherwise. A step read in part
    carries them as "support_reaction" (plot_select reads the `reaction_total` of the bodies with supports); a
    step read whole has the bodies' `reaction`, and the bodies whose reaction is 0 in every step are left out."""
    import numpy as np
    steps = result.get("steps", [])
    if len(steps) != rows or not steps:
        return None
    per_step = []
    for step in steps:
        if "support_reaction" in step:
            per_step.append({n: np.asarray(r, dtype=float) for n, r in step["support_reaction"].items()})
        elif step.get("bodies") and all("reaction" in b for b in step["bodies"].values()):
            per_step.append({n: np.asarray(b["reaction"], dtype=float).reshape(-1, 2).sum(axis=0)
                             for n, b in step["bodies"].items()})
        else:
            return None
    names = [n for n in per_step[-1] if all(n in s for s in per_step)]
    out = {n: np.array([s[n] for s in per_step]) for n in names}
    return {n: r for n, r in out.items() if np.any(r != 0)} or None


def load_path(result, pairs=None):
    """The load path of a result with more than one step, one point per step (/history/steps has a row for every
    step, whatever the file keeps): {"x": (S,), "x_label": "load factor" when the load factors increase (a
    loading job), else "step" (the step numbers 0 ... S-1: a job driven by its conditions' `history`, whose load
    factors are all 1), "load_factor": (S,), "pairs": {pair: {"force": (S,) the normal contact force,
    "tangential_force": (S,) or None}} for the pairs named in `pairs` (None: every pair), "reaction": {body: (S,
    2)} the force of each supported body's supports in each step (together they balance the applied loads), or
    None when the file does not keep every step}. None for a result of one step, and for an adaptive job (its job
    has `adaptivity`: its steps refine the mesh under one load; the pressure panels show them)."""
    import numpy as np
    h = result.get("history", {}).get("steps", {})
    lf = np.asarray(h.get("load_factor", []), dtype=float)
    if lf.ndim != 1 or len(lf) < 2 or (result.get("job") or {}).get("adaptivity"):
        return None
    increasing = bool(np.all(np.diff(lf) > 0))
    steps = np.asarray(h.get("step", np.arange(len(lf))), dtype=float)
    names = [n for n in h.get("pair_names", []) if pairs is None or n in pairs]
    force = _history_columns(h, "force", names, len(lf))
    tangential = _history_columns(h, "tangential_force", names, len(lf))
    return {"x": lf if increasing else steps, "x_label": "load factor" if increasing else "step",
            "load_factor": lf, "reaction": _support_reactions(result, len(lf)),
            "pairs": {name: {"force": force[name], "tangential_force": tangential[name]}
                      for name in names if force[name] is not None}}


def draw_load_curve(ax, curve):
    """Force (left axis, solid) and contact width (right axis, dashed) of each pair against the load factor."""
    import matplotlib.pyplot as plt
    colors = plt.get_cmap("tab10")
    lf = curve["load_factor"]
    right = ax.twinx()
    for j, (name, c) in enumerate(curve["pairs"].items()):
        ax.plot(lf, c["force"], color=colors(j % 10), marker="o", ms=3, lw=1.2, label=f"{name}: force")
        right.plot(lf, c["width"], color=colors(j % 10), marker="s", ms=3, lw=1.0, ls="--",
                   label=f"{name}: contact width")
    ax.set_xlabel("load factor")
    ax.set_ylabel("contact force (solid)")
    right.set_ylabel("contact width (dashed)")
    ax.set_title(f"load curve ({len(lf)} load steps)", fontsize=10)
    ax.grid(True, alpha=0.3)
    if len(curve["pairs"]) <= 3:
        handles = ax.get_legend_handles_labels()[0] + right.get_legend_handles_labels()[0]
        ax.legend(handles, [h.get_label() for h in handles], fontsize=7, loc="upper left", framealpha=0.8)


def _pair_lines(path, each):
    """The pairs' force curves to draw: [(label, normal force (S,), tangential force (S,) or None)], one per pair
    when `each`, else the sums over the pairs."""
    import numpy as np
    pairs = path["pairs"]
    if each:
        return [(name, p["force"], p["tangential_force"]) for name, p in pairs.items()]
    if not pairs:
        return []
    normal = np.sum([p["force"] for p in pairs.values()], axis=0)
    tangents = [p["tangential_force"] for p in pairs.values() if p["tangential_force"] is not None]
    return [(f"sum of the {len(pairs)} pairs drawn", normal, np.sum(tangents, axis=0) if tangents else None)]


def _reaction_lines(reaction):
    """[(label, (S,))]: x and y of each supported body's reaction, up to 2 bodies; beyond, their sum."""
    if not reaction:
        return []
    if len(reaction) > 2:
        total = sum(reaction.values())
        return [(f"supports' force {axis} ({len(reaction)} bodies)", total[:, i]) for i, axis in enumerate("xy")]
    return [(f"{body}'s supports: {axis}", r[:, i]) for body, r in reaction.items() for i, axis in enumerate("xy")]


def draw_load_history(ax, path):
    """The load history of a stepped job against the step (load_path() with x_label "step"): the force of the
    supports in x and y (solid, grey shades: the load applied, balanced), and the normal (dashed) and tangential
    (dotted) contact force of each pair drawn (their sums beyond 3 pairs). Every line has one point per step."""
    import matplotlib.pyplot as plt
    colors = plt.get_cmap("tab10")
    x = path["x"]
    for i, (label, values) in enumerate(_reaction_lines(path["reaction"])):
        ax.plot(x, values, color=("black", "dimgrey", "grey", "darkgrey")[i % 4], marker="o", ms=3, lw=1.4,
                ls="-" if i % 2 == 0 else "-.", gid="load_path", label=label)
    for j, (label, normal, tangential) in enumerate(_pair_lines(path, len(path["pairs"]) <= 3)):
        ax.plot(x, normal, color=colors(j % 10), marker="s", ms=3, lw=1.0, ls="--", gid="load_path",
                label=f"{label}: normal")
        if tangential is not None:
            ax.plot(x, tangential, color=colors(j % 10), marker="^", ms=3, lw=1.0, ls=":", gid="load_path",
                    label=f"{label}: tangential")
    ax.set_xlabel("step")
    ax.set_xticks(x if len(x) <= 12 else x[::max(1, len(x) // 8)])
    ax.set_ylabel("force")
    constant = len(set(path["load_factor"].tolist())) == 1
    ax.set_title(f"load history ({len(x)} steps" + (f", load factor {path['load_factor'][0]:g} in each)"
                                                     if constant else ")"), fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.axhline(0.0, color="black", lw=0.5)
    ax.legend(fontsize=6, loc="best", framealpha=0.8)
