"""The collapse view of a result (a job with "collapse"; docs/limit-analysis.md): the capacity curve, the load
multiplier of every state that held against a displacement of the user's choice (by default the node that moved
most at the last state that held, along its own final displacement), and the mechanism drawn over the structure:
every body's mesh, the bodies that move tinted with an arrow of their velocity, the joints that hinge marked at
their point, the joints that slide or open drawn over their slave edges, and each joint's centre of pressure at the
last state that held (joined into the thrust line where the joints form a chain: an arch, a column). The verdict
is the figure's title."""
from .errors import BadInput
from .plot_mesh import _bounds, _fit
from .results import ResultFile

KIND_COLOURS = {"hinge": "tab:red", "slides": "tab:purple", "opens": "tab:orange", "opens and slides": "tab:brown"}


def _control(f, last, body=None, point=None):
    """The control point: (body, node, direction) of the node nearest `point` on `body` (both given), or of the node
    that moved most at step group `last`; the direction is that node's final displacement (unit)."""
    import numpy as np
    step = f.step(last)
    best = None
    for name in ([body] if body else step["body_names"]):
        if name not in step["body_names"]:
            raise BadInput(f"--body {name}: the result has no body '{name}' (its bodies: "
                           + ", ".join(step["body_names"][:10]) + ")")
        b = f.body(last, name, ("points", "displacement"))
        u = np.asarray(b["displacement"])
        if point is not None:
            node = int(np.argmin(np.linalg.norm(np.asarray(b["points"]) - np.asarray(point), axis=1)))
            best = (name, node, np.linalg.norm(u[node]))
        else:
            node = int(np.argmax(np.linalg.norm(u, axis=1)))
            if best is None or np.linalg.norm(u[node]) > best[2]:
                best = (name, node, np.linalg.norm(u[node]))
    name, node, size = best
    u = np.asarray(f.body(last, name, ("displacement",))["displacement"])[node]
    direction = u / size if size > 0 else np.array([1.0, 0.0])
    return name, node, direction


def capacity_curve(f, body=None, point=None):
    """The capacity curve from the kept steps: {"multiplier": [...], "displacement": [...], "body", "node",
    "direction"}, one point per step group that holds a collapse trial (multiplier > 0) plus the loading's end."""
    import numpy as np
    if f.count == 0:
        raise BadInput(f"{f.path}: no step kept: no capacity curve to draw")
    name, node, direction = _control(f, f.count - 1, body, point)
    lam, disp = [], []
    for k in range(f.count):
        g = f._group(k)
        lam.append(float(g.attrs.get("multiplier", 0.0)))
        u = np.asarray(f.body(k, name, ("displacement",))["displacement"])[node]
        disp.append(float(np.dot(u, direction)))
    return {"multiplier": lam, "displacement": disp, "body": name, "node": node, "direction": direction.tolist()}


def thrust_line(f, k, step):
    """Each pair's centre of pressure at step group k (the point along its slave edge where its normal force acts),
    in the order of the pairs: {"points": [(x, y), ...], "pairs": [...], "chain": whether each pair shares a body
    with the next (an arch, a column: the points then join into the thrust line)}."""
    import numpy as np
    points, pairs, bodies = [], [], []
    for name in step["pair_names"]:
        c = f.pair(k, name, ("position", "arc_length"))
        s = c.get("attrs", {}).get("centre_of_pressure")
        force = c.get("attrs", {}).get("force", 0.0)
        if s is None or not force or not np.isfinite(s) or "arc_length" not in c or not len(c["arc_length"]):
            continue
        arc, xy = np.asarray(c["arc_length"], dtype=float), np.asarray(c["position"], dtype=float)
        points.append((float(np.interp(s, arc, xy[:, 0])), float(np.interp(s, arc, xy[:, 1]))))
        pairs.append(name)
        attrs = c["attrs"]
        bodies.append({attrs.get("slave_body"), attrs.get("master_body")})
    chain = len(points) > 2 and all(a & b for a, b in zip(bodies, bodies[1:]))
    return {"points": points, "pairs": pairs, "chain": chain}


