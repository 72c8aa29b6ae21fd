"""One pair's panels in the plot: the contact pressure along the slave edge; for a friction pair below it, on the
same horizontal axis, the tangential traction (the final stick zone shaded), the slip, and with several steps the
stick zone of each step as bars."""
from .plot_profiles import (AXIS_LABELS, SHORT_AXIS_LABELS, contact_pressure, contact_zone, edge_coordinate, friction_text,
                            iteration_curves, pressure_range, slip, step_curves, step_stick_zones, stick_zones,
                            tangential_traction)

STICK_COLOUR = "tab:green"  # the stick zone's shading
BOUND_COLOUR = "grey"  # the friction bound (slip where the traction reaches it)


def _curve_colours(curves):
    """(colour map, norm) that colour the curves [(number, ...), ...] from the first number to the last."""
    import matplotlib.colors
    import matplotlib.pyplot as plt
    numbers = [n for n, *_ in curves] or [0]
    return plt.get_cmap("viridis"), matplotlib.colors.Normalize(vmin=numbers[0],
                                                                vmax=max(numbers[-1], numbers[0] + 1))


def _draw_curves(ax, curves, what=None, labelled=False):
    """The curves [(number, coordinate, values, label suffix), ...] coloured by their place in the run (labelled
    "{what} {number}{suffix}" when `labelled`)."""
    cmap, norm = _curve_colours(curves)
    for number, s, v, extra in curves:
        ax.plot(s, v, color=cmap(norm(number)), lw=1.0, marker="." if len(s) < 80 else None, ms=2.5,
                label=f"{what} {number}{extra}" if labelled else None)
    return cmap, norm


def _draw_pressure(fig, ax, title, curves, c_final, final_iteration, what, total, along, xlim, bar_axes=None,
                   compact=False):
    """One pair's pressure panel: the curves coloured by their place in the run, the final profile from the file;
    the horizontal range from pressure_range() of the step curves and the final profile. The colour bar (more
    than 6 curves) takes its room from bar_axes (default: ax). `compact` (one of several narrow panels): the
    title in two lines, smaller. Returns the contact zone and the range set ((lo, hi) or None each)."""
    import matplotlib.cm
    labelled = len(curves) <= 6
    cmap, norm = _draw_curves(ax, curves, what, labelled)
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
    _from_zero(ax, [p for _, p in solutions])
    ax.set_xlabel(AXIS_LABELS[along])
    ax.set_ylabel("contact pressure")
    shown = f"{len(curves)} of {total}" if len(curves) < total else f"all {total}"
    ax.set_title(title + (("\n" if compact else " ") + f"({shown} {what}s)" if len(curves) > 1 else ""),
                 fontsize=8 if compact else 10)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=6 if compact else 7, loc="best", framealpha=0.8)
    found = contact_zone(solutions) if solutions else None
    return (found[0] if found else None), limits


def _from_zero(ax, profiles):
    """The pressure axis from 0 to 8 % above the largest pressure drawn: a uniform pressure (a shrink fit's, equal
    to 1e-9) is drawn as a level line, not as its rounding noise magnified."""
    import numpy as np
    values = [np.asarray(p, dtype=float) for p in profiles]
    top = max((float(np.nanmax(v)) for v in values if np.isfinite(v).any()), default=0.0)
    if top > 0:
        ax.set_ylim(min(0.0, ax.get_ylim()[0]), max(ax.get_ylim()[1], 1.08 * top))


def _pair_axes(fig, spec, friction, stick_steps):
    """A pair's panels in the gridspec cell `spec`, sharing the horizontal axis: [pressure] alone for a
    frictionless pair; for a friction pair [pressure, tangential traction, slip] and with `stick_steps` a lower
    strip for the stick zone of each step."""
    if not friction:
        return [fig.add_subplot(spec)]
    ratios = [1.0, 1.0, 0.8] + ([0.5] if stick_steps else [])
    rows = spec.subgridspec(len(ratios), 1, hspace=0.08, height_ratios=ratios)
    first = fig.add_subplot(rows[0, 0])
    return [first] + [fig.add_subplot(rows[i, 0], sharex=first) for i in range(1, len(ratios))]


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


def _draw_tangential(ax, curves, c_final, friction, along, zones, legend=True):
    """A friction pair's tangential-traction panel (below its pressure panel, sharing the horizontal axis): the
    curves [(number, coordinate, traction, _), ...] coloured as the pressure's, the final traction from the file
    (black; its legend names the friction law and the total tangential force), the final state's friction bound
    +-mu p or +-g (dotted: where the traction reaches it the node slips) and the final stick zones shaded; the
    legend unless `legend` is False (one of several narrow panels: the first has it, "small")."""
    _draw_curves(ax, curves)
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
    ax.set_ylabel("tangential traction")
    ax.grid(True, alpha=0.3)
    if legend:  # in a narrow panel (legend "small"), smaller, so that it stays inside
        ax.legend(fontsize=5 if legend == "small" else 7, loc="best", framealpha=0.8)


