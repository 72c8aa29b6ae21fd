"""The figure of a result: contact pressure along each pair, zoomed on the contact zone (for a friction pair with
the tangential traction below it, the stick zone shaded); the final mesh coloured by von Mises stress, whole and
around the contact."""
import os

from .errors import BadInput
from .results import pair_friction, read_events, read_result

# The pressure panels' horizontal coordinate: "arc", the arc length along the slave edge from its first node (the
# coordinate of the events' profiles, of the web page, of contact_begin/contact_end; it also serves edges that are
# not horizontal), or "x".
COORDINATES = ("arc", "x")
AXIS_LABELS = {"arc": "arc length along the slave edge", "x": "x of the slave edge node"}  # the web page's: "arc"
# By default a pressure panel shows the contact zone plus ZOOM_MARGIN of its width on each side, and at least
# ZOOM_NODES slave nodes beyond each end (so that the opening of the contact shows on a coarse mesh).
ZOOM_MARGIN = 0.15
ZOOM_NODES = 3
STICK_COLOUR = "tab:green"  # the stick zone's shading
BOUND_COLOUR = "grey"  # the friction bound (slip where the traction reaches it)


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


def _node_values(c, key):
    """A pair's dataset `key` per slave node, NaN where the node takes no part in the contact (status 1 to 3: not
    opposite the master, a crosspoint, barely covered; docs/results-format.md), so curves break there."""
    import numpy as np
    v = np.asarray(c[key], dtype=float).copy()
    status = c.get("status")
    if status is not None and len(status) == len(v):
        v[np.isin(np.asarray(status), (1, 2, 3))] = np.nan
    return v


def contact_pressure(c):
    """A pair's pressure per slave node, NaN where the node takes no part in the contact (_node_values)."""
    return _node_values(c, "pressure")


def tangential_traction(c):
    """A friction pair's tangential traction per slave node (along its tangent), NaN where the node takes no
    part in the contact; None for a frictionless pair or a file without it."""
    return _node_values(c, "tangential_traction") if "tangential_traction" in c else None


def friction_text(friction):
    """ "Coulomb, mu = 0.2" or "Tresca, g = 5" for pair_friction()'s dict."""
    if friction["law"] == "tresca":
        return f"Tresca, g = {friction['bound']:g}"
    if friction["law"] == "coulomb":
        return f"Coulomb, mu = {friction['coefficient']:g}"
    return friction["law"]


