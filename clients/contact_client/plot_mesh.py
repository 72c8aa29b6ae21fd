"""The meshes in the plot: each body's final mesh coloured by von Mises stress, displaced by a magnified
displacement (warp) chosen so that it draws no gap in a closed contact that is not there, and a zoom on the
contact."""
from .plot_profiles import ZOOM_MARGIN, edge_coordinate

# The automatic magnification draws no closed contact open by more than GAP_PIXELS pixels (choose_warp).
GAP_PIXELS = 1.0


def auto_warp(step, fraction=0.04):
    """The displacement scale that makes the largest displacement of the step `fraction` of the meshes' extent,
    rounded down to 1, 2 or 5 times a power of ten (0 when nothing moves)."""
    import numpy as np
    extent, largest = _extent(step), 0.0
    for b in step["bodies"].values():
        u = b.get("displacement")
        if u is not None and len(u):
            largest = max(largest, float(np.max(np.hypot(u[:, 0], u[:, 1]))))
    if largest <= 0 or extent <= 0 or not np.isfinite(largest):
        return 0.0
    raw = fraction * extent / largest
    power = 10.0 ** np.floor(np.log10(raw))
    return float(max(m for m in (1.0, 2.0, 5.0) if m * power <= raw * (1 + 1e-12)) * power)


def _step_down(w):
    """The next factor below w among 1, 2, 5 times a power of ten."""
    import numpy as np
    power = 10.0 ** np.floor(np.log10(w) + 1e-9)
    mantissa = w / power
    return float((2.0 if mantissa > 4.5 else 1.0 if mantissa > 1.5 else 0.5) * power)


def analytic_gaps(job):
    """{pair name: (constant, r0, x0)}: the part of each pair's initial gap that the job gives as data and the
    meshes do not draw (docs/job-format.md, "Contacts": gap.constant, below zero an interference, and
    gap.parabola r0 (x - x0)^2); pairs named as the job parser names them ("<slave>-<master>" without a name)."""
    out = {}
    for c in (job or {}).get("contacts", []) or []:
        if isinstance(c, dict):
            gap = c.get("gap") if isinstance(c.get("gap"), dict) else {}
            parabola = gap.get("parabola") if isinstance(gap.get("parabola"), dict) else {}
            out[c.get("name") or f"{c.get('slave')}-{c.get('master')}"] = (
                float(gap.get("constant") or 0.0), float(parabola.get("r0") or 0.0), float(parabola.get("x0") or 0.0))
    return out


def _closed_contacts(step, analytic):
    """Over the nodes in contact (active, pressure > 0) of every pair of the step: (the drawn initial gap d_geom =
    gap - the job's analytic part, the normal displacement jump u_1n + u_2n = gap - normal_gap,
    max(normal_gap, 0)), as rows of a (3, n) array."""
    import numpy as np
    parts = []
    for pair in step["pair_names"]:
        c = step["contacts"].get(pair, {})
        if "gap" not in c or "normal_gap" not in c or ("active" not in c and "pressure" not in c):
            continue
        d, g = np.asarray(c["gap"], float), np.asarray(c["normal_gap"], float)
        on = np.asarray(c["active"]) == 1 if "active" in c else np.nan_to_num(np.asarray(c["pressure"], float)) > 0
        on &= np.isfinite(d) & np.isfinite(g)
        constant, r0, x0 = analytic.get(pair, (0.0, 0.0, 0.0))
        d_geom = d[on] - constant
        if r0 and "position" in c:
            d_geom = d_geom - r0 * (np.asarray(c["position"], float)[on, 0] - x0) ** 2
        parts.append(np.stack([d_geom, d[on] - g[on], np.maximum(g[on], 0.0)]))
    return np.concatenate(parts, axis=1) if parts else np.zeros((3, 0))


def false_gap(closed, warp):
    """The largest gap that drawing the displacement times `warp` shows in a closed contact beyond the true one:
    a slave node in contact is drawn at the normal distance d_geom - warp (u_1n + u_2n) from the master, where it
    truly is at max(normal_gap, 0) (closed: _closed_contacts). 0 without contact; negative where every node is
    drawn overlapping."""
    import numpy as np
    d_geom, jump, true = closed
    return float(np.max(d_geom - warp * jump - true)) if closed.shape[1] else 0.0


