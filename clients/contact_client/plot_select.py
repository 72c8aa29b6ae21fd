"""What the plot draws of a result with many pairs and bodies, and reading only that: the pairs chosen by name
or pattern (at most a few panels), and from the file the chosen pairs in the steps drawn, the final step's
meshes and the state of every joint, the history of the steps, and the supports' force per step."""
import fnmatch

from .errors import BadInput
from .plot_mesh import analytic_gaps
from .plot_profiles import _spread
from .results import ResultFile

# Without a choice of pairs, at most MAX_PAIRS panels: those of the joints that govern (governing()), the largest
# final contact force among equals.
MAX_PAIRS = 4
# A result with more bodies than this is drawn as an overview of all bodies and joints (plot_wall) instead of the
# mesh row.
OVERVIEW_BODIES = 8
NAMES_SHOWN = 12  # pair names listed in the error of a pattern that matches none

# The datasets read: every body of the final step; every pair of the final step for its joint state and for the
# magnification's rule (plot_mesh.choose_warp); the pairs drawn in full.
BODY_KEYS = ("points", "cells", "displacement", "von_mises", "level")
STATE_KEYS = ("node", "status", "active", "stick", "gap", "normal_gap")


def split_patterns(patterns):
    """"a*,b" or ["a*", "b,c"] -> ["a*", "b", "c"]; None for none."""
    if patterns is None:
        return None
    if isinstance(patterns, str):
        patterns = [patterns]
    out = [p.strip() for text in patterns for p in str(text).split(",") if p.strip()]
    return out or None


def match_pairs(names, patterns, bodies_of=None):
    """The names (in their order) that one of the fnmatch patterns matches: the pair's name, or the name of its
    slave or master body (bodies_of: {pair: (slave body, master body)}), so that "base" picks every pair on the
    body base and "b0_*" every pair of the bricks b0_0, b0_1, ..."""
    bodies_of = bodies_of or {}
    return [n for n in names
            if any(fnmatch.fnmatchcase(n, p) or any(b and fnmatch.fnmatchcase(b, p) for b in bodies_of.get(n, ()))
                   for p in patterns)]


def no_match(patterns, names):
    """The BadInput of patterns that match no pair, naming the pairs there are (the first NAMES_SHOWN)."""
    shown = ", ".join(names[:NAMES_SHOWN]) + (f", ... ({len(names)} in all)" if len(names) > NAMES_SHOWN else "")
    return BadInput(f"no pair matches {','.join(patterns)} (by its name or its slave or master body's name); "
                    f"the pairs: {shown or 'none'}")


def governing(attrs):
    """How near a joint is to giving way, from its joint results at the final step (a pair's attributes:
    results-format.md, the contact tables): the larger of its friction utilisation |T| / (mu N) (1: it slips) and
    its eccentricity |e| / (L/2) (1: it hinges at an end); 0 for a joint without force (open) or without them."""
    import math
    if not attrs or not float(attrs.get("force", 0.0) or 0.0):
        return 0.0
    values = [abs(float(attrs.get(k, 0.0) or 0.0)) for k in ("friction_utilisation", "eccentricity")]
    return max((v for v in values if math.isfinite(v)), default=0.0)


def choose_pairs(names, patterns=None, max_pairs=MAX_PAIRS, force=None, bodies_of=None, governs=None):
    """The pairs to draw a panel for: (drawn, matched, note). `matched` are the pairs the patterns select (all
    without patterns; BadInput when they select none); beyond max_pairs of them, the max_pairs that govern most
    (governs: {pair: governing()}: slipping or hinging joints first), the largest final contact force (force: {pair:
    force}) among equals, are drawn, in the result's order, and the note says so."""
    patterns = split_patterns(patterns)
    matched = match_pairs(names, patterns, bodies_of) if patterns else list(names)
    if patterns and not matched:
        raise no_match(patterns, list(names))
    if len(matched) <= max_pairs:
        return matched, matched, ""
    force, governs = force or {}, governs or {}
    # Utilisations equal to 3 digits count as equal (1.000 for every slipping joint): the force decides among them.
    chosen = sorted(matched, key=lambda n: (-round(float(governs.get(n, 0.0)), 3),
                                            -abs(float(force.get(n, 0.0)))))[:max_pairs]
    drawn = [n for n in matched if n in chosen]
    what = f"{len(matched)} pairs match" if patterns else f"{len(matched)} pairs"
    rule = ("that govern (the highest friction utilisation |T|/(mu N) or eccentricity |e|/(L/2); the largest force "
            "among equals)" if governs else "with the largest contact force")
    return drawn, matched, (f"{what}: the {max_pairs} {rule} drawn; choose with --pairs PATTERN[,PATTERN] (pair or "
                            "body names, * and ?) and --max-pairs N")


