"""The command line: contact_client.py COMMAND ... (see the package's docstring). Whatever a server or a proxy
sends, a command ends with one "error: ..." line per problem and an exit code, never a traceback."""
import argparse
import json
import os
import sys
import traceback

from .client import DEFAULT_TIMEOUT, DEFAULT_URL, Client
from .display import Progress, dicts, num, print_job, word
from .errors import EXIT_ERROR, EXIT_JOB, EXIT_OK, EXIT_USAGE, BadInput, ClientError, one_line
from .plot import MAX_PAIRS, plot_result
from .plot_collapse import plot_collapse
from .results import read_events


def _cmd_submit(c, a):
    if (a.output or a.events_out or a.xmf) and not a.wait:
        raise BadInput("-o, --xmf and --events-out need --wait")
    job = c.submit(a.file, idempotency_key=a.idempotency_key)
    print(one_line(job["id"]), flush=True)  # submit() checked that it is there
    shown = print_warnings(job.get("warnings"))
    if not a.wait:
        return EXIT_OK
    return _follow(c, job["id"], a, shown)


def print_warnings(warnings, shown=0):
    """The model checks' warnings (docs/job-format.md, "Warnings") past the first `shown`, on stderr, each as
    "warning: <pointer>: <message>"; returns how many there are."""
    listed = dicts(warnings)
    for w in listed[shown:]:
        pointer = word(w.get("pointer"), 200)
        sys.stderr.write(f"warning: {pointer + ': ' if pointer else ''}{word(w.get('message'), 2000)}\n")
    return max(shown, len(listed))


def print_collapse(collapse, out=None):
    """A collapse analysis's answer, or a failed step's statics verdict (the end event's `collapse`), in lines."""
    if not isinstance(collapse, dict):
        return
    out = out or sys.stderr
    verdict, held, failed = word(collapse.get("verdict")), collapse.get("held"), collapse.get("failed")
    if verdict == "collapse" and isinstance(held, (int, float)) and isinstance(failed, (int, float)):
        out.write(f"collapse: lambda_c between {held:.6g} (held) and {failed:.6g} (did not hold), "
                  f"{collapse.get('solves', 0)} trial solves\n")
    elif verdict == "collapse":
        out.write("collapse: where the step failed, the states that held last show a mechanism\n")
    elif verdict:
        out.write(f"collapse analysis: {verdict}\n")
    bound = collapse.get("statics_bound")
    if isinstance(bound, (int, float)):
        out.write(f"  statics (rigid blocks, associated friction): lambda <= {bound:.6g}\n")
    mechanism = collapse.get("mechanism") or {}
    if mechanism.get("words"):
        whose = {"elastic": "the elastic solution's", "statics": "the rigid blocks' statics'"}.get(
            word(mechanism.get("source")), "")
        out.write(f"  mechanism{' (' + whose + ')' if whose else ''}: {word(mechanism['words'], 600)}\n")


def _follow(c, job_id, a, warnings_shown=0):
    """Follows the job to its end with the progress display; with -o downloads the result. With -q nothing is
    printed but errors and warnings: a job that does not end SUCCEEDED is one ("error: job ... ended FAILED ...")."""
    out = None
    progress = None
    try:
        if a.events_out:
            try:
                out = open(a.events_out, "w", encoding="utf-8")
            except OSError as exc:
                raise BadInput(f"cannot write {a.events_out}: {exc.strerror}") from None
        progress = Progress(quiet=a.quiet, events_out=out)
        c.log = progress.note
        end = None
        # --timeout, when given, is how long the stream may stay silent before it is resumed.
        for e in c.events(job_id, max_retries=a.retries, read_timeout=getattr(a, "timeout", None)):
            progress(e)
            if e.get("type") == "end":
                end = e
    finally:
        if progress:
            progress.close()
        if out:
            out.close()
    state = word(end.get("state")) if end else None
    if end:  # the answer's warnings (the job's were shown at submission), with -q too: they are not progress
        print_warnings(end.get("warnings"), warnings_shown)
        if not a.quiet:
            print_collapse(end.get("collapse"))
    if getattr(a, "output", None):
        if end and end.get("result_available") is True:
            c.download(job_id, a.output, xmf=getattr(a, "xmf", False))
            if not a.quiet:
                sys.stderr.write(f"wrote {a.output} ({os.path.getsize(a.output)} bytes)\n")
        else:
            sys.stderr.write(f"error: no result to download (job {state})\n")
    if state != "SUCCEEDED":
        reason = word(end.get("stop_reason")) if end else ""
        message = word(end.get("message"), 500) if end and end.get("message") else ""
        sys.stderr.write(f"error: job {one_line(job_id)} ended {state}" + (f" ({reason})" if reason else "")
                         + (f": {message}" if message else "") + "\n")
        return EXIT_JOB
    return EXIT_OK