def stick_zones(s, stick):
    """Where the nodes stick along the coordinate s: [(lo, hi), ...], one per run of neighbouring nodes with
    stick true, each reaching halfway to the next node that does not stick (to the node itself at an end of the
    edge), in increasing order; [] when no node sticks."""
    import numpy as np
    order = np.argsort(s)
    s, on = np.asarray(s, dtype=float)[order], np.asarray(stick, dtype=bool)[order]
    zones, n, i = [], len(s), 0
    while i < n:
        if not on[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and on[j + 1]:
            j += 1
        lo = (s[i - 1] + s[i]) / 2 if i > 0 else s[i]
        hi = (s[j] + s[j + 1]) / 2 if j + 1 < n else s[j]
        zones.append((float(lo), float(hi)))
        i = j + 1
    return zones


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




def edge_coordinate(c, along="arc"):
    """A pair's slave nodes' coordinate on the pressure axis: their arc length along the slave edge (along="arc")
    or their x (along="x")."""
    return c["arc_length"] if along == "arc" and "arc_length" in c else c["x"]


def contact_zone(curves):
    """Where the curves [(coordinate, pressure), ...] are in contact (pressure > 0): ((lo, hi), (lo_out, hi_out)),
    the coordinates of the first and last node in contact over all curves, and of the ZOOM_NODES-th node beyond
    each end (or the edge's end); None when no node is in contact."""
    import numpy as np
    found = None
    for s, p in curves:
        order = np.argsort(s)
        s, p = np.asarray(s, dtype=float)[order], np.nan_to_num(np.asarray(p, dtype=float)[order])
        on = np.flatnonzero(p > 0)
        if not len(on):
            continue
        i, j = on[0], on[-1]
        lo, hi, lo_out, hi_out = s[i], s[j], s[max(i - ZOOM_NODES, 0)], s[min(j + ZOOM_NODES, len(s) - 1)]
        if found is not None:
            (lo0, hi0), (lo_out0, hi_out0) = found
            lo, hi, lo_out, hi_out = min(lo, lo0), max(hi, hi0), min(lo_out, lo_out0), max(hi_out, hi_out0)
        found = ((float(lo), float(hi)), (float(lo_out), float(hi_out)))
    return found


def zoomed_range(zone, reach, edge):
    """The pressure axis's default range: the contact zone (lo, hi) plus ZOOM_MARGIN of its width on each side,
    reaching at least to `reach` (lo_out, hi_out), within the slave edge `edge` (lo, hi)."""
    (lo, hi), (lo_out, hi_out) = zone, reach
    pad = ZOOM_MARGIN * (hi - lo)
    return max(edge[0], min(lo - pad, lo_out)), min(edge[1], max(hi + pad, hi_out))


def pressure_range(curves, xlim=None):
    """The pressure axis's range (lo, hi) for the curves [(coordinate, pressure), ...]: xlim when it is a pair of
    numbers; None (matplotlib's range, the whole edge) for xlim="full" or when nothing is in contact; else the
    contact zone with its margins (zoomed_range)."""
    import numpy as np
    if isinstance(xlim, str):
        return None
    if xlim is not None:
        return float(xlim[0]), float(xlim[1])
    found = contact_zone(curves)
    if found is None:
        return None
    edge = (min(float(np.nanmin(s)) for s, _ in curves), max(float(np.nanmax(s)) for s, _ in curves))
    lo, hi = zoomed_range(*found, edge)
    return (lo, hi) if hi > lo else None


def _iteration_profiles(events):
    """{pair: [(iteration, arc length, pressure, tangential traction or None), ...]} from the iteration events
    (a friction pair's events carry `tangential_tractions`, as many as `positions`)."""
    import numpy as np
    profiles = {}
    for e in events or []:
        if e.get("type") == "iteration":
            for p in e.get("pairs", []):
                if p.get("positions") and p.get("pressures"):
                    t = p.get("tangential_tractions")
                    t = np.asarray(t, float) if t and len(t) == len(p["positions"]) else None
                    profiles.setdefault(p["name"], []).append(
                        (e["iteration"], np.asarray(p["positions"], float), np.asarray(p["pressures"], float), t))
    return profiles


def _step_curves(steps, pair, along, max_curves, loaded, values=contact_pressure):
    """One curve per plotted step: [(step, coordinate, values(pair), label suffix), ...] (values: contact_pressure
    or tangential_traction; a step whose pair has none is left out)."""
    curves = []
    for k in _spread(len(steps), max_curves):
        c = steps[k]["contacts"].get(pair)
        v = values(c) if c is not None and "x" in c else None
        if v is not None:
            load = f"load {steps[k]['load_factor']:g}, " if loaded else ""
            curves.append((k, edge_coordinate(c, along), v,
                           f" ({load}iter {steps[k]['iteration']}, {len(c['x'])} nodes)"))
    return curves


def _iteration_curves(profiles, c_final, along, max_curves, tangential=False):
    """One curve per plotted iteration of the events: [(iteration, coordinate, pressure, ""), ...], or with
    tangential=True the tangential traction (iterations without it left out). The events give arc lengths: with
    along="x" they are mapped to x through the final step's slave nodes."""
    import numpy as np
    arc, xs = c_final.get("arc_length"), c_final.get("x")
    to_x = along == "x" and arc is not None and xs is not None and len(arc) >= 2
    curves = []
    for i in _spread(len(profiles), max_curves):
        it, s, p, t = profiles[i]
        v = t if tangential else p
        if v is not None:
            curves.append((it, np.interp(s, arc, xs) if to_x else s, v, ""))
    return curves


def _curve_colours(curves):
    """(colour map, norm) that colour the curves [(number, ...), ...] from the first number to the last."""
    import matplotlib.colors
    import matplotlib.pyplot as plt
    numbers = [n for n, *_ in curves] or [0]
    return plt.get_cmap("viridis"), matplotlib.colors.Normalize(vmin=numbers[0],
                                                                vmax=max(numbers[-1], numbers[0] + 1))


def _draw_pressure(fig, ax, pair, curves, c_final, final_iteration, what, total, along, xlim, bar_axes=None):
    """One pair's panel: the curves coloured by their place in the run, the final profile from the file; the
    horizontal range from pressure_range() of the step curves and the final profile. The colour bar (more than 6
    curves) takes its room from bar_axes (default: ax). Returns the contact zone and the range set ((lo, hi) or
    None each)."""
    import matplotlib.cm
    cmap, norm = _curve_colours(curves)
    labelled = len(curves) <= 6
    for number, s, p, extra in curves:
        ax.plot(s, p, color=cmap(norm(number)), lw=1.0, marker="." if len(s) < 80 else None, ms=2.5,
                label=f"{what} {number}{extra}" if labelled else None)
    if len(curves) > 1 and not labelled:
        sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
        fig.colorbar(sm, ax=bar_axes or ax, fraction=0.05, pad=0.02).set_label(what, fontsize=8)
    # The zone is that of the solutions drawn: the steps' profiles and the final one, not the iterations on the
    # way (an early iterate may press far beyond the final contact).
    solutions = [(s, p) for _, s, p, _ in curves] if what == "step" else []
    if "x" in c_final:
        final = (edge_coordinate(c_final, along), contact_pressure(c_final))
        ax.plot(*final, color="black", lw=1.5, ls=(0, (5, 3)) if curves else "-",
                label=f"final (iter {final_iteration}, from the file)", zorder=5)
        solutions.append(final)
    limits = pressure_range(solutions, xlim) if solutions else None
    if limits is not None:
        ax.set_xlim(*limits)
    ax.set_xlabel(AXIS_LABELS[along])
    ax.set_ylabel("contact pressure")
    shown = f"{len(curves)} of {total}" if len(curves) < total else f"all {total}"
    ax.set_title(pair + (f" ({shown} {what}s)" if len(curves) > 1 else ""), fontsize=10)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="best", framealpha=0.8)
    found = contact_zone(solutions) if solutions else None
    return (found[0] if found else None), limits