def final_forces(history, names):
    """{pair: its normal contact force at the last step} from /history/steps (empty without)."""
    import numpy as np
    force = history.get("force")
    columns = list(history.get("pair_names", []))
    if force is None or not len(columns):
        return {}
    last = np.asarray(force, dtype=float).reshape(-1, len(columns))[-1]
    return {n: last[columns.index(n)] for n in names if n in columns}


def _supported(job, names):
    """The bodies with a displacement condition (the job's), whose reactions are the supports' force; all bodies
    without the job."""
    if not job or not isinstance(job.get("bodies"), list):
        return list(names)
    held = {b.get("name") for b in job["bodies"] if isinstance(b, dict)
            and any(isinstance(c, dict) and "displacement" in c for c in b.get("boundary") or [])}
    return [n for n in names if n in held]


def _support_reactions(f, steps, job):
    """Each step's "support_reaction": {body: the `reaction_total` of the body} over the supported bodies."""
    import numpy as np
    for step in steps:
        step["support_reaction"] = {
            name: np.asarray(f.body_attrs(step["step"], name).get("reaction_total", np.zeros(2)), dtype=float)
            for name in _supported(job, step["body_names"])}


def _final_step(f, step, drawn, overview, job):
    """Fills the final step: every body's mesh, displacement and stress; every pair not drawn, the datasets of its
    state (STATE_KEYS, with its position where the mesh row or the job's parabolic gap needs it)."""
    last = step["step"]
    parabola = {name for name, (_, r0, _) in analytic_gaps(job).items() if r0}
    for name in step["body_names"]:
        body = f.body(last, name, BODY_KEYS)
        if "cells" not in body:
            body.update(f.body(last, name, ("quads",)))
        step["bodies"][name] = body
    keys = STATE_KEYS if overview else STATE_KEYS + ("position", "arc_length")
    for name in step["pair_names"]:
        if name not in drawn:
            step["contacts"][name] = f.pair(last, name, keys + (("position",) if name in parabola else ()))


def read_for_plot(path, pairs=None, max_pairs=MAX_PAIRS, max_curves=12, overview=None):
    """Reads from the result file `path` what plot_result draws, in read_result()'s layout: every step's
    attributes; the pairs drawn (choose_pairs) whole in the steps whose curves are drawn (at most max_curves,
    spread over the run); the final step's bodies (BODY_KEYS) and the state of its other pairs (STATE_KEYS);
    /history/steps; the job (normalized); each step's supports' force ("support_reaction") when every step is
    kept. Returns (result, {"drawn", "matched", "note", "overview"}); overview None decides by the number of
    bodies (more than OVERVIEW_BODIES)."""
    with ResultFile(path) as f:
        steps = [f.step(k) for k in range(f.count)]
        history = f.history("steps")
        job = f.job("normalized") or f.job()
        result = {"path": f.path, "attrs": f.attrs, "steps": steps, "history": {"steps": history} if history else {},
                  "body_names": steps[-1]["body_names"] if steps else [],
                  "pair_names": steps[-1]["pair_names"] if steps else []}
        if job is not None:
            result["job"] = job
        if not steps:
            return result, {"drawn": [], "matched": [], "note": "", "overview": False}
        final = steps[-1]
        names = final["pair_names"]
        attrs = {n: f.pair(final["step"], n, ())["attrs"] for n in names}
        bodies_of = {n: (a.get("slave_body"), a.get("master_body")) for n, a in attrs.items()}
        governs = {n: governing(a) for n, a in attrs.items()}
        drawn, matched, note = choose_pairs(names, pairs, max_pairs, final_forces(history, names), bodies_of,
                                            governs)
        for k in sorted(set(_spread(len(steps), max_curves)) | {len(steps) - 1}):
            for name in drawn:
                if name in steps[k]["pair_names"]:
                    steps[k]["contacts"][name] = f.pair(steps[k]["step"], name)
        many = len(final["body_names"]) > OVERVIEW_BODIES if overview is None else bool(overview)
        _final_step(f, final, drawn, many, job)
        if len(steps) == len(history.get("load_factor", [])):
            _support_reactions(f, steps, job)
    return result, {"drawn": drawn, "matched": matched, "note": note, "overview": many}