def _cmd_watch(c, a):
    return _follow(c, a.id, a)


def _cmd_status(c, a):
    job = c.status(a.id)
    if a.json:
        print(json.dumps(job, indent=2))
    else:
        print_job(job, sys.stdout)
    return EXIT_OK


def _cmd_list(c, a):
    page = c.list(state=a.state, page_size=a.page_size, page_token=a.page_token, all_pages=a.all)
    if a.json:
        print(json.dumps(page, indent=2))
        return EXIT_OK
    jobs = page["jobs"]
    if not jobs:
        print("no jobs")
    for j in jobs:
        outcome = word(j.get("stop_reason")) or (f"queue {num(j['queue_position'], 'd')}"
                                                 if j.get("queue_position") else "")
        print(f"{word(j.get('id'), 40)}  {word(j.get('state')):9}  {num(j.get('iterations', 0), 'd'):>7}  "
              f"{outcome:14}  {word(j.get('created'), 40)}  {word(j.get('name'), 200)}")
    if page.get("next_page_token"):
        print(f"more: --page-token {word(page['next_page_token'], 300)}")
    return EXIT_OK


def _cmd_cancel(c, a):
    job = c.cancel(a.id)
    job_id = word(job.get("id")) or a.id
    if job.get("state") == "CANCELLED":
        print(f"{job_id} CANCELLED")
    else:
        print(f"{job_id} {word(job.get('state'))}: cancellation requested (stops within one iteration)")
    return EXIT_OK


def _cmd_delete(c, a):
    c.delete(a.id)
    print(f"{a.id} deleted")
    return EXIT_OK


def _cmd_download(c, a):
    c.download(a.id, a.output, xmf=a.xmf)
    print(f"wrote {a.output} ({os.path.getsize(a.output)} bytes)"
          + (f" and {os.path.splitext(a.output)[0] + '.xmf'}" if a.xmf else ""))
    return EXIT_OK


def _cmd_validate(c, a):
    r = c.validate(a.file)
    bodies = ", ".join(f"{word(b.get('name'))} {num(b.get('elements'), 'd')} cells {num(b.get('nodes'), 'd')} nodes"
                       for b in dicts(r.get("bodies")))
    print(f"valid: {word(r.get('name'), 300)}: {num(r.get('dofs'), 'd')} dofs ({bodies}), "
          f"{num(r.get('contacts'), 'd')} contact pair(s)", flush=True)
    print_warnings(r.get("warnings"))
    if a.normalized:
        print(json.dumps(r.get("normalized"), indent=2))
    return EXIT_OK


def _xlim(words):
    """plot --xlim: None (the default zoom), "full", or (lo, hi) with lo < hi."""
    if words is None:
        return None
    if words == ["full"]:
        return "full"
    try:
        lo, hi = (float(w) for w in words)
    except ValueError:
        lo = hi = None
    if lo is None or not lo < hi:
        raise BadInput(f"--xlim {' '.join(words)}: give two numbers LO < HI, or 'full'")
    return lo, hi


