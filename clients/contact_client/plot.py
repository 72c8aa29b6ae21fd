"""The figure of a result: contact pressure along each pair, the final mesh coloured by von Mises stress."""
import os

from .errors import BadInput
from .results import read_events, read_result


def _spread(n, k):
    """At most k indices of range(n), evenly spread, the first and the last included."""
    if n <= k:
        return list(range(n))
    return sorted({round(i * (n - 1) / (k - 1)) for i in range(k)})


def auto_warp(step, fraction=0.04):
    """The displacement scale that makes the largest displacement of the step `fraction` of the meshes' extent,
    rounded down to 1, 2 or 5 times a power of ten (0 when nothing moves)."""
    import numpy as np
    extent, largest = 0.0, 0.0
    for b in step["bodies"].values():
        xy, u = b.get("points"), b.get("displacement")
        if xy is not None and len(xy):
            extent = max(extent, float(np.max(xy.max(axis=0) - xy.min(axis=0))))
        if u is not None and len(u):
            largest = max(largest, float(np.max(np.hypot(u[:, 0], u[:, 1]))))
    if largest <= 0 or extent <= 0 or not np.isfinite(largest):
        return 0.0
    raw = fraction * extent / largest
    power = 10.0 ** np.floor(np.log10(raw))
    return float(max(m for m in (1.0, 2.0, 5.0) if m * power <= raw * (1 + 1e-12)) * power)


def contact_pressure(c):
    """A pair's pressure per slave node, NaN where the node takes no part in the contact (status 1 to 3: not
    opposite the master, a crosspoint, barely covered; docs/results-format.md), so curves break there."""
    import numpy as np
    p = np.asarray(c["pressure"], dtype=float).copy()
    status = c.get("status")
    if status is not None and len(status) == len(p):
        p[np.isin(np.asarray(status), (1, 2, 3))] = np.nan
    return p


def load_curve(result):
    """The force-load curve of a load-stepped result (Fig. 4 of the paper as a curve), from /history/steps:
    {"load_factor": (S,), "pairs": {pair: {"force": (S,), "width": (S,)}}}, the width being contact_end -
    contact_begin (the half-width of a symmetric half model). None unless the file holds more than one step at
    increasing load factors (an adaptive run's steps all share load factor 1)."""
    import numpy as np
    h = result.get("history", {}).get("steps", {})
    lf = np.asarray(h.get("load_factor", []), dtype=float)
    if lf.ndim != 1 or len(lf) < 2 or not np.all(np.diff(lf) > 0):
        return None
    names = list(h.get("pair_names", []))
    force = np.asarray(h.get("force", np.zeros((len(lf), 0))), dtype=float).reshape(len(lf), -1)
    begin = np.asarray(h.get("contact_begin", np.zeros_like(force)), dtype=float).reshape(len(lf), -1)
    end = np.asarray(h.get("contact_end", np.zeros_like(force)), dtype=float).reshape(len(lf), -1)
    pairs = {name: {"force": force[:, j], "width": end[:, j] - begin[:, j]}
             for j, name in enumerate(names) if j < force.shape[1]}
    return {"load_factor": lf, "pairs": pairs}


def _draw_load_curve(ax, curve):
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