def _pair_axes(fig, spec, friction):
    """A pair's panels in the gridspec cell `spec`: the pressure panel; for a friction pair it takes the upper
    half and the tangential traction the lower, sharing the horizontal axis. (pressure axes, tangential axes or
    None)."""
    if not friction:
        return fig.add_subplot(spec), None
    halves = spec.subgridspec(2, 1, hspace=0.08)
    ax = fig.add_subplot(halves[0, 0])
    return ax, fig.add_subplot(halves[1, 0], sharex=ax)


def _draw_stick(ax, zones, label):
    """The stick zones [(lo, hi), ...] shaded across ax's height, behind the curves (the first one labelled when
    `label`)."""
    for i, (lo, hi) in enumerate(zones):
        ax.axvspan(lo, hi, color=STICK_COLOUR, alpha=0.2, lw=0, zorder=0, gid="stick_zone",
                   label="stick zone (final)" if label and i == 0 else None)


def _friction_bound(c, friction):
    """The largest tangential traction each slave node can carry, the bound where it slips: mu p (Coulomb) or g
    (Tresca, on the whole edge)."""
    import numpy as np
    if friction["law"] == "coulomb":
        return friction["coefficient"] * contact_pressure(c)
    return np.full(len(c["pressure"]), friction["bound"])


def _draw_tangential(ax, curves, c_final, friction, along, zones):
    """A friction pair's tangential-traction panel (below its pressure panel, sharing the horizontal axis): the
    curves [(number, coordinate, traction, _), ...] coloured as the pressure's, the final traction from the file
    (black; its legend names the friction law and the total tangential force), the final state's friction bound
    +-mu p or +-g (dotted: where the traction reaches it the node slips) and the final stick zones shaded."""
    cmap, norm = _curve_colours(curves)
    for number, s, t, _ in curves:
        ax.plot(s, t, color=cmap(norm(number)), lw=1.0, marker="." if len(s) < 80 else None, ms=2.5)
    s, t = edge_coordinate(c_final, along), tangential_traction(c_final)
    bound = _friction_bound(c_final, friction)
    name = "mu p" if friction["law"] == "coulomb" else "g"
    ax.plot(s, bound, color=BOUND_COLOUR, lw=1.0, ls=":", label=f"slip bound ±{name}", gid="friction_bound")
    ax.plot(s, -bound, color=BOUND_COLOUR, lw=1.0, ls=":", gid="friction_bound")
    if t is not None:
        ax.plot(s, t, color="black", lw=1.5, ls=(0, (5, 3)) if curves else "-", zorder=5, gid="tangential_traction",
                label=f"final ({friction_text(friction)}): force {friction['tangential_force']:.4g}")
    _draw_stick(ax, zones, label=True)
    ax.axhline(0.0, color="black", lw=0.5)
    ax.set_xlabel(AXIS_LABELS[along])
    ax.set_ylabel("tangential traction")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="best", framealpha=0.8)