def _draw_slip(ax, curves, c_final, along):
    """A friction pair's slip panel: the slip of each plotted step (coloured as the pressure's) and the final slip
    from the file in black; 0 marked. The vertical range is at least +-1e-6 of the slave edge's length, so that a
    pair that sticks throughout (slip at rounding level, 1e-16) shows a flat line at 0, not its noise."""
    import numpy as np
    _draw_curves(ax, curves)
    arc = np.asarray(c_final.get("arc_length", [0.0]), dtype=float)
    values = [np.asarray(v, dtype=float) for _, _, v, _ in curves] + [np.zeros(1)]
    if slip(c_final) is not None:
        values.append(slip(c_final))
    largest = max(float(np.nanmax(np.abs(v))) if np.isfinite(v).any() else 0.0 for v in values)
    floor = 1e-6 * float(np.ptp(arc)) if len(arc) else 0.0
    if floor > 0 and largest < floor:
        ax.set_ylim(-floor, floor)
    v = slip(c_final)
    if v is not None:
        ax.plot(edge_coordinate(c_final, along), v, color="black", lw=1.5, ls=(0, (5, 3)) if curves else "-",
                zorder=5, gid="slip", label="final slip")
    ax.axhline(0.0, color="black", lw=0.5)
    ax.set_ylabel("slip")
    ax.grid(True, alpha=0.3)


def _draw_stick_steps(ax, per_step):
    """The stick zones of each plotted step [(step, [(lo, hi), ...]), ...] as bars, one row per step (y: the
    step), coloured as the step's curves."""
    cmap, norm = _curve_colours(per_step)
    for k, zones in per_step:
        ax.broken_barh([(lo, hi - lo) for lo, hi in zones], (k - 0.35, 0.7), facecolors=cmap(norm(k)),
                       edgecolors=STICK_COLOUR, linewidth=0.8, gid="stick_step")
    steps = [k for k, _ in per_step]
    if steps:
        ax.set_ylim(min(steps) - 0.6, max(steps) + 0.6)
        ax.set_yticks(steps if len(steps) <= 6 else steps[::max(1, len(steps) // 4)])
    ax.set_ylabel("stick\n(step)", fontsize=8)
    ax.tick_params(axis="y", labelsize=7)
    ax.grid(True, axis="x", alpha=0.3)


def _draw_friction(axes, steps, pair, friction, profiles, along, max_curves, loaded, legend=True):
    """The friction pair's panels below its pressure panel axes[0]: the tangential traction (the step curves, or
    with a single step the events' iterations) with the final stick zones shaded (in the pressure panel too),
    the slip per step, and with several steps the stick zone of each step; only the lowest panel keeps its tick
    labels. Returns (the final stick zones, the stick zones per step)."""
    ax, tax, sax = axes[:3]
    c_final = steps[-1]["contacts"][pair]
    if len(steps) > 1:
        curves = step_curves(steps, pair, along, max_curves, loaded, values=tangential_traction)
        slips = step_curves(steps, pair, along, max_curves, loaded, values=slip)
    else:
        curves = iteration_curves(profiles, c_final, along, max_curves, tangential=True)
        slips = []
    stick = friction["stick"]
    zones = stick_zones(edge_coordinate(c_final, along), stick) if stick is not None else []
    _draw_stick(ax, zones, label=False)
    _draw_tangential(tax, curves, c_final, friction, along, zones, legend)
    _draw_slip(sax, slips, c_final, along)
    per_step = step_stick_zones(steps, pair, along, max_curves) if len(axes) > 3 else []
    if len(axes) > 3:
        _draw_stick_steps(axes[3], per_step)
    for a in axes[:-1]:
        a.set_xlabel("")
        a.tick_params(labelbottom=False)
    axes[-1].set_xlabel(AXIS_LABELS[along])
    return zones, per_step


def draw_pair(fig, spec, steps, pair, friction, along, xlim, max_curves, loaded, profiles, title=None,
              compact=False, legend=True):
    """The panels of one pair in the gridspec cell `spec` (the pressure; for a friction pair the tangential
    traction, the slip and, with several steps, the stick zone per step below it): one curve per step, or with a
    single step one per iteration of the events' `profiles` (plot_profiles.iteration_profiles); `compact` and
    `legend` for one of several narrow panels (smaller titles; the tangential legend on the first only).
    Returns {"zone": the contact zone (lo, hi) or None, "zoomed": the range set or None, "xlim": the horizontal
    range as drawn, "stick_zones": the final stick zones, "stick_steps": [(step, zones), ...]} (the last two
    friction pairs only)."""
    c_final = steps[-1]["contacts"][pair]
    axes = _pair_axes(fig, spec, friction is not None, len(steps) > 1)
    if len(steps) > 1:
        curves = step_curves(steps, pair, along, max_curves, loaded)
        what, total = "step", len(steps)
    else:
        curves = iteration_curves(profiles, c_final, along, max_curves)
        what, total = "iteration", len(profiles)
    zone, limits = _draw_pressure(fig, axes[0], title or pair, curves, c_final, steps[-1]["iteration"], what,
                                  total, along, xlim, bar_axes=axes if len(axes) > 1 else None, compact=compact)
    out = {"zone": zone, "zoomed": limits}
    if friction is not None:
        out["stick_zones"], out["stick_steps"] = _draw_friction(axes, steps, pair, friction, profiles, along,
                                                                max_curves, loaded, legend)
    if compact:  # narrow panels side by side: the long label would run into the next one
        axes[-1].set_xlabel(SHORT_AXIS_LABELS[along])
    if limits is not None:
        axes[0].set_xlim(*limits)  # the panels below share it; their own data does not widen it
    out["xlim"] = tuple(float(v) for v in axes[0].get_xlim())
    return out