def draw_mechanism(fig, ax, f, collapse):
    """Every body's undeformed mesh in light grey, the bodies that move tinted with their velocity as an arrow at
    their reference point, hinges as red dots, sliding and opening joints over their slave edges."""
    import numpy as np
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.lines import Line2D
    last = f.count - 1
    step = f.step(last)
    m = collapse.get("mechanism", {})
    moving = set(m.get("body_names", []))
    verts, tint, points = [], [], []
    for name in step["body_names"]:
        b = f.body(last, name, ("points", "cells", "quads"))
        cells = b.get("cells", b.get("quads"))
        if cells is None:
            continue
        cells = np.where(cells >= 0, cells, cells[:, :1])
        v = np.asarray(b["points"])[cells]
        verts.append(v)
        tint += [name in moving] * len(v)
        points.append(np.asarray(b["points"]))
    allpts = np.concatenate(points) if points else np.zeros((1, 2))
    box, _ = _fit(fig, ax, _bounds(allpts, pad=0.04))
    ax.set_xlim(box[0], box[1])
    ax.set_ylim(box[2], box[3])
    ax.set_aspect("equal")
    if verts:
        v = np.concatenate(verts)
        faces = np.where(np.asarray(tint)[:, None], [[1.0, 0.85, 0.6, 1.0]], [[0.92, 0.92, 0.92, 1.0]])
        ax.add_collection(PolyCollection(v, facecolors=faces, edgecolors=(0.6, 0.6, 0.6, 0.5), linewidths=0.3))
    size = float(max(allpts.max(axis=0) - allpts.min(axis=0)))
    refs = np.asarray(m.get("body_reference", np.zeros((0, 2))), dtype=float).reshape(-1, 2)
    vel = np.asarray(m.get("body_velocity", np.zeros((0, 2))), dtype=float).reshape(-1, 2)
    if len(refs):
        ax.quiver(refs[:, 0], refs[:, 1], vel[:, 0], vel[:, 1], angles="xy", scale_units="xy",
                  scale=1.0 / (0.12 * size), color="tab:blue", width=0.004, zorder=5)
    handles = [Line2D([], [], color="tab:blue", lw=2, label="a moving body's velocity")]
    kinds = list(m.get("joint_kind", []))
    pts = np.asarray(m.get("joint_point", np.zeros((0, 2))), dtype=float).reshape(-1, 2)
    edges = {kind: [] for kind in KIND_COLOURS}
    for pair, kind, p in zip(m.get("pair_names", []), kinds, pts):
        if kind == "hinge":
            ax.plot([p[0]], [p[1]], "o", color=KIND_COLOURS[kind], ms=7, zorder=6)
            continue
        c = f.pair(last, pair, ("position",)) if pair in step["pair_names"] else None
        if c is not None and "position" in c:
            edges.setdefault(kind, []).append(np.asarray(c["position"], dtype=float))
    for kind, lines in edges.items():
        if lines:
            ax.add_collection(LineCollection(lines, colors=KIND_COLOURS.get(kind, "black"), linewidths=3, zorder=4))
    for kind in KIND_COLOURS:
        n = kinds.count(kind)
        if n:
            marker = "o" if kind == "hinge" else None
            handles.append(Line2D([], [], color=KIND_COLOURS[kind], lw=0 if marker else 3, marker=marker,
                                  label=f"{kind} ({n} joint{'s' if n > 1 else ''})"))
    line = thrust_line(f, last, step)
    if line["points"]:
        pts = np.asarray(line["points"])
        if line["chain"]:
            ax.plot(pts[:, 0], pts[:, 1], "-", color="black", lw=1.2, zorder=5)
        ax.plot(pts[:, 0], pts[:, 1], "o", color="black", ms=3, zorder=6)
        handles.append(Line2D([], [], color="black", marker="o", ms=3, lw=1.2 if line["chain"] else 0,
                              label="centres of pressure at the last state that held"
                                    + (" (the thrust line)" if line["chain"] else "")))
    ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.05), ncol=len(handles))
    whose = ("the elastic solution's motion into the last state that held" if m.get("source") == "elastic"
             else "the rigid blocks' statics' motion at its bound")
    ax.set_title(f"mechanism ({m.get('kind') or 'none found'}): {whose}", fontsize=10)


def plot_collapse(path, png, body=None, point=None, title=None):
    """Draws the collapse view of result file `path` to `png`; returns what it drew: {"verdict", "held",
    "failed", "statics_bound", "kind", "words", "curve": capacity_curve(...)}."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    with ResultFile(path) as f:
        collapse = f.collapse()
        if collapse is None:
            raise BadInput(f"{path}: no collapse analysis in this result (a job with \"collapse\", "
                           "docs/job-format.md)")
        curve = capacity_curve(f, body, point)
        fig = plt.figure(figsize=(13, 6.5))
        ax_curve = fig.add_axes([0.06, 0.14, 0.3, 0.72])
        ax_mech = fig.add_axes([0.42, 0.14, 0.56, 0.72])
        ax_curve.plot(curve["displacement"], curve["multiplier"], "o-", color="tab:blue", ms=4)
        held, failed = float(collapse.get("held", 0.0)), collapse.get("failed")
        ax_curve.axhline(held, color="tab:green", lw=1, ls="--", label=f"held {held:.4g}")
        if failed is not None and failed == failed:
            ax_curve.axhline(float(failed), color="tab:red", lw=1, ls="--", label=f"did not hold {float(failed):.4g}")
        bound = collapse.get("statics_bound")
        if bound is not None and bound == bound and bound != float("inf"):
            ax_curve.axhline(float(bound), color="grey", lw=1, ls=":", label=f"statics bound {float(bound):.4g}")
        ax_curve.set_xlabel(f"displacement of '{curve['body']}' node {curve['node']} along "
                            f"({curve['direction'][0]:.2f}, {curve['direction'][1]:.2f})")
        ax_curve.set_ylabel("load multiplier of the live loads")
        ax_curve.set_title("capacity curve: the states that held", fontsize=10)
        ax_curve.grid(alpha=0.3)
        ax_curve.legend(fontsize=8, loc="lower right")
        draw_mechanism(fig, ax_mech, f, collapse)
        verdict = collapse.get("verdict", "")
        head = title or (f"{verdict}: lambda_c in [{held:.4g}, {float(failed):.4g}]"
                         if verdict == "collapse" else f"{verdict}: held up to {held:.4g}")
        fig.suptitle(head, fontsize=12)
        fig.savefig(png, dpi=100)
        plt.close(fig)
    return {"verdict": verdict, "held": held, "failed": failed, "statics_bound": bound,
            "kind": collapse.get("mechanism", {}).get("kind", ""), "words": collapse.get("words", ""),
            "curve": curve}
