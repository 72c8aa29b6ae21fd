"""The profiles along a pair's slave edge that the plot draws, as numbers: the values per slave node (pressure,
tangential traction, slip), their coordinate along the edge (arc length, x, or the angle about the edge's centre
of curvature), the contact and stick zones, the panels' ranges, and the curves per step or per iteration."""

# The pressure panels' horizontal coordinate: "arc", the arc length along the slave edge from its first node (the
# coordinate of the events' profiles, of the web page, of contact_begin/contact_end; it also serves edges that are
# not horizontal), "x", or "angle", the angle in degrees about the centre of the circle fitted through the slave
# nodes (a ring, a shaft, a roller); "auto" picks "angle" for a circular slave edge in a conforming contact that
# wraps around it (resolve_along) and "arc" otherwise.
COORDINATES = ("auto", "arc", "x", "angle")
AXIS_LABELS = {"arc": "arc length along the slave edge", "x": "x of the slave edge node",  # the web page's: "arc"
               "angle": "angle about the slave edge's centre (degrees)"}
SHORT_AXIS_LABELS = {"arc": "arc length", "x": "x", "angle": "angle (degrees)"}  # under narrow panels
# A slave edge is circular when its nodes lie on the circle fitted through them to CIRCLE_TOLERANCE of its radius
# (root mean square); "auto" plots against the angle when the nodes in contact also turn through more than
# ANGLE_TURN degrees about its centre and the contact conforms: their initial gap varies by less than CONFORMING
# of the radius (a ring on a shaft, a pin in its hole). A cylinder pressed on a flat stays against the arc
# length: its gap grows as R (1 - cos theta), 3.4 % of R at 30 degrees of contact.
CIRCLE_TOLERANCE = 1e-3
ANGLE_TURN = 30.0
CONFORMING = 0.01
# By default a pressure panel shows the contact zone plus ZOOM_MARGIN of its width on each side, and at least
# ZOOM_NODES slave nodes beyond each end (so that the opening of the contact shows on a coarse mesh).
ZOOM_MARGIN = 0.15
ZOOM_NODES = 3


def _spread(n, k):
    """At most k indices of range(n), evenly spread, the first and the last included."""
    if n <= k:
        return list(range(n))
    return sorted({round(i * (n - 1) / (k - 1)) for i in range(k)})


def _node_values(c, key):
    """A pair's dataset `key` per slave node, NaN where the node takes no part in the pair's contact (status 1 to 3:
    not opposite the master, a crosspoint, barely covered; 5: carried by another pair of its group;
    docs/results-format.md), so curves break there."""
    import numpy as np
    v = np.asarray(c[key], dtype=float).copy()
    status = c.get("status")
    if status is not None and len(status) == len(v):
        v[np.isin(np.asarray(status), (1, 2, 3, 5))] = np.nan
    return v


def contact_pressure(c):
    """A pair's pressure per slave node, NaN where the node takes no part in the contact (_node_values)."""
    return _node_values(c, "pressure")


def tangential_traction(c):
    """A friction pair's tangential traction per slave node (along its tangent), NaN where the node takes no
    part in the contact; None for a frictionless pair or a file without it."""
    return _node_values(c, "tangential_traction") if "tangential_traction" in c else None


def slip(c):
    """A friction pair's slip per slave node (along its tangent, accumulated over the load steps), NaN where the
    node takes no part in the contact; None for a frictionless pair or a file without it."""
    return _node_values(c, "slip") if "slip" in c else None


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


def fit_circle(points):
    """The least-squares circle through points (n, 2) (the algebraic fit: x^2 + y^2 = 2 a x + 2 b y + c, about
    the points' mean for accuracy): (centre (2,), radius, root-mean-square distance of the points from it), or
    None for fewer than 3 points or points on a line."""
    import numpy as np
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    p = p[np.all(np.isfinite(p), axis=1)]
    if len(p) < 3:
        return None
    mean = p.mean(axis=0)
    q = p - mean
    a = np.column_stack([2 * q, np.ones(len(q))])
    solution, _, rank, _ = np.linalg.lstsq(a, (q ** 2).sum(axis=1), rcond=None)
    radius2 = solution[2] + solution[0] ** 2 + solution[1] ** 2
    if rank < 3 or not np.isfinite(radius2) or radius2 <= 0:
        return None
    centre, radius = mean + solution[:2], float(np.sqrt(radius2))
    residual = float(np.sqrt(np.mean((np.hypot(*(p - centre).T) - radius) ** 2)))
    return centre, radius, residual


