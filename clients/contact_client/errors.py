"""The client's errors: each carries the one-line messages to show and the exit code of the command. Nothing a
server or a proxy sends can make them fail: every field of a problem document is checked before it is used."""
import errno
import http.client
import re
import socket

EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_JOB = 0, 1, 2, 3


class ClientError(Exception):
    """Every error of the client. `lines` are the one-line messages to show (without the "error: " prefix);
    `exit_code` is what the command exits with."""
    exit_code = EXIT_ERROR

    def __init__(self, message, lines=None):
        super().__init__(message)
        self.lines = list(lines) if lines else [message]


class BadInput(ClientError):
    """A job file that cannot be read or is not JSON, a bad argument (exit 2)."""
    exit_code = EXIT_USAGE


class ConnectionFailed(ClientError):
    """The server could not be reached (refused, unknown host, reset before an answer)."""


class RequestTimeout(ClientError):
    """The server did not answer within the timeout."""


class BadAnswer(ClientError):
    """An answer that is not what the API defines: a redirect, a body that is not JSON or lacks a field, a download
    that is not an HDF5 file, a broken stream (often a proxy's or another server's page)."""


class ApiError(ClientError):
    """An HTTP error answer. `status` is the HTTP status, `problem` the RFC 9457 problem document (a dict; {}
    if the body was not one), `errors` the list of {"pointer", "message"} of an invalid job."""

    def __init__(self, status, problem, headers=None):
        self.status = status
        self.problem = problem if isinstance(problem, dict) else {}
        self.headers = headers or {}
        errors = self.problem.get("errors")
        self.errors = [e for e in errors if isinstance(e, dict)] if isinstance(errors, list) else []
        lines = problem_lines(status, self.problem, self.headers)
        super().__init__(lines[0], lines)
        if text(self.problem.get("type")).endswith("/invalid-job"):
            self.exit_code = EXIT_USAGE


def text(value, limit=2000):
    """A value from an answer as text for a message: strings as they are, anything else (None: "") as JSON-ish
    text, cut at `limit` characters."""
    if value is None:
        return ""
    s = value if isinstance(value, str) else repr(value)
    return s if len(s) <= limit else s[:limit] + "..."


# Control characters (C0, DEL, C1) and the bidirectional overrides: what a terminal obeys rather than shows.
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")


def printable(s):
    """The text with each control character written as an escape (ESC as \\x1b, U+202E as \\u202e): nothing
    a server sends reaches the terminal as a command."""
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), s)


def one_line(value):
    """A value from an answer as one line of printable text: runs of white space become one space, any other
    control character is escaped. Everything the client prints from a server goes through here."""
    return printable(" ".join(text(value).split()))


def problem_lines(status, problem, headers):
    """ "400 invalid job: /bodies/1/material/nu: nu = 0.5 is outside (-1, 0.5)", one line per error."""
    ptype = text(problem.get("type")) or "about:blank"
    if ptype != "about:blank":
        kind = ptype.rstrip("/").rsplit("/", 1)[-1].replace("-", " ")
    else:
        kind = (text(problem.get("title")) or http.client.responses.get(status, "error")).lower()
    kind = one_line(kind)[:80]
    head = f"{status} {kind}"
    errors = problem.get("errors")
    errors = [e for e in errors if isinstance(e, dict)] if isinstance(errors, list) else []
    if errors:
        shown = [f"{head}: {one_line(e.get('pointer')) or '(the whole document)'}: {one_line(e.get('message'))}"
                 for e in errors[:200]]
        if len(errors) > 200:
            shown.append(f"{head}: and {len(errors) - 200} more")
        return shown
    detail = one_line(problem.get("detail"))[:1000]
    extra = []
    if problem.get("state"):
        extra.append(f"state {one_line(problem['state'])[:40]}")
    retry = headers.get("retry-after") if isinstance(headers, dict) else None
    if retry:
        extra.append(f"retry after {one_line(retry)[:20]} s")
    line = head + (f": {detail}" if detail and detail.lower() != kind else "")
    if extra:
        line += " (" + ", ".join(extra) + ")"
    if status == 401:
        line += " - give the token with --token or CONTACT_TOKEN"
    return [line]


def connection_error(url, exc):
    """One line for a failure to reach the server."""
    reason = None
    err = getattr(exc, "errno", None)
    if isinstance(exc, ConnectionRefusedError) or err == errno.ECONNREFUSED:
        return ConnectionFailed(f"cannot connect to {url} (connection refused) - is contactd running?")
    if isinstance(exc, socket.gaierror):
        return ConnectionFailed(f"cannot connect to {url} (unknown host: {exc.strerror or exc})")
    if isinstance(exc, (http.client.RemoteDisconnected, ConnectionResetError, BrokenPipeError)):
        reason = "the server closed the connection"
    elif isinstance(exc, http.client.HTTPException):
        reason = f"the server's answer is not valid HTTP: {type(exc).__name__} {one_line(exc)[:100]}".rstrip()
    elif isinstance(exc, OSError) and exc.strerror:
        reason = exc.strerror.lower()
    return ConnectionFailed(f"cannot connect to {url} ({reason or one_line(exc)[:200] or type(exc).__name__})")