def _cmd_plot(c, a):
    if not os.path.exists(a.file):
        raise BadInput(f"cannot read {a.file}: no such file")
    try:
        import h5py  # noqa: F401
        import matplotlib  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as exc:
        raise ClientError(f"plot needs {exc.name}, which {sys.executable} cannot import (Debian's "
                          "/usr/bin/python3 with apt-get install python3-h5py python3-numpy python3-matplotlib)"
                          ) from None
    if a.max_pairs < 1:
        raise BadInput(f"--max-pairs {a.max_pairs}: give 1 or more")
    events = None
    if a.events:
        try:
            events = read_events(a.events)
        except (OSError, ValueError) as exc:
            raise BadInput(f"cannot read events from {a.events}: {one_line(exc)}") from None
    try:
        # Only what the figure draws is read (a wall of hundreds of bodies holds tens of thousands of datasets).
        drawn = plot_result(a.file, a.output, events=events, warp=a.warp, title=a.title, xlim=_xlim(a.xlim),
                            along=a.along, pairs=a.pairs, max_pairs=a.max_pairs, overview=a.overview)
    except (OSError, KeyError) as exc:
        raise BadInput(f"cannot read {a.file}: {one_line(exc)}") from None
    _print_plot(a.output, drawn)
    return EXIT_OK


def _cmd_collapse(c, a):
    if not os.path.exists(a.file):
        raise BadInput(f"cannot read {a.file}: no such file")
    if a.point is not None and not a.body:
        raise BadInput("--point needs --body (the body whose node nearest the point is followed)")
    try:
        drawn = plot_collapse(a.file, a.output, body=a.body, point=a.point, title=a.title)
    except (OSError, KeyError) as exc:
        raise BadInput(f"cannot read {a.file}: {one_line(exc)}") from None
    curve = drawn["curve"]
    print(f"wrote {a.output}: the capacity curve ({len(curve['multiplier'])} states that held, the displacement of "
          f"'{curve['body']}' node {curve['node']}) and the mechanism ({drawn['kind'] or 'none found'})")
    print(f"verdict: {word(drawn['words'], 2000)}")
    return EXIT_OK


COORDINATE_WORDS = {"arc": "arc length", "x": "x", "angle": "angle"}


def _print_plot(png, drawn):
    """What plot drew: the size and the magnification, the pairs chosen, each pair's range and contact (and
    friction), the joints' states of the overview, the load path."""
    warp, (width, height) = drawn["warp"], drawn["size"]
    print(f"wrote {png} ({width} x {height} px; " + (f"mesh displaced x {warp:g})" if warp else "undeformed mesh)"))
    if drawn["warp_note"]:
        print(f"  magnification lowered: {drawn['warp_note']}")
    if drawn["pairs_note"]:
        print(f"  {drawn['pairs_note']}")
    for pair, (lo, hi) in drawn["pressure_xlim"].items():
        zone = drawn["contact_zone"].get(pair)
        print(f"  {pair}: pressure drawn from {COORDINATE_WORDS[drawn['along'][pair]]} {lo:g} to {hi:g}, "
              + (f"contact from {zone[0]:g} to {zone[1]:g}" if zone else "no contact"))
        if pair in drawn["friction"]:
            print(f"  {pair}: {drawn['friction'][pair]}, tangential force {drawn['tangential_force'][pair]:.6g}, "
                  + _stick_text(drawn["stick_zones"][pair]))
    if drawn["overview"]:
        nodes = drawn["overview"]["nodes"]
        print(f"  overview: {drawn['overview']['bodies']} bodies, {drawn['overview']['pairs']} pairs; slave nodes "
              + ", ".join(f"{n} {state}" for state, n in nodes.items() if n))
    path = drawn["load_path"]
    if path is not None and "x_label" in path:
        print(f"  load history: {len(path['x'])} steps against the {path['x_label']}")


def _stick_text(zones):
    """ "stick from 0.37 to 0.68" (several zones joined by "and"), or "no node sticks"."""
    if not zones:
        return "no node sticks"
    return "stick " + " and ".join(f"from {lo:g} to {hi:g}" for lo, hi in zones)


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.print_usage(sys.stderr)
        sys.stderr.write(f"error: {message}\n")
        sys.exit(EXIT_USAGE)