def plot_result(result, png, events=None, warp=None, title=None, max_curves=12):
    """Draws one figure of 1000 x 800 pixels (10 x 8 inches at 100 dpi) into png:

    top: the contact pressure against x along each pair (one panel per pair), one curve per adaptive or load
         step; for a load-stepped result one more panel, the load curve (load_curve(): force and contact width
         of each pair against the load factor);
         with a single step, the pressure profile of each iteration when `events` (the job's events, a list of
         dicts or a path to saved events) are given (at most max_curves of them, spread over the run), and the
         final profile from the file (slave nodes that take no part in the contact are left out);
    bottom: each body's final mesh, deformed, cells coloured by von Mises stress, edges drawn (refinement shows
         as smaller cells), the slave edge of each pair in red, one colour bar. The mesh is drawn displaced by
         warp x displacement: warp=None picks the scale that makes the largest displacement 4 % of the mesh
         (auto_warp), 0 draws the undeformed mesh.

    result is a path or the dict of read_result(). Returns the scale the mesh was drawn with."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.cm
    import matplotlib.colors
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.collections import PolyCollection

    if not isinstance(result, dict):
        result = read_result(result)
    if isinstance(events, (str, os.PathLike)):
        events = read_events(events)
    steps = result["steps"]
    if not steps:
        raise BadInput(f"{result.get('path', 'the result')}: no step in the file (the solve failed before its "
                       "first iteration)")
    final = steps[-1]
    pair_names = final["pair_names"]
    if warp is None:
        warp = auto_warp(final)
    attrs = result["attrs"]

    fig = plt.figure(figsize=(10, 8), dpi=100)
    curve = load_curve(result)
    npairs = max(1, len(pair_names))
    gs = fig.add_gridspec(2, npairs + (curve is not None), height_ratios=[1.0, 1.25], left=0.08, right=0.92, top=0.92, bottom=0.07,
                          hspace=0.32, wspace=0.4)
    name = attrs.get("name") or os.path.basename(result.get("path", ""))
    stop = attrs.get("stop_reason", "")
    iterations = attrs.get("iterations", "?")
    fig.suptitle(title or f"{name}: {iterations} iteration{'' if iterations == 1 else 's'}, {stop}, "
                 f"{len(steps)} step{'s' if len(steps) != 1 else ''}", fontsize=12)

    iteration_profiles = {}
    if len(steps) == 1 and events:
        for e in events:
            if e.get("type") == "iteration":
                for p in e.get("pairs", []):
                    if p.get("positions") and p.get("pressures"):
                        iteration_profiles.setdefault(p["name"], []).append(
                            (e["iteration"], np.asarray(p["positions"], float), np.asarray(p["pressures"], float)))

    for j, pair in enumerate(pair_names or [None]):
        ax = fig.add_subplot(gs[0, j])
        if pair is None:
            ax.text(0.5, 0.5, "no contact pair", ha="center", va="center", transform=ax.transAxes)
            continue
        c_final = final["contacts"][pair]
        cmap = plt.get_cmap("viridis")
        # (number, x, pressure, extra label) per curve, coloured by its place in the run.
        curves, what = [], "step"
        if len(steps) > 1:
            for k in _spread(len(steps), max_curves):
                c = steps[k]["contacts"].get(pair)
                if c is not None and "x" in c:
                    load = f"load {steps[k]['load_factor']:g}, " if curve is not None else ""
                    curves.append((k, c["x"], contact_pressure(c),
                                   f" ({load}iter {steps[k]['iteration']}, {len(c['x'])} nodes)"))
            span = (0, len(steps) - 1)
        else:
            profiles = iteration_profiles.get(pair, [])
            what = "iteration"
            arc, xs = c_final.get("arc_length"), c_final.get("x")
            if xs is None or arc is None or len(arc) < 2:
                arc = None
            for i in _spread(len(profiles), max_curves):
                it, sv, pv = profiles[i]
                curves.append((it, np.interp(sv, arc, xs) if arc is not None else sv, pv, ""))
            span = (profiles[0][0], profiles[-1][0]) if profiles else (0, 1)
        norm = matplotlib.colors.Normalize(vmin=span[0], vmax=max(span[1], span[0] + 1))
        labelled = len(curves) <= 6
        for number, x, pv, extra in curves:
            ax.plot(x, pv, color=cmap(norm(number)), lw=1.0, marker="." if len(x) < 80 else None, ms=2.5,
                    label=f"{what} {number}{extra}" if labelled else None)
        if len(curves) > 1 and not labelled:
            sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
            fig.colorbar(sm, ax=ax, fraction=0.05, pad=0.02).set_label(what, fontsize=8)
        if "x" in c_final:
            ax.plot(c_final["x"], contact_pressure(c_final), color="black", lw=1.5, ls=(0, (5, 3)) if curves else "-",
                    label=f"final (iter {final['iteration']}, from the file)", zorder=5)
        ax.set_xlabel("x of the slave edge node")
        ax.set_ylabel("contact pressure")
        total = len(steps) if what == "step" else len(iteration_profiles.get(pair, []))
        shown = f"{len(curves)} of {total}" if len(curves) < total else f"all {total}"
        ax.set_title(pair + (f" ({shown} {what}s)" if len(curves) > 1 else ""), fontsize=10)
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="best", framealpha=0.8)

    if curve is not None:
        _draw_load_curve(fig.add_subplot(gs[0, npairs]), curve)

    ax = fig.add_subplot(gs[1, :])
    polys, values, levels = [], [], []
    for body in final["body_names"]:
        b = final["bodies"][body]
        xy = b["points"]
        if warp and "displacement" in b and len(b["displacement"]) == len(xy):
            xy = xy + warp * b["displacement"]
        cells = b["cells"] if "cells" in b else b["quads"]  # files before triangles have quads only
        # A triangle's fourth entry is -1: drawn as its first node again, so that every cell has four corners.
        cells = np.where(cells >= 0, cells, cells[:, :1])
        polys.append(xy[cells])
        vm = b.get("von_mises")
        values.append(vm if vm is not None and len(vm) == len(cells) else np.full(len(cells), np.nan))
        lv = b.get("level")
        levels.append((body, len(cells), int(lv.max()) if lv is not None and len(lv) else 0))
    for body, xy in zip(final["body_names"], polys):
        if len(xy):
            flat = xy.reshape(-1, 2)
            centre = (flat.min(axis=0) + flat.max(axis=0)) / 2
            ax.text(centre[0], centre[1], body, ha="center", va="center", fontsize=9, zorder=5,
                    bbox=dict(boxstyle="round,pad=0.2", facecolor="white", alpha=0.75, edgecolor="none"))
    # The slave edge of each pair, displaced like its body.
    for pair in pair_names:
        c = final["contacts"].get(pair, {})
        body = final["bodies"].get(c.get("attrs", {}).get("slave_body"))
        nodes = c.get("node")
        if body is None or nodes is None or not len(nodes):
            continue
        xy = body["points"][nodes]
        if warp and "displacement" in body and len(body["displacement"]) == len(body["points"]):
            xy = xy + warp * body["displacement"][nodes]
        ax.plot(xy[:, 0], xy[:, 1], color="red", lw=1.2, zorder=4)
    verts = np.concatenate(polys) if polys else np.zeros((0, 4, 2))
    vals = np.concatenate(values) if values else np.zeros(0)
    # Edges thin out on fine meshes so that the colours still show.
    lw = float(np.clip(0.3 * np.sqrt(1000.0 / max(1, len(verts))), 0.05, 0.3))
    pc = PolyCollection(verts, array=vals, cmap="viridis", edgecolors=(0, 0, 0, 0.8), linewidths=lw)
    ax.add_collection(pc)
    if len(verts):
        lo, hi = verts.reshape(-1, 2).min(axis=0), verts.reshape(-1, 2).max(axis=0)
        pad = 0.02 * max(hi - lo)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal", adjustable="datalim")  # the panel keeps its size; the shorter side's range grows
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title("final mesh" + (f", deformed (displacement x {warp:g})" if warp else ", undeformed") + ": "
                 + ", ".join(f"{b} {m} cells" + (f", refinement level <= {lv}" if lv else "")
                             for b, m, lv in levels), fontsize=10)
    cb = fig.colorbar(pc, ax=ax, fraction=0.04, pad=0.02)
    cb.set_label("von Mises stress")
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return warp