def _draw_friction(ax, tax, steps, pair, friction, profiles, along, max_curves, loaded):
    """The friction pair's tangential traction in tax (the step curves, or with a single step the events'
    iterations) and its final stick zones shaded in both panels; ax's tick labels left to tax, below it.
    Returns the stick zones [(lo, hi), ...]."""
    c_final = steps[-1]["contacts"][pair]
    if len(steps) > 1:
        curves = _step_curves(steps, pair, along, max_curves, loaded, values=tangential_traction)
    else:
        curves = _iteration_curves(profiles, c_final, along, max_curves, tangential=True)
    stick = friction["stick"]
    zones = stick_zones(edge_coordinate(c_final, along), stick) if stick is not None else []
    _draw_stick(ax, zones, label=False)
    _draw_tangential(tax, curves, c_final, friction, along, zones)
    ax.set_xlabel("")
    ax.tick_params(labelbottom=False)
    return zones


def _displaced(body, warp, nodes=None):
    """A body's points (those of `nodes` when given), displaced by warp x displacement."""
    xy, u = body["points"], body.get("displacement")
    moved = xy + warp * u if warp and u is not None and len(u) == len(xy) else xy
    return moved if nodes is None else moved[nodes]


def _meshes(final, warp):
    """Per body of the step, in order: {"name", "verts": (m, 4, 2) displaced cell corners, "values": von Mises
    per cell (NaN without), "level": highest refinement level}."""
    import numpy as np
    out = []
    for name in final["body_names"]:
        b = final["bodies"][name]
        xy = _displaced(b, warp)
        cells = b["cells"] if "cells" in b else b["quads"]  # files before triangles have quads only
        # A triangle's fourth entry is -1: drawn as its first node again, so that every cell has four corners.
        cells = np.where(cells >= 0, cells, cells[:, :1])
        vm, lv = b.get("von_mises"), b.get("level")
        out.append({"name": name, "verts": xy[cells],
                    "values": vm if vm is not None and len(vm) == len(cells) else np.full(len(cells), np.nan),
                    "level": int(lv.max()) if lv is not None and len(lv) else 0})
    return out


def _slave_edges(final, warp):
    """{pair: (its displaced slave nodes (k, 2), its contact group)} per pair of the step."""
    out = {}
    for pair in final["pair_names"]:
        c = final["contacts"].get(pair, {})
        body = final["bodies"].get(c.get("attrs", {}).get("slave_body"))
        nodes = c.get("node")
        if body is not None and nodes is not None and len(nodes):
            out[pair] = (_displaced(body, warp, nodes), c)
    return out


def _bounds(points, pad=0.0):
    """(x0, x1, y0, y1) around points (n, 2), `pad` times the larger side wider on each side."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    p = pad * float(max(hi - lo))
    return (lo[0] - p, hi[0] + p, lo[1] - p, hi[1] + p)


def _zoom_box(edges, ranges, along, whole):
    """The square of the mesh around the plotted stretch of each slave edge: centred on the slave nodes whose
    coordinate is within their pair's pressure range (ranges: {pair: (lo, hi)}), ZOOM_MARGIN wider than them on
    each side. None without such nodes, or when it would not magnify the whole mesh's box `whole` at least 3 times."""
    import numpy as np
    inside = []
    for pair, (lo, hi) in ranges.items():
        if pair in edges:
            xy, c = edges[pair]
            s = edge_coordinate(c, along)
            inside.append(xy[(s >= lo) & (s <= hi)])
    points = np.concatenate(inside) if inside else np.zeros((0, 2))
    if not len(points):
        return None
    x0, x1, y0, y1 = _bounds(points)
    half = 0.5 * max(x1 - x0, y1 - y0) * (1 + 2 * ZOOM_MARGIN)
    if half <= 0 or 2 * half > max(whole[1] - whole[0], whole[3] - whole[2]) / 3:
        return None
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    return (cx - half, cx + half, cy - half, cy + half)