def slave_circle(c):
    """The circle of a pair's slave edge (fit_circle of its nodes' positions) when the nodes lie on it to
    CIRCLE_TOLERANCE of its radius: (centre, radius); None for an edge that is not circular."""
    fit = fit_circle(c["position"]) if "position" in c else None
    if fit is None or fit[2] > CIRCLE_TOLERANCE * fit[1]:
        return None
    return fit[0], fit[1]


def edge_angle(points, centre):
    """The angle in degrees of each point about centre, continuous along the points' order (unwrapped), the first
    one in (-180, 180]."""
    import numpy as np
    p = np.asarray(points, dtype=float)
    return np.degrees(np.unwrap(np.arctan2(p[:, 1] - centre[1], p[:, 0] - centre[0])))


def edge_coordinate(c, along="arc"):
    """A pair's slave nodes' coordinate on the pressure axis: their arc length along the slave edge (along="arc"),
    their x (along="x"), or their angle in degrees about the centre of the slave edge's circle (along="angle";
    the arc length when the edge is not circular)."""
    if along == "angle":
        circle = slave_circle(c)
        if circle is not None:
            return edge_angle(c["position"], circle[0])
        along = "arc"
    return c["arc_length"] if along == "arc" and "arc_length" in c else c["x"]


def resolve_along(c, along):
    """The coordinate a pair is drawn against for the requested `along`: "arc" or "x" as asked; "angle" when its
    slave edge is circular (slave_circle), else "arc"; "auto": "angle" when the slave edge is circular, its nodes
    in contact (pressure > 0) turn through more than ANGLE_TURN degrees about its centre and their initial `gap`
    varies by less than CONFORMING of the radius (a conforming contact: a ring, a shrink fit, a closed loop),
    else "arc"."""
    import numpy as np
    if along in ("arc", "x"):
        return along
    circle = slave_circle(c)
    if circle is None:
        return "arc"
    if along == "angle":
        return "angle"
    on = np.nan_to_num(contact_pressure(c)) > 0
    if on.sum() < 2 or np.ptp(edge_angle(c["position"], circle[0])[on]) <= ANGLE_TURN:
        return "arc"
    gap = np.asarray(c.get("gap", np.zeros(len(on))), dtype=float)[on]
    conforming = len(gap) == on.sum() and np.isfinite(gap).all() and np.ptp(gap) < CONFORMING * circle[1]
    return "angle" if conforming else "arc"


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


def iteration_profiles(events):
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


def step_curves(steps, pair, along, max_curves, loaded, values=contact_pressure):
    """One curve per plotted step: [(step, coordinate, values(pair), label suffix), ...] (values: contact_pressure,
    tangential_traction or slip; a step whose pair has none is left out). The steps plotted are at most
    max_curves of them, spread over the run (the first and the last included)."""
    curves = []
    for k in _spread(len(steps), max_curves):
        c = steps[k]["contacts"].get(pair)
        v = values(c) if c is not None and "x" in c else None
        if v is not None:
            load = f"load {steps[k]['load_factor']:g}, " if loaded else ""
            curves.append((k, edge_coordinate(c, along), v,
                           f" ({load}iter {steps[k]['iteration']}, {len(c['x'])} nodes)"))
    return curves


def iteration_curves(profiles, c_final, along, max_curves, tangential=False):
    """One curve per plotted iteration of the events: [(iteration, coordinate, pressure, ""), ...], or with
    tangential=True the tangential traction (iterations without it left out). The events give arc lengths: with
    another coordinate they are mapped to it through the final step's slave nodes."""
    import numpy as np
    arc = c_final.get("arc_length")
    mapped = along != "arc" and arc is not None and "x" in c_final and len(arc) >= 2
    coordinate = edge_coordinate(c_final, along) if mapped else None
    curves = []
    for i in _spread(len(profiles), max_curves):
        it, s, p, t = profiles[i]
        v = t if tangential else p
        if v is not None:
            curves.append((it, np.interp(s, arc, coordinate) if mapped else s, v, ""))
    return curves


def step_stick_zones(steps, pair, along, max_curves):
    """The stick zones of a friction pair in each plotted step (as step_curves picks them): [(step, [(lo, hi),
    ...]), ...] along the coordinate `along` (stick_zones of the step's `stick`); steps without `stick` left out."""
    import numpy as np
    out = []
    for k in _spread(len(steps), max_curves):
        c = steps[k]["contacts"].get(pair)
        if c is not None and "stick" in c and "x" in c and len(c["stick"]) == len(c["x"]):
            out.append((k, stick_zones(edge_coordinate(c, along), np.asarray(c["stick"]) == 1)))
    return out
