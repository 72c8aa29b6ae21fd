"""The overview of a result with many bodies (a masonry wall of hundreds of bricks): every body of the final step
drawn deformed, its cells coloured by von Mises stress, and every pair's slave edge drawn over it, each node's
stretch coloured by the node's state: open, stick, slip (friction pairs), in contact (frictionless pairs). Drawn
with one PolyCollection for all the cells and one LineCollection for all the joints, so that a 22 x 22 wall (496
bodies, 946 pairs) takes well under a second to draw."""
from .plot_mesh import _bounds, _displaced, _edge_colours, _edge_opacity, _fit

# A slave node's state, in drawing order (the later over the earlier where two pairs share a slave edge: a node
# outside one pair's master is inside its neighbour's).
JOINT_STATES = ("outside", "open", "contact", "stick", "slip")
JOINT_COLOURS = {"outside": "silver", "open": "tab:orange", "contact": "black", "stick": "tab:green",
                 "slip": "tab:red"}
JOINT_LABELS = {"outside": "not opposite the master", "open": "open (no contact)",
                "contact": "in contact (frictionless)", "stick": "stick", "slip": "slip"}


def joint_states(c):
    """Each slave node's state, an index into JOINT_STATES: "outside" where the node takes no part in the
    contact (status 1 to 3), "open" where it does not touch (active 0), and where it touches "stick" or "slip" for
    a friction pair (`stick` 1 or 0) or "contact" for a frictionless one."""
    import numpy as np
    k = len(c["node"]) if "node" in c else len(c.get("position", []))
    active = np.asarray(c["active"]) == 1 if "active" in c else np.nan_to_num(c.get("pressure", np.zeros(k))) > 0
    state = np.where(active, JOINT_STATES.index("contact"), JOINT_STATES.index("open"))
    friction = c.get("attrs", {}).get("friction", "none") not in ("none", "", None)
    if friction and "stick" in c and len(c["stick"]) == k:
        stick = np.asarray(c["stick"]) == 1
        state = np.where(active, np.where(stick, JOINT_STATES.index("stick"), JOINT_STATES.index("slip")), state)
    if "status" in c and len(c["status"]) == k:
        state = np.where(np.isin(np.asarray(c["status"]), (1, 2, 3)), JOINT_STATES.index("outside"), state)
    return state.astype(int)


def node_pieces(xy):
    """Each node's stretch of the polyline xy (k, 2): from halfway to the previous node through the node to
    halfway to the next (the node itself at an end): (k, 3, 2)."""
    import numpy as np
    mid = (xy[:-1] + xy[1:]) / 2
    before = np.concatenate([xy[:1], mid])
    after = np.concatenate([mid, xy[-1:]])
    return np.stack([before, xy, after], axis=1)


def _joints(step, warp):
    """Every pair's node pieces, displaced with their slave body: (pieces (N, 3, 2), states (N,), pair index per
    piece (N,)), in the order of the step's pair_names."""
    import numpy as np
    pieces, states, owner = [], [], []
    for i, pair in enumerate(step["pair_names"]):
        c = step["contacts"].get(pair)
        if c is None or "node" not in c or not len(c["node"]):
            continue
        body = step["bodies"].get(c.get("attrs", {}).get("slave_body"))
        xy = _displaced(body, warp, np.asarray(c["node"])) if body is not None and "points" in body \
            else np.asarray(c["position"], dtype=float)
        pieces.append(node_pieces(xy))
        states.append(joint_states(c))
        owner.append(np.full(len(xy), i))
    if not pieces:
        return np.zeros((0, 3, 2)), np.zeros(0, int), np.zeros(0, int)
    return np.concatenate(pieces), np.concatenate(states), np.concatenate(owner)


def _cells(step, warp):
    """All bodies' displaced cells (m, 4, 2) (a triangle repeats its first corner) and von Mises stress (m,)."""
    import numpy as np
    verts, values = [], []
    for name in step["body_names"]:
        b = step["bodies"].get(name, {})
        cells = b.get("cells", b.get("quads"))
        if cells is None or "points" not in b:
            continue
        cells = np.where(cells >= 0, cells, cells[:, :1])
        verts.append(_displaced(b, warp)[cells])
        vm = b.get("von_mises")
        values.append(vm if vm is not None and len(vm) == len(cells) else np.full(len(cells), np.nan))
    if not verts:
        return np.zeros((0, 4, 2)), np.zeros(0)
    return np.concatenate(verts), np.concatenate(values)