def _fit(fig, ax, box):
    """box (x0, x1, y0, y1) widened in one direction to the shape of ax's panel, so that at equal aspect all of it
    shows and the panel is filled; with the screen pixels per length unit: (box, pixels per unit)."""
    pos = ax.get_position()
    width, height = pos.width * fig.get_figwidth() * fig.dpi, pos.height * fig.get_figheight() * fig.dpi
    x0, x1, y0, y1 = box
    scale = min(width / (x1 - x0), height / (y1 - y0))
    cx, cy, hx, hy = (x0 + x1) / 2, (y0 + y1) / 2, width / scale / 2, height / scale / 2
    return (cx - hx, cx + hx, cy - hy, cy + hy), scale


def _edge_opacity(verts, pixels_per_unit):
    """The opacity of black cell edges, growing with the cell's size on screen, its narrower side (area / longest
    edge): none up to 2 px, full (0.7) from 8 px. A drawn edge is about half a pixel wide, so on a cell of 2 px
    the edges would cover half of it and on a refined region they would merge into a black blob (the colours
    lost); faded with the size, coarse cells show their edges, fine ones their colour, and the zoom panel shows
    the fine cells large enough to have edges."""
    import numpy as np
    x, y = verts[..., 0], verts[..., 1]
    dx, dy = np.roll(x, -1, axis=1) - x, np.roll(y, -1, axis=1) - y
    area = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1))
    longest = np.hypot(dx, dy).max(axis=1)
    size = np.divide(area, longest, out=np.zeros_like(area), where=longest > 0) * pixels_per_unit
    return 0.7 * np.clip((size - 2.0) / 6.0, 0.0, 1.0)


def _edge_colours(faces, opacity):
    """Each cell's edge: its face colour darkened by `opacity` (black at 1), opaque. Edges of the face colour
    rather than transparent ones, so that the seams between antialiased cells do not let the white through."""
    import numpy as np
    edges = faces.copy()
    edges[:, :3] *= (1.0 - opacity)[:, None]
    edges[:, 3] = np.maximum(edges[:, 3], opacity)
    return edges


def _draw_mesh(fig, ax, meshes, edges, box, norm, labels):
    """The meshes in ax, showing box (x0, x1, y0, y1) at equal aspect (_fit): cells coloured by von Mises stress
    with _edge_opacity, each pair's slave edge in red, and the bodies' names when `labels`."""
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.collections import PolyCollection
    box, scale = _fit(fig, ax, box)
    ax.set_xlim(box[0], box[1])
    ax.set_ylim(box[2], box[3])
    ax.set_aspect("equal")
    verts = np.concatenate([m["verts"] for m in meshes]) if meshes else np.zeros((0, 4, 2))
    values = np.concatenate([m["values"] for m in meshes]) if meshes else np.zeros(0)
    faces = plt.get_cmap("viridis")(norm(values))  # NaN: transparent
    ax.add_collection(PolyCollection(verts, facecolors=faces, linewidths=0.4,
                                     edgecolors=_edge_colours(faces, _edge_opacity(verts, scale))), autolim=False)
    for xy, _ in edges.values():
        ax.plot(xy[:, 0], xy[:, 1], color="red", lw=1.2, zorder=4, scalex=False, scaley=False)
    for m in meshes if labels else []:
        if len(m["verts"]):
            x0, x1, y0, y1 = _bounds(m["verts"].reshape(-1, 2))
            ax.text((x0 + x1) / 2, (y0 + y1) / 2, m["name"], ha="center", va="center", fontsize=9, zorder=5,
                    clip_on=True, bbox=dict(boxstyle="round,pad=0.2", facecolor="white", alpha=0.75,
                                            edgecolor="none"))


def _stress_norm(meshes):
    import matplotlib.colors
    import numpy as np
    values = np.concatenate([m["values"] for m in meshes]) if meshes else np.zeros(0)
    values = values[np.isfinite(values)]
    return matplotlib.colors.Normalize(*(values.min(), values.max()) if len(values) else (0.0, 1.0))


