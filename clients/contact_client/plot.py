"""The figure of a result: contact pressure along each pair drawn, zoomed on the contact zone (for a friction pair
the tangential traction, the slip and the stick zones below it); the load path of a stepped job; the final mesh
coloured by von Mises stress, whole and around the contact, or for many bodies an overview of all bodies and the
state of every joint.

The parts live in plot_profiles (the profiles as numbers), plot_pairs (a pair's panels), plot_paths (the load
curves), plot_mesh (the mesh row and the magnification), plot_wall (the overview) and plot_select (the pairs
chosen and what is read of the file)."""
import os

from .errors import BadInput
from .plot_mesh import GAP_PIXELS, _edge_opacity, analytic_gaps, auto_warp, choose_warp, mesh_row, warp_text
from .plot_pairs import draw_pair
from .plot_paths import draw_load_curve, draw_load_history, load_curve, load_path
from .plot_profiles import (AXIS_LABELS, COORDINATES, contact_pressure, fit_circle, friction_text,
                            iteration_profiles, resolve_along, slip, stick_zones, tangential_traction)
from .plot_select import MAX_PAIRS, OVERVIEW_BODIES, choose_pairs, final_forces, governing, read_for_plot
from .plot_wall import draw_overview
from .results import pair_friction, read_events

# The names other modules and the tests use from here (the parts' own names are in their modules).
__all__ = ["plot_result", "load_curve", "load_path", "auto_warp", "choose_warp", "warp_text", "GAP_PIXELS",
           "AXIS_LABELS", "COORDINATES", "MAX_PAIRS", "OVERVIEW_BODIES", "contact_pressure", "tangential_traction",
           "slip", "stick_zones", "fit_circle", "_edge_opacity"]

# The figure: 10 x 8 inches at 100 dpi, 12 x 9 with the overview of many bodies.
SIZE = (10, 8)
OVERVIEW_SIZE = (12, 9)
DPI = 100


def _select(result, pairs, max_pairs, overview):
    """choose_pairs() for a result already read (read_result()): the pairs' bodies from their attributes."""
    steps = result["steps"]
    if not steps:
        return {"drawn": [], "matched": [], "note": "", "overview": False}
    final = steps[-1]
    names = final["pair_names"]
    bodies_of = {n: (final["contacts"].get(n, {}).get("attrs", {}).get("slave_body"),
                     final["contacts"].get(n, {}).get("attrs", {}).get("master_body")) for n in names}
    forces = final_forces(result.get("history", {}).get("steps", {}), names)
    governs = {n: governing(final["contacts"].get(n, {}).get("attrs", {})) for n in names}
    drawn, matched, note = choose_pairs(names, pairs, max_pairs, forces, bodies_of, governs)
    many = len(final["body_names"]) > OVERVIEW_BODIES if overview is None else bool(overview)
    return {"drawn": drawn, "matched": matched, "note": note, "overview": many}


def _draw_pairs(fig, gs, steps, pairs, frictions, alongs, xlim, max_curves, loaded, profiles, numbered):
    """The pairs' panels in the top row of gs (plot_pairs.draw_pair), numbered when `numbered` (the overview marks
    them so). Returns (the parts of plot_result's answer they give, {pair: its zoomed range})."""
    out = {"pressure_xlim": {}, "contact_zone": {}, "stick_zones": {}, "stick_zones_per_step": {}}
    zoomed, npairs = {}, max(1, len(pairs))
    for j, pair in enumerate(pairs or [None]):
        if pair is None:
            ax = fig.add_subplot(gs[0, j])
            ax.text(0.5, 0.5, "no contact pair", ha="center", va="center", transform=ax.transAxes)
            continue
        panel = draw_pair(fig, gs[0, j], steps, pair, frictions.get(pair), alongs[pair], xlim, max_curves, loaded,
                          profiles.get(pair, []), title=f"{j + 1}: {pair}" if numbered else pair,
                          compact=npairs >= 3, legend=True if npairs < 3 else "small" if j == 0 else False)
        out["contact_zone"][pair], out["pressure_xlim"][pair] = panel["zone"], panel["xlim"]
        if panel["zoomed"] is not None:
            zoomed[pair] = panel["zoomed"]
        if pair in frictions:
            out["stick_zones"][pair], out["stick_zones_per_step"][pair] = panel["stick_zones"], panel["stick_steps"]
    return out, zoomed