def choose_warp(step, analytic=None, pixels=1000, fraction=0.04):
    """The automatic magnification of the displacement and what the figure says of it: (warp, note).

    The rule: auto_warp's factor (the largest displacement `fraction` of the meshes' extent), unless a closed
    contact would then be drawn open: a node in contact is drawn at the normal distance d_geom - warp (u_1n +
    u_2n) from its master, d_geom the gap the meshes draw (the file's gap less the job's constant and parabola,
    analytic_gaps). A shrink fit given as gap.constant = -delta has d_geom = 0 and u_1n + u_2n = -delta: magnified
    100 times it shows a gap of 100 delta that is not there. So the factor is lowered through 1, 2, 5 times powers
    of ten, down to 1 (the true displacement) and at last 0 (undeformed, the meshes as the job draws them), to the
    first that draws no closed contact open by more than GAP_PIXELS pixels at the scale of a mesh panel `pixels`
    wide (the false gap times pixels / extent; a real panel is narrower, so the gap drawn is smaller still).
    Overlaps are not limited: a curved contact (Hertz) magnified draws the bodies overlapping, as does a gap
    given by a parabola; the zoom panel shows them with the true displacement. The note is "" when auto_warp's
    factor stands, else says why it was lowered."""
    import numpy as np
    warp = auto_warp(step, fraction)
    if warp == 0:
        return 0.0, ""
    extent = _extent(step)
    closed = _closed_contacts(step, analytic or {})
    candidates, w = [warp], warp
    while w > 1.0 + 1e-12:
        w = max(_step_down(w), 1.0)
        candidates.append(w)
    for w in candidates + ([1.0] if warp < 1.0 else []) + [0.0]:
        if false_gap(closed, w) * pixels / extent <= GAP_PIXELS:
            break
    if w == warp:
        return warp, ""
    gap = false_gap(closed, warp)
    return w, (f"x {warp:g} would draw a closed contact {gap * pixels / extent:.0f} px open" if np.isfinite(gap)
               else "")


def _extent(step):
    """The larger side of the box around every body's nodes (0 without nodes)."""
    import numpy as np
    extent = 0.0
    for b in step["bodies"].values():
        xy = b.get("points")
        if xy is not None and len(xy):
            extent = max(extent, float(np.max(xy.max(axis=0) - xy.min(axis=0))))
    return extent


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
    """{pair: (its displaced slave nodes (k, 2), its contact group)} per pair of the step (those read)."""
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


def _zoom_box(edges, ranges, alongs, whole):
    """The square of the mesh around the plotted stretch of each slave edge: centred on the slave nodes whose
    coordinate (alongs: {pair: its coordinate}) is within their pair's pressure range (ranges: {pair: (lo, hi)}),
    ZOOM_MARGIN wider than them on each side. None without such nodes, or when it would not magnify the whole
    mesh's box `whole` at least 3 times."""
    import numpy as np
    inside = []
    for pair, (lo, hi) in ranges.items():
        if pair in edges:
            xy, c = edges[pair]
            s = edge_coordinate(c, alongs[pair])
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
    with _edge_opacity, each pair's slave edge in red, and the bodies' names when `labels`. Returns the pixels per
    length unit."""
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
    return scale


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


def warp_text(warp, note=""):
    """What the figure says of the magnification: "displacement x 50", "true displacement (x 1)" or
    "undeformed", with the reason when the automatic factor was lowered."""
    text = (f"displacement x {warp:g}" if warp != 1 else "true displacement (x 1)") if warp else "undeformed"
    return text + (f"; lowered: {note}" if note else "")


def _mesh_title(meshes, warp, note=""):
    return ("final mesh" + (f", deformed ({warp_text(warp, note)})" if warp else f", {warp_text(warp, note)}") + ": "
            + ", ".join(f"{m['name']} {len(m['verts'])} cells"
                        + (f", refinement level <= {m['level']}" if m["level"] else "") for m in meshes))


def mesh_row(fig, spec, final, warp, ranges, alongs, note=""):
    """The bottom row in the gridspec cell `spec`: the whole final mesh displaced by warp and, when the pressure
    panels are zoomed (ranges: {pair: their (lo, hi)}), a zoom on the stretch of the slave edges they show
    (_zoom_box), marked by a dashed box on the whole mesh; one colour bar. The zoom shows the true displacement
    (the undeformed mesh with warp=0): magnified, an exaggerated one would show the bodies overlapping by (warp - 1)
    times their initial gap where they touch. Returns (the zoom's box or None, the whole mesh's pixels per length
    unit)."""
    import matplotlib.cm
    from matplotlib.patches import Rectangle
    meshes, edges = _meshes(final, warp), _slave_edges(final, warp)
    whole = _whole_box(meshes)
    marked = _zoom_box(edges, ranges, alongs, whole)
    true_warp = 1.0 if warp else 0.0
    true_edges = _slave_edges(final, true_warp) if marked else {}
    zoom = _zoom_box(true_edges, ranges, alongs, whole) if marked else None
    ratios = [1.0, 1.0, 0.05] if zoom else [1.0, 0.03]
    row = spec.subgridspec(1, len(ratios), width_ratios=ratios, wspace=0.2 if zoom else 0.04)
    norm = _stress_norm(meshes)
    ax = fig.add_subplot(row[0, 0])
    scale = _draw_mesh(fig, ax, meshes, edges, whole, norm, labels=True)
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
    fig.text(0.5, spec.get_position(fig).y1 + 0.03, _mesh_title(meshes, warp, note), ha="center", va="bottom",
             fontsize=10, gid="magnification")
    return zoom, scale