def _whole_box(meshes):
    """(x0, x1, y0, y1) around every cell, 2 % wider on each side."""
    import numpy as np
    corners = np.concatenate([m["verts"].reshape(-1, 2) for m in meshes]) if meshes else np.zeros((1, 2))
    x0, x1, y0, y1 = _bounds(corners, pad=0.02)
    return (x0, x1, y0, y1) if x1 > x0 and y1 > y0 else (x0 - 1, x1 + 1, y0 - 1, y1 + 1)


def _mesh_title(meshes, warp):
    return ("final mesh" + (f", deformed (displacement x {warp:g})" if warp else ", undeformed") + ": "
            + ", ".join(f"{m['name']} {len(m['verts'])} cells"
                        + (f", refinement level <= {m['level']}" if m["level"] else "") for m in meshes))


def _mesh_row(fig, spec, final, warp, ranges, along):
    """The bottom row in the gridspec cell `spec`: the whole final mesh displaced by warp and, when the pressure
    panels are zoomed (ranges: {pair: their (lo, hi)}), a zoom on the stretch of the slave edges they show
    (_zoom_box), marked by a dashed box on the whole mesh; one colour bar. The zoom shows the true displacement
    (the undeformed mesh with warp=0): magnified, an exaggerated one would show the bodies overlapping by (warp - 1)
    times their initial gap where they touch. Returns the zoom's box or None."""
    import matplotlib.cm
    from matplotlib.patches import Rectangle
    meshes, edges = _meshes(final, warp), _slave_edges(final, warp)
    whole = _whole_box(meshes)
    marked = _zoom_box(edges, ranges, along, whole)
    true_warp = 1.0 if warp else 0.0
    true_edges = _slave_edges(final, true_warp) if marked else {}
    zoom = _zoom_box(true_edges, ranges, along, whole) if marked else None
    ratios = [1.0, 1.0, 0.05] if zoom else [1.0, 0.03]
    row = spec.subgridspec(1, len(ratios), width_ratios=ratios, wspace=0.2 if zoom else 0.04)
    norm = _stress_norm(meshes)
    ax = fig.add_subplot(row[0, 0])
    _draw_mesh(fig, ax, meshes, edges, whole, norm, labels=True)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    if zoom:
        ax.add_patch(Rectangle((marked[0], marked[2]), marked[1] - marked[0], marked[3] - marked[2], fill=False,
                               edgecolor="black", ls="--", lw=1.0, zorder=6))
        zax = fig.add_subplot(row[0, 1])
        _draw_mesh(fig, zax, _meshes(final, true_warp), true_edges, zoom, norm, labels=False)
        zax.set_title("around the contact (the dashed box), " + ("true displacement" if warp else "undeformed"),
                      fontsize=9)
        zax.set_xlabel("x")
    sm = matplotlib.cm.ScalarMappable(norm=norm, cmap="viridis")
    fig.colorbar(sm, cax=fig.add_subplot(row[0, -1])).set_label("von Mises stress")
    fig.text(0.5, spec.get_position(fig).y1 + 0.03, _mesh_title(meshes, warp), ha="center", va="bottom",
             fontsize=10)
    return zoom