def build_parser():
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--url", default=argparse.SUPPRESS,
                        help=f"server URL (default: $CONTACT_URL or {DEFAULT_URL})")
    common.add_argument("--token", default=argparse.SUPPRESS, help="bearer token (default: $CONTACT_TOKEN)")
    common.add_argument("--timeout", type=float, default=argparse.SUPPRESS,
                        help=f"seconds to wait for an answer (default {DEFAULT_TIMEOUT:g}); for watch and "
                             "submit --wait, how long the progress stream may stay silent before it is resumed")
    p = _Parser(prog="contact_client.py", parents=[common],
                description="Client of contactd, the contact solver service. Exit codes: 0 ok, 1 server or job "
                            "error, 2 usage or invalid job, 3 job ended but not SUCCEEDED.")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    def follow_opts(sp):
        sp.add_argument("-q", "--quiet", action="store_true",
                        help="print nothing but errors and the model checks' warnings (no progress, no state "
                             "changes, no end line)")
        sp.add_argument("--events-out", metavar="FILE", help="also save every event as NDJSON (for plot --events)")
        sp.add_argument("--retries", type=int, default=5, help="reconnections in a row before giving up (5)")

    s = sub.add_parser("submit", parents=[common], help="submit a job; prints its id")
    s.add_argument("file", metavar="FILE|-", help="the job JSON ('-' for standard input)")
    s.add_argument("--wait", action="store_true", help="follow the job to its end (exit 3 unless SUCCEEDED)")
    s.add_argument("-o", "--output", metavar="FILE", help="with --wait: download the result to FILE")
    s.add_argument("--xmf", action="store_true", help="with -o: also save the XDMF sidecar next to it")
    s.add_argument("--idempotency-key", metavar="KEY", help="retry-safe submission key")
    follow_opts(s)
    s.set_defaults(func=_cmd_submit)

    s = sub.add_parser("watch", parents=[common], help="follow a job's progress to its end")
    s.add_argument("id")
    follow_opts(s)
    s.set_defaults(func=_cmd_watch)

    s = sub.add_parser("status", parents=[common], help="a job's state, progress and outcome")
    s.add_argument("id")
    s.add_argument("--json", action="store_true", help="the job resource as JSON")
    s.set_defaults(func=_cmd_status)

    s = sub.add_parser("list", parents=[common], help="jobs, newest first")
    s.add_argument("--state", choices=["QUEUED", "RUNNING", "SUCCEEDED", "FAILED", "CANCELLED"],
                   type=str.upper)
    s.add_argument("--page-size", type=int)
    s.add_argument("--page-token")
    s.add_argument("--all", action="store_true", help="follow next_page_token to the last page")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=_cmd_list)

    for name, func, text in (("cancel", _cmd_cancel, "cancel a queued or running job"),
                             ("delete", _cmd_delete, "delete a finished job and its files")):
        s = sub.add_parser(name, parents=[common], help=text)
        s.add_argument("id")
        s.set_defaults(func=func)

    s = sub.add_parser("download", parents=[common], help="download a job's HDF5 result")
    s.add_argument("id")
    s.add_argument("-o", "--output", required=True, metavar="FILE")
    s.add_argument("--xmf", action="store_true", help="also save the XDMF sidecar (FILE with .xmf) for ParaView")
    s.set_defaults(func=_cmd_download)

    s = sub.add_parser("validate", parents=[common], help="validate a job on the server without running it")
    s.add_argument("file", metavar="FILE|-")
    s.add_argument("--normalized", action="store_true", help="print the job with every default filled in")
    s.set_defaults(func=_cmd_validate)

    s = sub.add_parser("plot", parents=[common],
                       help="plot a result: pressure along each pair (with friction also the tangential "
                            "traction, the slip and the stick zone per step), deformed mesh by von Mises stress or "
                            "for many bodies an overview with every joint's state, the load path of a stepped job")
    s.add_argument("file", metavar="FILE.hdf")
    s.add_argument("-o", "--output", required=True, metavar="PNG")
    s.add_argument("--events", metavar="FILE",
                   help="the job's saved events (--events-out, or NDJSON/SSE from curl): one curve per iteration")
    s.add_argument("--warp", type=float, default=None,
                   help="draw the mesh displaced by this factor times the displacement (default: the factor that "
                        "makes the largest displacement 4%% of the mesh, lowered as far as needed, down to 1 or 0, "
                        "so that no closed contact is drawn open by more than a pixel; 0: undeformed)")
    s.add_argument("--xlim", nargs="+", metavar=("LO", "HI"),
                   help="--xlim LO HI: the pressure panels' horizontal range; --xlim full: the whole slave edge "
                        "(default: the contact zone, the nodes with "
                        "pressure > 0, plus 15%% of its width and at least 3 nodes on each side; the mesh is "
                        "drawn whole and zoomed on that stretch)")
    s.add_argument("--along", choices=["auto", "arc", "x", "angle"], default="auto",
                   help="the pressure panels' horizontal coordinate: arc, the arc length along the slave edge "
                        "from its first node, as on the web page; x, the nodes' x; angle, degrees about the centre "
                        "of a circular slave edge; auto (default): angle where the slave edge is circular and the "
                        "contact turns through more than 30 degrees (a ring, a shrink fit), else arc")
    s.add_argument("--pairs", metavar="PATTERN[,PATTERN]", action="append",
                   help="draw the panels of these pairs: names or shell patterns (* ?) of pairs, or of their "
                        "slave or master bodies ('b0_*', base); repeatable (default: every pair, or beyond "
                        "--max-pairs the joints that govern: the highest friction utilisation or eccentricity, the largest force among equals)")
    s.add_argument("--max-pairs", type=int, default=MAX_PAIRS, metavar="N",
                   help=f"at most N pair panels ({MAX_PAIRS}); beyond, the joints that govern (slipping or hinging first)")
    group = s.add_mutually_exclusive_group()
    group.add_argument("--overview", dest="overview", action="store_true", default=None,
                       help="draw all bodies by stress and every joint by state (open, stick, slip) instead of "
                            "the mesh row (the default beyond 8 bodies)")
    group.add_argument("--no-overview", dest="overview", action="store_false",
                       help="draw the mesh row whatever the number of bodies")
    s.add_argument("--title")
    s.set_defaults(func=_cmd_plot)

    s = sub.add_parser("collapse", parents=[common],
                       help="a collapse analysis's result: the verdict, the capacity curve (the multiplier of every "
                            "state that held against a displacement) and the mechanism over the structure")
    s.add_argument("file", metavar="FILE.hdf")
    s.add_argument("-o", "--output", required=True, metavar="PNG")
    s.add_argument("--body", help="the capacity curve follows a node of this body (default: the node that moved "
                                  "most at the last state that held)")
    s.add_argument("--point", nargs=2, type=float, metavar=("X", "Y"),
                   help="with --body: the node of that body nearest (X, Y)")
    s.add_argument("--title")
    s.set_defaults(func=_cmd_collapse)
    return p


def main(argv=None):
    a = build_parser().parse_args(argv)
    try:
        if a.command in ("plot", "collapse"):
            return a.func(None, a)
        c = Client(getattr(a, "url", None), getattr(a, "token", None),
                   getattr(a, "timeout", DEFAULT_TIMEOUT))
        return a.func(c, a)
    except ClientError as exc:
        sys.stdout.flush()
        for line in exc.lines:
            sys.stderr.write(f"error: {line}\n")
        return exc.exit_code
    except KeyboardInterrupt:
        sys.stderr.write("\ninterrupted (the job goes on on the server; cancel it with: cancel ID)\n")
        return 130
    except BrokenPipeError:
        return EXIT_ERROR
    except Exception as exc:  # a bug of the client: one line, the details only on request
        sys.stdout.flush()
        if os.environ.get("CONTACT_CLIENT_DEBUG"):
            traceback.print_exc()
        sys.stderr.write(f"error: internal error of the client: {type(exc).__name__}: {one_line(exc)[:300]} "
                         "(CONTACT_CLIENT_DEBUG=1 shows where)\n")
        return EXIT_ERROR