def _title(result, steps):
    attrs = result["attrs"]
    name = attrs.get("name") or os.path.basename(result.get("path", ""))
    iterations = attrs.get("iterations", "?")
    return (f"{name}: {iterations} iteration{'' if iterations == 1 else 's'}, {attrs.get('stop_reason', '')}, "
            f"{len(steps)} step{'s' if len(steps) != 1 else ''}")


def _overview_row(fig, spec, final, warp, note, highlight):
    """The bottom row with the overview (plot_wall.draw_overview) and its colour bar; the magnification stated in
    its title."""
    row = spec.subgridspec(1, 2, width_ratios=[1.0, 0.015], wspace=0.02)
    return draw_overview(fig, fig.add_subplot(row[0, 0]), fig.add_subplot(row[0, 1]), final, warp, highlight,
                         warp_label=("deformed: " if warp else "") + warp_text(warp, note))


def plot_result(result, png, events=None, warp=None, title=None, max_curves=12, xlim=None, along="auto", pairs=None,
                max_pairs=MAX_PAIRS, overview=None):
    """Draws one figure into png, 1000 x 800 pixels (10 x 8 inches at 100 dpi), 1200 x 900 with the overview:

    top: the contact pressure along each pair drawn (one panel per pair): the pairs that `pairs` selects
         (fnmatch patterns, a list or one string with commas, on the pair's name or its slave or master body's
         name: "b0_*", "*base*"; BadInput naming the pairs when none matches), or every pair; beyond max_pairs (4)
         of them the max_pairs that govern (plot_select.governing: slipping or hinging joints first), and a line on the
         figure says so (with
         hundreds of pairs, one panel each would be illegible and take minutes). Against `along`: "arc" (the arc
         length along the slave edge from its first node, as the web page and the events), "x", "angle" (degrees
         about the centre of the circle fitted through the slave nodes: plot_profiles.resolve_along; the arc length
         for an edge that is not circular), or "auto" (the default): the angle for a circular slave edge whose
         nodes in contact turn through more than 30 degrees (a ring, a shrink fit), else the arc length. One
         curve per adaptive or load step (at most max_curves, spread over the run); with a single step, the
         pressure profile of each iteration when `events` (the job's events, a list of dicts or a path to saved
         events) are given, and the final profile from the file (slave nodes that take no part in the contact
         are left out). The horizontal range: xlim=None, the contact zone (the nodes with pressure > 0 on any
         curve drawn of the pair) plus ZOOM_MARGIN (15 %) of its width on each side and at least ZOOM_NODES (3)
         nodes beyond each end, within the slave edge (the whole edge without contact); xlim=(lo, hi) for every
         pair's panel; xlim="full": the whole slave edge.
         A friction pair's panel is split: the pressure above; below it on the same horizontal axis the
         tangential traction (its curves as the pressure's, the final one from the file in black, the final
         friction bound +-mu p or +-g dotted, the legend naming the law, its coefficient or bound and the
         tangential force), the final stick zones (stick_zones()) shaded green in both; the slip (accumulated
         over the steps) of each step; and with several steps a strip with the stick zone of each step as bars.
         For a result with several steps one more panel, the load path: for increasing load factors the load
         curve (load_curve(): force and contact width of each pair drawn against the load factor), else the
         load history against the step (load_path(): the supports' force, the applied load balanced, and the
         pairs' normal and tangential forces; a job driven by its conditions' `history` has load factor 1 in
         every step);
    bottom: with at most OVERVIEW_BODIES (8) bodies (or overview=False), each body's final mesh, deformed, cells
         coloured by von Mises stress, cell edges drawn where the cells are large enough on screen to show them,
         the slave edge of each pair in red; next to it, when the pressure panels are zoomed, the mesh around the
         part of the slave edges they show (true displacement); one colour bar. With more bodies (or
         overview=True) the overview instead (plot_wall.draw_overview): all bodies, cells by von Mises stress,
         every pair's slave edge coloured by each node's state (open, stick, slip, in contact), the pairs drawn
         above outlined and numbered. Displaced by warp x displacement: warp=None chooses it (choose_warp: the
         largest displacement 4 % of the mesh, lowered to a factor that draws no closed contact open by more than
         GAP_PIXELS (1 px): a shrink fit magnified would show a gap that is not there); 0 draws the undeformed
         mesh. The magnification is stated on the figure.

    result is a path (only what is drawn is read: plot_select.read_for_plot) or the dict of read_result().
    Returns {"warp": the mesh's scale, "warp_note": why the automatic one was lowered ("" if not), "pairs": the
    pairs drawn, "pairs_matched": the pairs selected, "pairs_note": the figure's line on the choice ("" when all
    are drawn), "along": {pair: its coordinate}, "pressure_xlim": {pair: (lo, hi) of its panel's horizontal axis,
    as drawn}, "contact_zone": {pair: (lo, hi) of its nodes in contact, or None}, "mesh_zoom": (x0, x1, y0, y1)
    of the zoom panel or None, "mesh_pixels_per_unit": the scale of the whole mesh or overview panel, "overview":
    None or {"nodes": {state: slave nodes drawn in it}, "pairs", "bodies"}, "load_path": load_curve()'s or
    load_path()'s dict or None, "friction": {friction pair: its law, as "Coulomb, mu = 0.2"},
    "tangential_force": {friction pair: its final total tangential force}, "stick_zones": {friction pair: [(lo,
    hi), ...] shaded}, "stick_zones_per_step": {friction pair: [(step, [(lo, hi), ...]), ...]}, "size": (width,
    height) in pixels, "figure": the matplotlib Figure drawn (closed)}."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    along = along or "auto"
    if along not in COORDINATES:
        raise BadInput(f"along must be one of {', '.join(COORDINATES)}, not {along!r}")
    if isinstance(result, dict):
        chosen = _select(result, pairs, max_pairs, overview)
    else:
        result, chosen = read_for_plot(result, pairs, max_pairs, max_curves, overview)
    if isinstance(events, (str, os.PathLike)):
        events = read_events(events)
    steps = result["steps"]
    if not steps:
        raise BadInput(f"{result.get('path', 'the result')}: no step in the file (the solve failed before its "
                       "first iteration)")
    final, drawn_pairs, many = steps[-1], chosen["drawn"], chosen["overview"]
    size = OVERVIEW_SIZE if many else SIZE
    note = ""
    if warp is None:
        warp, note = choose_warp(final, analytic_gaps(result.get("job")), pixels=size[0] * DPI)
    frictions = {pair: pair_friction(final["contacts"][pair]) for pair in drawn_pairs}
    frictions = {pair: f for pair, f in frictions.items() if f is not None}  # the friction pairs
    alongs = {pair: resolve_along(final["contacts"][pair], along) for pair in drawn_pairs}
    curve = load_curve(result, drawn_pairs)
    path = load_path(result, drawn_pairs) if curve is None else None

    fig = plt.figure(figsize=size, dpi=DPI)
    npairs = max(1, len(drawn_pairs))
    # A friction pair's pressure, tangential traction and slip share the top row's height: the row gets more.
    gs = fig.add_gridspec(2, npairs + (curve is not None or path is not None),
                          height_ratios=[2.0, 1.0] if frictions else [1.0, 1.25],
                          left=0.08, right=0.92, top=0.9 if chosen["note"] else 0.92, bottom=0.1 if many else 0.07,
                          hspace=0.4,
                          wspace=0.4)
    fig.suptitle(title or _title(result, steps), fontsize=12)
    if chosen["note"]:
        fig.text(0.5, 0.935, chosen["note"], ha="center", va="bottom", fontsize=9, gid="pairs_note")
    profiles = iteration_profiles(events) if len(steps) == 1 else {}
    out, zoomed = _draw_pairs(fig, gs, steps, drawn_pairs, frictions, alongs, xlim, max_curves, curve is not None,
                              profiles, many)
    if curve is not None:
        draw_load_curve(fig.add_subplot(gs[0, npairs]), curve)
    elif path is not None:
        draw_load_history(fig.add_subplot(gs[0, npairs]), path)
    if many:
        wall = _overview_row(fig, gs[1, :], final, warp, note, drawn_pairs)
        zoom, scale = None, wall.pop("pixels_per_unit")
    else:
        wall = None
        zoom, scale = mesh_row(fig, gs[1, :], final, warp, zoomed, alongs, note)
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=DPI)
    plt.close(fig)
    out.update({"warp": warp, "warp_note": note, "pairs": drawn_pairs, "pairs_matched": chosen["matched"],
                "pairs_note": chosen["note"], "along": alongs, "mesh_zoom": zoom, "mesh_pixels_per_unit": scale,
                "overview": wall, "load_path": curve if curve is not None else path,
                "friction": {pair: friction_text(f) for pair, f in frictions.items()},
                "tangential_force": {pair: f["tangential_force"] for pair, f in frictions.items()},
                "size": (size[0] * DPI, size[1] * DPI), "figure": fig})
    return out