def plot_result(result, png, events=None, warp=None, title=None, max_curves=12, xlim=None, along="arc"):
    """Draws one figure of 1000 x 800 pixels (10 x 8 inches at 100 dpi) into png:

    top: the contact pressure along each pair (one panel per pair) against `along`: "arc" (the arc length along
         the slave edge from its first node, as the web page and the events) or "x"; one curve per adaptive or
         load step; for a load-stepped result one more panel, the load curve (load_curve(): force and contact
         width of each pair against the load factor);
         with a single step, the pressure profile of each iteration when `events` (the job's events, a list of
         dicts or a path to saved events) are given (at most max_curves of them, spread over the run), and the
         final profile from the file (slave nodes that take no part in the contact are left out).
         The horizontal range: xlim=None, the contact zone (the nodes with pressure > 0 on any curve drawn of the
         pair) plus ZOOM_MARGIN (15 %) of its width on each side and at least ZOOM_NODES (3) nodes beyond each
         end, within the slave edge (the whole edge without contact); xlim=(lo, hi) for every pair's panel;
         xlim="full": the whole slave edge;
         a friction pair's panel is split: the pressure above, the tangential traction below on the same
         horizontal axis (its curves as the pressure's, the final one from the file in black, the final friction
         bound +-mu p or +-g dotted, the legend naming the law, its coefficient or bound and the tangential
         force), the final stick zones (stick_zones()) shaded green in both;
    bottom: each body's final mesh, deformed, cells coloured by von Mises stress, cell edges drawn where the cells
         are large enough on screen to show them (_edge_opacity), the slave edge of each pair
         in red; next to it, when the pressure panels are zoomed, the mesh around the part of the slave edges
         they show, with the same colours (the fine cells there with their edges); one colour bar. The mesh is
         drawn displaced by warp x displacement: warp=None picks the scale that makes the largest displacement 4 %
         of the mesh (auto_warp), 0 draws the undeformed mesh.

    result is a path or the dict of read_result(). Returns {"warp": the mesh's scale, "pressure_xlim": {pair:
    (lo, hi) of its panel's horizontal axis, as drawn}, "contact_zone": {pair: (lo, hi) of its nodes in contact,
    or None}, "mesh_zoom": (x0, x1, y0, y1) of the zoom panel or None, "friction": {friction pair: its law, as
    "Coulomb, mu = 0.2"}, "tangential_force": {friction pair: its final total tangential force}, "stick_zones":
    {friction pair: [(lo, hi), ...] shaded}, "figure": the matplotlib Figure drawn (closed)}."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if along not in COORDINATES:
        raise BadInput(f"along must be one of {', '.join(COORDINATES)}, not {along!r}")
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
    frictions = {pair: pair_friction(final["contacts"][pair]) for pair in pair_names}
    frictions = {pair: f for pair, f in frictions.items() if f is not None}  # the friction pairs
    # A friction pair's pressure and tangential traction share the top row's height: the row gets more of it.
    gs = fig.add_gridspec(2, npairs + (curve is not None), height_ratios=[1.6, 1.0] if frictions else [1.0, 1.25],
                          left=0.08, right=0.92, top=0.92, bottom=0.07, hspace=0.4, wspace=0.4)
    name = attrs.get("name") or os.path.basename(result.get("path", ""))
    stop = attrs.get("stop_reason", "")
    iterations = attrs.get("iterations", "?")
    fig.suptitle(title or f"{name}: {iterations} iteration{'' if iterations == 1 else 's'}, {stop}, "
                 f"{len(steps)} step{'s' if len(steps) != 1 else ''}", fontsize=12)

    profiles = _iteration_profiles(events) if len(steps) == 1 else {}
    xlims, zones, zoomed, sticks = {}, {}, {}, {}
    for j, pair in enumerate(pair_names or [None]):
        ax, tax = _pair_axes(fig, gs[0, j], pair in frictions)
        if pair is None:
            ax.text(0.5, 0.5, "no contact pair", ha="center", va="center", transform=ax.transAxes)
            continue
        c_final = final["contacts"][pair]
        if len(steps) > 1:
            curves = _step_curves(steps, pair, along, max_curves, loaded=curve is not None)
            what, total = "step", len(steps)
        else:
            curves = _iteration_curves(profiles.get(pair, []), c_final, along, max_curves)
            what, total = "iteration", len(profiles.get(pair, []))
        zones[pair], limits = _draw_pressure(fig, ax, pair, curves, c_final, final["iteration"], what, total,
                                             along, xlim, bar_axes=[ax, tax] if tax else None)
        if tax is not None:
            sticks[pair] = _draw_friction(ax, tax, steps, pair, frictions[pair], profiles.get(pair, []), along,
                                          max_curves, loaded=curve is not None)
        if limits is not None:
            zoomed[pair] = limits
        xlims[pair] = tuple(float(v) for v in ax.get_xlim())

    if curve is not None:
        _draw_load_curve(fig.add_subplot(gs[0, npairs]), curve)
    zoom = _mesh_row(fig, gs[1, :], final, warp, zoomed, along)
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return {"warp": warp, "pressure_xlim": xlims, "contact_zone": zones, "mesh_zoom": zoom,
            "friction": {pair: friction_text(f) for pair, f in frictions.items()},
            "tangential_force": {pair: f["tangential_force"] for pair, f in frictions.items()},
            "stick_zones": sticks, "figure": fig}
