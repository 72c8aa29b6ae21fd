"""What the commands print: the live progress of a job (a tqdm counter on a terminal) and a job's state. Every
value comes from the server and is formatted through num() / word() / dicts(), which accept anything (a string
where a number belongs, a list where an object belongs) and never raise."""
import json
import shutil
import sys

from .errors import one_line


def num(value, spec, missing="?"):
    """A number formatted with `spec`; anything else as short text ("?" when absent)."""
    if value is None:
        return missing
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return word(value, 20)
    try:
        return format(value, spec)
    except (TypeError, ValueError):
        return word(value, 20)


def word(value, limit=80):
    """A value as one line of text of at most `limit` characters."""
    return one_line(value)[:limit]


def dicts(value):
    """The objects of a list (anything else: none)."""
    return [x for x in value if isinstance(x, dict)] if isinstance(value, list) else []


def obj(value):
    return value if isinstance(value, dict) else {}


class Progress:
    """The live progress display of watch and submit --wait, on stderr.

    On a terminal, with Debian's python3-tqdm: a tqdm counter redrawn in place, with the iteration, what decides
    convergence (the measure: residuals, or the complementarity and the active set), the force and maximum
    pressure of each pair, the DOFs of each body and the solver's elapsed time; load steps, cuts and collapse
    trials in their own words (load_step_words); state changes and adaptive steps
    are printed above it. Otherwise (a pipe, a log, or no tqdm): one plain line per iteration.
    quiet: nothing at all (the commands print errors only); events_out still receives every event."""

    def __init__(self, stream=None, quiet=False, events_out=None):
        self.out = stream or sys.stderr
        self.quiet = quiet
        self.events_out = events_out
        self.bar = None
        self.tqdm = None
        if not quiet and hasattr(self.out, "isatty") and self.out.isatty():
            try:
                from tqdm import tqdm
                self.tqdm = tqdm
            except ImportError:  # python3-tqdm missing: plain lines
                self.tqdm = None

    def _line(self, text):
        if self.quiet:
            return
        if self.bar is not None:
            self.bar.write(text, file=self.out)  # above the bar, which is redrawn below
        else:
            self.out.write(text + "\n")
            self.out.flush()

    def _iteration(self, e):
        if self.tqdm is None:
            self._line(format_iteration(e))
            return
        iteration = e.get("iteration")
        if not isinstance(iteration, int) or isinstance(iteration, bool):
            return
        width = shutil.get_terminal_size((100, 20)).columns - 1
        tail = len("  [00:00, 0000.00it/s]")
        forms = compact_iterations(e, elapsed=False)
        text = next((f for f in forms if len(f) + tail <= width), forms[-1][:max(10, width - tail)])
        if self.bar is None or iteration < self.bar.n:  # a job run again from the start counts again
            self._close_bar()
            # "iter 84  paper 8.96e-05  res 1.34e-02  active 15  force 142.53  p_max 184.47  dofs 16640/16640
            #  [00:03, 27.1it/s]": tqdm keeps the elapsed time and the rate.
            self.bar = self.tqdm(desc=text, total=None, file=self.out, unit="it", dynamic_ncols=True,
                                 mininterval=0.1, bar_format="{desc}  [{elapsed}, {rate_fmt}]")
        else:
            self.bar.set_description_str(text, refresh=False)
        self.bar.update(iteration - self.bar.n)

    def _close_bar(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def note(self, text):
        self._line(text)

    def close(self):
        self._close_bar()

    def __call__(self, e):
        if self.events_out:
            self.events_out.write(json.dumps(e) + "\n")
            self.events_out.flush()
        t = e.get("type")
        if self.quiet:
            return
        if t == "iteration":
            self._iteration(e)
        elif t == "state":
            msg = f": {word(e['message'], 500)}" if e.get("message") else ""
            self._line(f"state {word(e.get('state'))}{msg}")
        elif t == "step":
            listed = dicts(e.get("bodies"))
            total = obj(e.get("bodies_summary"))
            if total and (not listed or len(listed) > LISTED):
                bodies = f"{num(total.get('count'), 'd')} bodies, {num(total.get('elements'), 'd')} cells"
            else:
                bodies = ", ".join(f"{word(b.get('name'))} {num(b.get('elements'), 'd')} cells" for b in listed)
            self._line(f"step {num(e.get('step'), 'd')} at iteration {num(e.get('iteration'), 'd')}: {bodies}")
        elif t == "load_step":
            self._line(load_step_words(e))
        elif t == "adaptive_step":
            self._line(adaptive_step_words(e))
        elif t == "end":
            if self.bar is not None:
                self.bar.refresh()
            self._close_bar()
            conv = word(e.get("stop_reason")) or "?"
            if conv != "converged" and e.get("state") == "SUCCEEDED":
                conv += ", not converged"
            msg = f": {word(e['message'], 500)}" if e.get("message") else ""
            self._line(f"end {word(e.get('state'))} ({conv}) after {num(e.get('iterations'), 'd')} "
                       f"iterations, {num(e.get('solve_seconds', 0), '.3g')} s{msg}")


def adaptive_step_words(e):
    """An adaptive_step event in words: the step's unknowns, its estimated pressure error and, once there is a step
    with at most half its unknowns, the largest change the stop test reads against it (docs/job-format.md, "What
    the defaults aim at")."""
    unknowns = sum(b.get("unknowns", 0) for b in dicts(e.get("bodies")) if isinstance(b.get("unknowns"), int))
    text = f"adaptive step {num(e.get('step'), 'd')}: {unknowns} unknowns"
    if isinstance(e.get("pressure_estimate"), (int, float)):
        text += f", pressure error ~{num(100 * e['pressure_estimate'], '.3g')} %"
    changes = [e.get(k) for k in ("force_change", "peak_change", "extent_change", "stick_change", "tangential_change")]
    changes = [c for c in changes if isinstance(c, (int, float)) and not isinstance(c, bool)]
    compared = e.get("compared_with")
    if isinstance(compared, int) and compared >= 0 and changes:
        text += f"; against step {compared}: the answer changed by at most {num(100 * max(changes), '.2g')} %"
    return text


def load_step_words(e):
    """A load_step event in words (contact/progress_json.hpp's load_step_words, the same): a load step held, a cut
    (with the load reached and the next try), a collapse trial (its multiplier, held or not)."""
    iterations = num(e.get("iterations", 0), "d")
    if e.get("kind") == "trial":
        return (f"collapse trial {num(e.get('step'), 'd')}: multiplier {num(e.get('multiplier'), '.6g')} "
                f"{'held' if e.get('held') else 'did not hold'} ({iterations} iterations)")
    step = f"load step {num(e.get('step'), 'd')} of {num(e.get('steps'), 'd')}"
    fraction = e.get("fraction", 1.0)
    if e.get("kind") == "cut":
        return (f"{step} cut: held up to {num(100 * fraction, '.4g')} % of the step (load factor "
                f"{num(e.get('load_factor'), '.6g')}), now trying {num(100 * e.get('next', 0.0), '.4g')} %")
    if isinstance(fraction, (int, float)) and fraction < 1.0:
        return (f"{step}: sub-step to {num(100 * fraction, '.4g')} % held (load factor "
                f"{num(e.get('load_factor'), '.6g')}, {iterations} iterations)")
    return f"{step} held at load factor {num(e.get('load_factor'), '.6g')} ({iterations} iterations)"


def _measure_parts(e, wide=True):
    """What decides convergence in an iteration event (its "measure"): the active set, its changes and the
    complementarity residual for the active-set methods; both residuals for the fixed-point schemes; the energy
    gradient for the penalty monolithic reference."""
    measure = word(e.get("measure")) or "fixed_point"
    active = f"active {num(e.get('active_nodes', 0), 'd')} ({num(e.get('active_set_changes', 0), 'd')} changed)"
    if measure == "complementarity":
        return [active, f"compl {num(e.get('complementarity'), '.2e', 'nan')}"]
    if measure == "gradient":
        return [f"gradient {num(e.get('fixed_point_residual'), '.2e', 'nan')}", active]
    digits = ".3e" if wide else ".2e"
    parts = [f"paper {num(e.get('paper_criterion'), digits, 'nan')}",
             f"{'residual' if wide else 'res'} {num(e.get('fixed_point_residual'), digits, 'nan')}"]
    return parts if wide else parts + [f"active {num(e.get('active_nodes', 0), 'd')}"]


def _label(e):
    return "step" if word(e.get("measure")) == "complementarity" else "iter"


def _tangential(p):
    """ " t_force -0.9847" for a friction pair's event (it carries `tangential_force`), "" otherwise."""
    return f" t_force {num(p['tangential_force'], '.5g')}" if "tangential_force" in p else ""


# Past this many pairs or bodies, a line shows their totals (the event's pairs_summary and bodies_summary) and
# the pairs the job selects (output.progress_pairs), not each one.
LISTED = 6


def _summarised(e, key):
    """True when the line should show the totals of `key` ("pairs" or "bodies") rather than each item: the event
    lists only some of them, or more than LISTED."""
    summary = obj(e.get(f"{key}_summary"))
    count = summary.get("count") if isinstance(summary.get("count"), int) else len(dicts(e.get(key)))
    return bool(summary) and (e.get(f"{key}_listed") not in (None, "all") or count > LISTED)


def _pairs_total(e):
    """ "946 pairs: force 232.3 active 2882 (0 changed in 0 pairs) stick 2882 slip 0 p_max 3.94 at b0_21..." """
    s = obj(e.get("pairs_summary"))
    text = (f"{num(s.get('count'), 'd')} pairs: force {num(s.get('force', 0), '.5g')} "
            f"active {num(s.get('active_nodes', 0), '.0f')} ({num(s.get('changed_nodes', 0), '.0f')} changed in "
            f"{num(s.get('pairs_changed', 0), 'd')} pairs)")
    if s.get("friction_pairs"):
        text += (f" stick {num(s.get('stick_nodes', 0), '.0f')} slip {num(s.get('slip_nodes', 0), '.0f')}"
                 f" t_force {num(s.get('tangential_force', 0), '.5g')}")
    text += f" p_max {num(s.get('max_pressure', 0), '.5g')} at {word(s.get('max_pressure_pair'))}"
    if s.get("most_changed_nodes"):
        text += f" most changed {word(s.get('most_changed_pair'))} ({num(s.get('most_changed_nodes'), '.0f')})"
    return text


def _selected_pairs(e):
    """The pairs an event lists beyond the two its summary names (those the job selects), at most LISTED."""
    s = obj(e.get("pairs_summary"))
    named = {s.get("max_pressure_pair"), s.get("most_changed_pair")}
    return [p for p in dicts(e.get("pairs")) if p.get("name") not in named][:LISTED]


def _bodies_total(e):
    s = obj(e.get("bodies_summary"))
    return (f"dofs {num(s.get('dofs', 0), '.0f')} in {num(s.get('count'), 'd')} bodies"
            f"{'' if not s.get('elements_refined') else ', ' + num(s['elements_refined'], '.0f') + ' cells refined'}")


def format_iteration(e):
    """ "iter 12  paper 1.23e-03  residual 2.22e-02  dofs upper 528 lower 528  | pair: force 140.9 p_max 166.4"
    (active-set methods: "step 3  active 245 (2 changed)  compl 1.20e-03 ..."; a friction pair adds its
    tangential force: "| pair: force 6.18 p_max 20.3 t_force -0.985"). Past LISTED pairs or bodies, or when the
    event lists only some, their totals instead ("| 946 pairs: force ... p_max ... at <pair>", "dofs 29832 in 496
    bodies") and the pairs the job selects."""
    parts = [f"{_label(e)} {num(e.get('iteration', 0), '5d'):>5}"] + _measure_parts(e)
    bodies = dicts(e.get("bodies"))
    if _summarised(e, "bodies"):
        parts.append(_bodies_total(e))
    elif bodies:
        parts.append("dofs " + " ".join(f"{word(b.get('name'))} {num(b.get('dofs'), 'd')}" for b in bodies))
    pairs = dicts(e.get("pairs"))
    if _summarised(e, "pairs"):
        parts.append("| " + _pairs_total(e))
        pairs = _selected_pairs(e)
    for p in pairs:
        parts.append(f"| {word(p.get('name'))}: force {num(p.get('force', 0), '.5g')} "
                     f"p_max {num(p.get('max_pressure', 0), '.5g')}{_tangential(p)}")
    if e.get("elapsed_seconds") is not None:
        parts.append(f"{num(e['elapsed_seconds'], '.2f')}s")
    note = word(e.get("note"), 200).strip().rstrip(";").strip()
    if note:
        parts.append(f"({note})")
    return "  ".join(parts)


def compact_iterations(e, elapsed=True):
    """The terminal's live line, in forms from the fullest to the shortest (the first that fits is drawn):
    "iter 12  paper 1.23e-03  res 2.22e-02  active 15  force 140.9  p_max 166.4  dofs 528/528  0.05s", or for
    the active-set methods "step 2  active 245 (3 changed)  compl 1.20e-03  force ..." (several pairs or bodies:
    values joined by '/', in the order of the job; with friction pairs "t_force", '-' for a frictionless pair;
    past LISTED pairs or bodies their totals: "force 232.3 (946 pairs)  p_max 3.94  dofs 29832 (496 bodies)").
    elapsed=False leaves out the solver's elapsed time."""
    pairs, bodies = dicts(e.get("pairs")), dicts(e.get("bodies"))
    head = [f"{_label(e)} {num(e.get('iteration', 0), 'd')}"] + _measure_parts(e, wide=False)
    extra = []  # left out from the end first when the line is too long
    if _summarised(e, "pairs"):
        s = obj(e.get("pairs_summary"))
        extra.append(f"force {num(s.get('force', 0), '.5g')} ({num(s.get('count'), 'd')} pairs)")
        extra.append(f"p_max {num(s.get('max_pressure', 0), '.5g')}")
        if s.get("friction_pairs"):
            extra.append(f"stick/slip {num(s.get('stick_nodes', 0), '.0f')}/{num(s.get('slip_nodes', 0), '.0f')}")
    elif pairs:
        extra.append("force " + "/".join(num(p.get("force", 0), ".5g") for p in pairs))
        extra.append("p_max " + "/".join(num(p.get("max_pressure", 0), ".5g") for p in pairs))
        if any("tangential_force" in p for p in pairs):
            extra.append("t_force " + "/".join(num(p.get("tangential_force"), ".5g", "-") for p in pairs))
    if _summarised(e, "bodies"):
        s = obj(e.get("bodies_summary"))
        extra.append(f"dofs {num(s.get('dofs', 0), '.0f')} ({num(s.get('count'), 'd')} bodies)")
    elif bodies:
        extra.append("dofs " + "/".join(num(b.get("dofs"), "d") for b in bodies))
    seconds = [f"{num(e['elapsed_seconds'], '.1f')}s"] if elapsed and e.get("elapsed_seconds") is not None else []
    forms = ["  ".join(head + extra + seconds), " ".join(head + extra + seconds)]
    forms += [" ".join(head + extra[:k]) for k in range(len(extra), -1, -1)]
    return forms + [" ".join(head[:2])]


def print_job(job, out):
    prog = obj(job.get("progress"))
    rows = [("id", word(job.get("id"))), ("name", word(job.get("name"), 300)), ("state", word(job.get("state")))]
    if job.get("queue_position") is not None:
        rows.append(("queue position", num(job["queue_position"], "d")))
    rows.append(("iterations", num(job.get("iterations"), "d")))
    if prog:
        rows.append(("progress", format_iteration(prog)))
    if job.get("stop_reason"):
        rows.append(("stop", f"{word(job['stop_reason'])} (converged: {word(job.get('converged')).lower()})"))
    if job.get("message"):
        rows.append(("message", word(job["message"], 2000)))
    if job.get("error"):
        rows.append(("error", word(obj(job["error"]).get("message", job["error"]), 2000)))
    for w in dicts(job.get("warnings")):
        rows.append(("warning", f"{word(w.get('pointer'), 200)}: {word(w.get('message'), 2000)}"))
    t = obj(job.get("timings"))
    if t:
        rows.append(("timings", ", ".join(f"{word(k).replace('_seconds', '')} {num(v, '.3g')} s" for k, v in t.items()
                                          if isinstance(v, (int, float)) and not isinstance(v, bool))))
    for key in ("created", "started", "finished"):
        if job.get(key):
            rows.append((key, word(job[key])))
    rows.append(("result", "available" if job.get("result_available") is True else "none"))
    for k, v in rows:
        out.write(f"{k + ':':16}{v}\n")