def stress_colours():
    """The bodies' colour map: light to dark blue (matplotlib's Blues without its near-white end), so that the
    joints' green, red, orange and black stand out on every body."""
    import matplotlib.colors
    import matplotlib.pyplot as plt
    import numpy as np
    return matplotlib.colors.ListedColormap(plt.get_cmap("Blues")(np.linspace(0.15, 0.95, 256)), name="stress")


def draw_overview(fig, ax, cax, step, warp, highlight=(), warp_label=""):
    """The overview in ax (colour bar in cax): every body of `step` displaced by warp x displacement, its cells
    coloured by von Mises stress (cell edges where the cells are large enough on screen, _edge_opacity), and every
    pair's slave edge coloured by each node's state (joint_states; node_pieces), the pairs in `highlight` (names,
    numbered 1, 2, ... as their panels) outlined in black and labelled with their number; a legend with the node
    count of each state. Returns {"nodes": {state: number of slave nodes drawn in it}, "pairs": pairs drawn,
    "bodies": bodies drawn, "pixels_per_unit": the scale}."""
    import matplotlib.cm
    import matplotlib.colors
    import numpy as np
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.lines import Line2D
    verts, values = _cells(step, warp)
    pieces, states, owner = _joints(step, warp)
    points = np.concatenate([verts.reshape(-1, 2), pieces.reshape(-1, 2)]) if len(verts) + len(pieces) else \
        np.zeros((1, 2))
    box, scale = _fit(fig, ax, _bounds(points, pad=0.02))
    ax.set_xlim(box[0], box[1])
    ax.set_ylim(box[2], box[3])
    ax.set_aspect("equal")
    finite = values[np.isfinite(values)]
    norm = matplotlib.colors.Normalize(*(finite.min(), finite.max()) if len(finite) else (0.0, 1.0))
    cmap = stress_colours()
    faces = cmap(norm(values))
    ax.add_collection(PolyCollection(verts, facecolors=faces, linewidths=0.3,
                                     edgecolors=_edge_colours(faces, _edge_opacity(verts, scale))), autolim=False)
    chosen = [step["pair_names"].index(p) for p in highlight if p in step["pair_names"]]
    outlined = np.isin(owner, chosen)
    if outlined.any():
        ax.add_collection(LineCollection(pieces[outlined], colors="black", linewidths=4.0, zorder=3,
                                         gid="highlight"), autolim=False)
    order = np.argsort(states, kind="stable")
    colours = [JOINT_COLOURS[JOINT_STATES[s]] for s in states[order]]
    widths = np.where(states[order] == JOINT_STATES.index("outside"), 0.6, 1.6)
    ax.add_collection(LineCollection(pieces[order], colors=colours, linewidths=widths, zorder=4, gid="joints"),
                      autolim=False)
    for number, index in enumerate(chosen, 1):  # at the middle node of the stretch opposite the master
        mine = (owner == index) & (states != JOINT_STATES.index("outside"))
        nodes = pieces[mine if mine.any() else owner == index][:, 1]
        middle = nodes[len(nodes) // 2]
        ax.text(middle[0], middle[1], str(number), fontsize=8, ha="center", va="bottom", zorder=6, clip_on=True,
                bbox=dict(boxstyle="round,pad=0.15", facecolor="white", alpha=0.85, edgecolor="black", lw=0.5))
    counts = {name: int(np.sum(states == i)) for i, name in enumerate(JOINT_STATES)}
    handles = [Line2D([], [], color=JOINT_COLOURS[s], lw=2.0, label=f"{JOINT_LABELS[s]} ({counts[s]} nodes)")
               for s in JOINT_STATES[::-1] if counts[s]]
    if outlined.any():
        handles.append(Line2D([], [], color="black", lw=4.0, label="pairs drawn above (numbered)"))
    if handles:  # below the panel: a wall fills its width
        ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.06), ncol=len(handles),
                  framealpha=0.85, title="joints: the slave nodes by state", title_fontsize=7)
    fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), cax=cax).set_label("von Mises stress")
    bodies, pairs = len(step["body_names"]), len(set(owner.tolist()))
    ax.set_title(f"{bodies} bodies, cells by von Mises stress; the slave edges of {pairs} pairs by state at the "
                 f"final step\n{warp_label}", fontsize=10)
    return {"nodes": counts, "pairs": pairs, "bodies": bodies, "pixels_per_unit": scale}
