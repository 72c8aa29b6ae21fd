"""What the commands print: the live progress of a job and a job's state. Every value comes from the server and
is formatted through num() / word() / dicts(), which accept anything (a string where a number belongs, a list
where an object belongs) and never raise."""
import json
import shutil
import sys
import time

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
    """The live progress display of watch and submit --wait, on stderr: one line redrawn in place on a
    terminal; one plain line per iteration otherwise."""

    def __init__(self, stream=None, quiet=False, events_out=None):
        self.out = stream or sys.stderr
        self.tty = hasattr(self.out, "isatty") and self.out.isatty()
        self.quiet = quiet
        self.pending = ""        # the last line drawn in place (TTY)
        self.last_draw = 0.0
        self.pending_text = None  # a line not drawn yet (redraws are limited to 10 per second)
        self.events_out = events_out

    def _line(self, text):
        if self.tty and self.pending:
            self.out.write("\n")  # the live line stays, as the last iteration before this line
            self.pending = ""
        self.out.write(text + "\n")
        self.out.flush()

    def _live(self, text, force=False):
        if not self.tty:
            if not self.quiet:
                self._line(text)
            return
        now = time.monotonic()
        if not force and now - self.last_draw < 0.1:
            self.pending_text = text
            return
        width = shutil.get_terminal_size((100, 20)).columns - 1
        for candidate in text:
            if len(candidate) <= width:
                break
        self.out.write("\r\x1b[K" + candidate[:max(10, width)])
        self.out.flush()
        self.pending = text
        self.pending_text = None
        self.last_draw = now

    def note(self, text):
        self._line(text)

    def __call__(self, e):
        if self.events_out:
            self.events_out.write(json.dumps(e) + "\n")
            self.events_out.flush()
        t = e.get("type")
        if t == "iteration":
            self._live(compact_iterations(e) if self.tty else format_iteration(e))
        elif t == "state":
            msg = f": {word(e['message'], 500)}" if e.get("message") else ""
            self._line(f"state {word(e.get('state'))}{msg}")
        elif t == "step":
            bodies = ", ".join(f"{word(b.get('name'))} {num(b.get('elements'), 'd')} cells"
                               for b in dicts(e.get("bodies")))
            if self.pending_text:
                self._live(self.pending_text, force=True)
            self._line(f"step {num(e.get('step'), 'd')} at iteration {num(e.get('iteration'), 'd')}: {bodies}")
        elif t == "end":
            if self.pending_text:
                self._live(self.pending_text, force=True)
            if self.tty and self.pending:
                self.out.write("\n")
                self.pending = ""
            conv = word(e.get("stop_reason")) or "?"
            if conv != "converged" and e.get("state") == "SUCCEEDED":
                conv += ", not converged"
            msg = f": {word(e['message'], 500)}" if e.get("message") else ""
            self.out.write(f"end {word(e.get('state'))} ({conv}) after {num(e.get('iterations'), 'd')} "
                           f"iterations, {num(e.get('solve_seconds', 0), '.3g')} s{msg}\n")
            self.out.flush()


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
    return [f"paper {num(e.get('paper_criterion'), digits, 'nan')}",
            f"{'residual' if wide else 'res'} {num(e.get('fixed_point_residual'), digits, 'nan')}"]


def _label(e):
    return "step" if word(e.get("measure")) == "complementarity" else "iter"


def format_iteration(e):
    """ "iter 12  paper 1.23e-03  residual 2.22e-02  dofs upper 528 lower 528  | pair: force 140.9 p_max 166.4"
    (active-set methods: "step 3  active 245 (2 changed)  compl 1.20e-03 ...") """
    parts = [f"{_label(e)} {num(e.get('iteration', 0), '5d'):>5}"] + _measure_parts(e)
    bodies = dicts(e.get("bodies"))
    if bodies:
        parts.append("dofs " + " ".join(f"{word(b.get('name'))} {num(b.get('dofs'), 'd')}" for b in bodies))
    for p in dicts(e.get("pairs")):
        parts.append(f"| {word(p.get('name'))}: force {num(p.get('force', 0), '.5g')} "
                     f"p_max {num(p.get('max_pressure', 0), '.5g')}")
    if e.get("elapsed_seconds") is not None:
        parts.append(f"{num(e['elapsed_seconds'], '.2f')}s")
    note = word(e.get("note"), 200).strip().rstrip(";").strip()
    if note:
        parts.append(f"({note})")
    return "  ".join(parts)


def compact_iterations(e):
    """The terminal's live line, in forms from the fullest to the shortest (the first that fits is drawn):
    "iter 12  paper 1.23e-03  res 2.22e-02  force 140.9  p_max 166.4  dofs 528/528  0.05s", or for the
    active-set methods "step 2  active 245 (3 changed)  compl 1.20e-03  force ..." (several pairs or bodies:
    values joined by '/', in the order of the job)."""
    pairs, bodies = dicts(e.get("pairs")), dicts(e.get("bodies"))
    parts = [f"{_label(e)} {num(e.get('iteration', 0), 'd')}"] + _measure_parts(e, wide=False)
    if pairs:
        parts.append("force " + "/".join(num(p.get("force", 0), ".5g") for p in pairs))
        parts.append("p_max " + "/".join(num(p.get("max_pressure", 0), ".5g") for p in pairs))
    if bodies:
        parts.append("dofs " + "/".join(num(b.get("dofs"), "d") for b in bodies))
    elapsed = [f"{num(e['elapsed_seconds'], '.1f')}s"] if e.get("elapsed_seconds") is not None else []
    return ["  ".join(parts + elapsed), " ".join(parts + elapsed), " ".join(parts)]


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
