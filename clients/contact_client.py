#!/usr/bin/python3
"""contact_client: the command-line and Python client of contactd (docs/server.md, api/openapi.yaml).

Standard-library HTTP only. Reading and plotting results needs Debian's python3-numpy, python3-h5py and
python3-matplotlib (imported only by the commands and functions that need them).

As a command:

    contact_client.py submit api/examples/seed_layers.json --wait -o seed.hdf
    contact_client.py watch ID                # live progress line; reconnects with Last-Event-ID
    contact_client.py status ID | list | cancel ID | delete ID
    contact_client.py download ID -o seed.hdf [--xmf]
    contact_client.py validate my_job.json
    contact_client.py plot seed.hdf -o seed.png [--events events.ndjson]

    --url (CONTACT_URL, default http://127.0.0.1:8080), --token (CONTACT_TOKEN), --timeout (seconds).
    Exit codes: 0 ok; 1 server, connection or job error; 2 usage or bad input (an invalid job included);
    3 the job ended but not SUCCEEDED (submit --wait, watch).

As a module:

    from contact_client import Client, read_result, plot_result
    c = Client("http://127.0.0.1:8080")
    job = c.submit("api/examples/seed_layers.json")
    final = c.wait(job["id"], on_event=print)
    c.download(job["id"], "seed.hdf")
    r = read_result("seed.hdf")                 # numpy arrays
    x, p = r["steps"][-1]["contacts"]["upper.bottom-lower.top"]["x"], ...["pressure"]
"""
import argparse
import errno
import http.client
import json
import os
import shutil
import socket
import sys
import time
import urllib.parse

__all__ = ["Client", "ClientError", "ConnectionFailed", "RequestTimeout", "ApiError", "BadInput",
           "read_result", "read_events", "plot_result", "DEFAULT_URL", "main"]

DEFAULT_URL = "http://127.0.0.1:8080"
DEFAULT_TIMEOUT = 30.0
# A progress stream sends a heartbeat at least every --heartbeat-seconds (15 s by default): a stream silent for
# longer than this is taken as dropped and resumed with Last-Event-ID.
STREAM_READ_TIMEOUT = 60.0
FINAL_STATES = ("SUCCEEDED", "FAILED", "CANCELLED")

EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_JOB = 0, 1, 2, 3


# ---------------------------------------------------------------------------------------------------- errors
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


class ApiError(ClientError):
    """An HTTP error answer. `status` is the HTTP status, `problem` the RFC 9457 problem document (a dict; {}
    if the body was not one), `errors` the list of {"pointer", "message"} of an invalid job."""

    def __init__(self, status, problem, headers=None):
        self.status = status
        self.problem = problem if isinstance(problem, dict) else {}
        self.headers = headers or {}
        self.errors = [e for e in self.problem.get("errors") or [] if isinstance(e, dict)]
        lines = _problem_lines(status, self.problem, self.headers)
        super().__init__(lines[0], lines)
        if self.problem.get("type", "").endswith("/invalid-job"):
            self.exit_code = EXIT_USAGE


def _one_line(text):
    return " ".join(str(text).split())


def _problem_lines(status, problem, headers):
    """ "400 invalid job: /bodies/1/material/nu: nu = 0.5 is outside (-1, 0.5)", one line per error."""
    ptype = problem.get("type") or "about:blank"
    if ptype != "about:blank":
        kind = ptype.rstrip("/").rsplit("/", 1)[-1].replace("-", " ")
    else:
        kind = (problem.get("title") or http.client.responses.get(status, "error")).lower()
    head = f"{status} {kind}"
    errors = [e for e in problem.get("errors") or [] if isinstance(e, dict)]
    if errors:
        return [f"{head}: {e.get('pointer') or '(the whole document)'}: {_one_line(e.get('message', ''))}"
                for e in errors]
    detail = _one_line(problem.get("detail") or "")
    extra = []
    if problem.get("state"):
        extra.append(f"state {problem['state']}")
    if headers.get("retry-after"):
        extra.append(f"retry after {headers['retry-after']} s")
    line = head + (f": {detail}" if detail and detail.lower() != kind else "")
    if extra:
        line += " (" + ", ".join(extra) + ")"
    if status == 401:
        line += " - give the token with --token or CONTACT_TOKEN"
    return [line]


def _connection_error(url, exc):
    """One line for a failure to reach the server."""
    reason = None
    err = getattr(exc, "errno", None)
    if isinstance(exc, ConnectionRefusedError) or err == errno.ECONNREFUSED:
        return ConnectionFailed(f"cannot connect to {url} (connection refused) - is contactd running?")
    if isinstance(exc, socket.gaierror):
        return ConnectionFailed(f"cannot connect to {url} (unknown host: {exc.strerror or exc})")
    if isinstance(exc, (http.client.RemoteDisconnected, ConnectionResetError, BrokenPipeError)):
        reason = "the server closed the connection"
    elif isinstance(exc, OSError) and exc.strerror:
        reason = exc.strerror.lower()
    return ConnectionFailed(f"cannot connect to {url} ({reason or _one_line(exc) or type(exc).__name__})")


# ---------------------------------------------------------------------------------------------------- client
class Client:
    """contactd over HTTP (standard library). Every method returns plain dicts (the API's JSON) and raises a
    ClientError subclass on failure.

    url      base URL (default: CONTACT_URL or http://127.0.0.1:8080); a path prefix is kept (reverse proxy)
    token    bearer token (default: CONTACT_TOKEN)
    timeout  seconds to wait for a connection and for each answer (streams: at least STREAM_READ_TIMEOUT)
    log      callable taking one line, for notes such as a stream being resumed (default: silent)
    """

    def __init__(self, url=None, token=None, timeout=DEFAULT_TIMEOUT, log=None):
        self.url = (url or os.environ.get("CONTACT_URL") or DEFAULT_URL).rstrip("/")
        if "://" not in self.url:
            self.url = "http://" + self.url
        self.token = token if token is not None else (os.environ.get("CONTACT_TOKEN") or None)
        self.timeout = float(timeout)
        self.log = log or (lambda line: None)
        u = urllib.parse.urlsplit(self.url)
        if u.scheme not in ("http", "https") or not u.hostname:
            raise BadInput(f"bad server URL '{self.url}' (expected http://host:port)")
        self._https = u.scheme == "https"
        self._host = u.hostname
        try:
            self._port = u.port or (443 if self._https else 80)
        except ValueError:
            raise BadInput(f"bad port in server URL '{self.url}'") from None
        self._prefix = u.path.rstrip("/")

    # -- plumbing ---------------------------------------------------------------------------------------------
    def _connection(self, timeout):
        cls = http.client.HTTPSConnection if self._https else http.client.HTTPConnection
        return cls(self._host, self._port, timeout=timeout)

    def _headers(self, extra=None):
        # X-Requested-With: contactd refuses a body-less POST or a DELETE without it (its cross-site rule).
        h = {"User-Agent": "contact_client/1", "Accept": "application/json", "X-Requested-With": "contact_client"}
        if self.token:
            h["Authorization"] = "Bearer " + self.token
        h.update(extra or {})
        return h

    def _open(self, method, path, body=None, headers=None, timeout=None):
        """Sends a request; returns (connection, response) with the body unread. HTTP errors raise ApiError."""
        timeout = self.timeout if timeout is None else timeout
        conn = self._connection(timeout)
        try:
            conn.request(method, self._prefix + path, body=body, headers=self._headers(headers))
            resp = conn.getresponse()
        except socket.timeout:
            conn.close()
            raise RequestTimeout(f"no answer from {self.url} within {timeout:g} s (timeout)") from None
        except (OSError, http.client.HTTPException) as exc:
            conn.close()
            raise _connection_error(self.url, exc) from None
        if resp.status >= 400:
            try:
                data = resp.read()
            except (OSError, http.client.HTTPException):
                data = b""
            finally:
                conn.close()
            try:
                problem = json.loads(data.decode("utf-8", "replace")) if data else {}
            except ValueError:
                problem = {"detail": data.decode("utf-8", "replace")[:200]}
            raise ApiError(resp.status, problem, {k.lower(): v for k, v in resp.getheaders()})
        return conn, resp

    def _request(self, method, path, body=None, headers=None, timeout=None):
        """Returns (status, headers dict with lower-case names, body bytes)."""
        conn, resp = self._open(method, path, body, headers, timeout)
        try:
            data = resp.read()
        except socket.timeout:
            raise RequestTimeout(f"no answer from {self.url} within {self.timeout:g} s (timeout)") from None
        except (OSError, http.client.HTTPException) as exc:
            raise _connection_error(self.url, exc) from None
        finally:
            conn.close()
        return resp.status, {k.lower(): v for k, v in resp.getheaders()}, data

    def _json(self, method, path, body=None, headers=None):
        status, _, data = self._request(method, path, body, headers)
        if status == 204 or not data:
            return {}
        try:
            return json.loads(data)
        except ValueError:
            raise ClientError(f"the server's answer to {method} {path} is not JSON: {data[:100]!r}") from None

    @staticmethod
    def _job_body(job):
        """The bytes to send for a job: a dict is serialised; a path (str or os.PathLike) is read and sent
        unchanged (after checking that it is JSON); bytes are sent as they are; '-' reads standard input."""
        if isinstance(job, dict):
            return json.dumps(job).encode()
        if isinstance(job, (bytes, bytearray)):
            data, where = bytes(job), "the job"
        else:
            where = os.fspath(job)
            try:
                if where == "-":
                    data, where = sys.stdin.buffer.read(), "standard input"
                else:
                    with open(where, "rb") as f:
                        data = f.read()
            except OSError as exc:
                raise BadInput(f"cannot read {where}: {exc.strerror or exc}") from None
        try:
            json.loads(data.decode("utf-8"))
        except UnicodeDecodeError as exc:
            raise BadInput(f"{where}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
        except ValueError as exc:
            raise BadInput(f"{where}: not JSON: {exc}") from None
        return data

    @staticmethod
    def _check_id(job_id):
        job_id = str(job_id).strip()
        if not job_id or "/" in job_id or "?" in job_id or "#" in job_id:
            raise BadInput(f"'{job_id}' is not a job id")
        return urllib.parse.quote(job_id)

    # -- the API ----------------------------------------------------------------------------------------------
    def submit(self, job, idempotency_key=None):
        """Submits a job (a dict, a path to a JSON file, JSON bytes, or '-' for standard input); returns the job
        resource (state QUEUED, or whatever an idempotent replay finds). An invalid job raises ApiError with
        .errors (exit code 2)."""
        headers = {"Content-Type": "application/json"}
        if idempotency_key:
            headers["Idempotency-Key"] = str(idempotency_key)
        return self._json("POST", "/v1/jobs", self._job_body(job), headers)

    def validate(self, job):
        """Validates a job without running it: {"valid": true, "dofs": ..., "bodies": [...], "normalized": {...}};
        an invalid job raises ApiError with .errors."""
        return self._json("POST", "/v1/validate", self._job_body(job), {"Content-Type": "application/json"})

    def status(self, job_id):
        """The job resource (state, progress, timings, outcome, links)."""
        return self._json("GET", f"/v1/jobs/{self._check_id(job_id)}")

    def list(self, state=None, page_size=None, page_token=None, all_pages=False):
        """One page of jobs, newest first: {"jobs": [...], "next_page_token": "..."}; with all_pages=True every
        page is fetched and the jobs are concatenated (next_page_token is then "")."""
        jobs = []
        while True:
            query = {k: v for k, v in (("state", state), ("page_size", page_size), ("page_token", page_token))
                     if v not in (None, "")}
            path = "/v1/jobs" + ("?" + urllib.parse.urlencode(query) if query else "")
            page = self._json("GET", path)
            jobs.extend(page.get("jobs", []))
            page_token = page.get("next_page_token") or ""
            if not all_pages or not page_token:
                return {"jobs": jobs, "next_page_token": page_token}

    def cancel(self, job_id):
        """Cancels a queued or running job; returns the job resource (a running job stops within one
        iteration: follow it with wait())."""
        return self._json("POST", f"/v1/jobs/{self._check_id(job_id)}/cancel", b"", {"Content-Length": "0"})

    def delete(self, job_id):
        """Deletes a finished job and its files (409 while QUEUED or RUNNING)."""
        # contactd itself waits for a job whose `end` event is still being written, so a DELETE right after
        # `end` succeeds without retries here.
        self._request("DELETE", f"/v1/jobs/{self._check_id(job_id)}")

    def health(self):
        return self._json("GET", "/healthz")

    def schema(self):
        return self._json("GET", "/v1/schema")

    def events(self, job_id, last_event_id=None, max_retries=5, read_timeout=None):
        """Iterates over the job's progress events (dicts with seq, type, time, ...) from the first one (or after
        last_event_id) to the `end` event included. If the connection drops, or the stream closes without
        `end` (a server shutdown), it reconnects with Last-Event-ID after a backoff, at most max_retries times in
        a row; events are never repeated or skipped."""
        path = f"/v1/jobs/{self._check_id(job_id)}/events"
        read_timeout = max(self.timeout, STREAM_READ_TIMEOUT) if read_timeout is None else read_timeout
        last = None if last_event_id is None else int(last_event_id)
        failures = 0
        while True:
            headers = {"Accept": "text/event-stream", "Cache-Control": "no-cache"}
            if last is not None:
                headers["Last-Event-ID"] = str(last)
            problem, wait = None, None
            try:
                conn, resp = self._open("GET", path, headers=headers, timeout=read_timeout)
                try:
                    for event in _read_sse(resp):
                        seq = event.get("seq")
                        if isinstance(seq, int):
                            if last is not None and seq <= last:
                                continue  # never repeat an event
                            last = seq
                        failures = 0
                        yield event
                        if event.get("type") == "end":
                            return
                    problem = "the stream closed before the job's end"
                finally:
                    conn.close()
            except ApiError as exc:
                if exc.status not in (502, 503, 504):
                    raise
                problem, wait = exc.lines[0], _retry_after(exc.headers)
            except (ConnectionFailed, RequestTimeout) as exc:
                problem = exc.lines[0]
            except socket.timeout:
                problem = f"no event or heartbeat for {read_timeout:g} s"
            except (OSError, http.client.HTTPException) as exc:
                problem = f"connection lost ({_one_line(exc) or type(exc).__name__})"
            failures += 1
            if failures > max_retries:
                raise ConnectionFailed(f"progress stream of {job_id} lost after {max_retries} reconnections: "
                                       f"{problem}")
            delay = min(0.5 * 2 ** (failures - 1), 10.0)
            if wait:
                delay = max(delay, min(wait, 30.0))
            where = f"after event {last}" if last is not None else "from the start"
            self.log(f"{problem}; reconnecting in {delay:g} s ({failures}/{max_retries}), resuming {where}")
            time.sleep(delay)

    def wait(self, job_id, on_event=None, max_retries=5):
        """Follows the job's events to its end (on_event(event) is called for each) and returns the final job
        resource."""
        for event in self.events(job_id, max_retries=max_retries):
            if on_event:
                on_event(event)
        return self.status(job_id)

    def download(self, job_id, path, xmf=False):
        """Downloads the HDF5 result to path (written to path + '.part' then renamed). With xmf=True the XDMF
        sidecar is saved next to it (same name, .xmf) with its data references renamed to the file's name.
        Returns path."""
        base = f"/v1/jobs/{self._check_id(job_id)}"
        path = os.fspath(path)
        _download_to(self, base + "/result", path)
        if xmf:
            _, _, text = self._request("GET", base + "/result.xmf")
            name = os.path.basename(path)
            text = text.decode("utf-8").replace('result.hdf:/', name + ":/")
            side = os.path.splitext(path)[0] + ".xmf"
            with open(side + ".part", "w", encoding="utf-8") as f:
                f.write(text)
            os.replace(side + ".part", side)
        return path


def _retry_after(headers):
    try:
        return float(headers.get("retry-after", ""))
    except ValueError:
        return None


def _download_to(client, api_path, path):
    conn, resp = client._open("GET", api_path)
    tmp = path + ".part"
    try:
        expected = resp.getheader("Content-Length")
        size = 0
        with open(tmp, "wb") as f:
            while True:
                chunk = resp.read(1 << 16)
                if not chunk:
                    break
                f.write(chunk)
                size += len(chunk)
        if expected is not None and size != int(expected):
            raise ConnectionFailed(f"download of {api_path} cut short ({size} of {expected} bytes)")
        os.replace(tmp, path)
    except socket.timeout:
        raise RequestTimeout(f"download from {client.url} stalled for {client.timeout:g} s (timeout)") from None
    except OSError as exc:
        if getattr(exc, "filename", None):
            raise ClientError(f"cannot write {exc.filename}: {exc.strerror}") from None
        raise _connection_error(client.url, exc) from None
    finally:
        conn.close()
        if os.path.exists(tmp):
            os.remove(tmp)


def _read_sse(resp):
    """Server-Sent Events from an http.client response: yields each event's data as a dict (the SSE `id` and
    `event` fields repeat the object's seq and type). Comments (heartbeats) are skipped."""
    data, event_type = [], None
    while True:
        line = resp.readline()
        if not line:
            return
        line = line.decode("utf-8", "replace").rstrip("\r\n")
        if line == "":
            if data:
                obj = json.loads("\n".join(data))
                if isinstance(obj, dict):
                    obj.setdefault("type", event_type)
                    yield obj
            data, event_type = [], None
            continue
        if line.startswith(":"):
            continue
        key, _, value = line.partition(":")
        value = value[1:] if value.startswith(" ") else value
        if key == "data":
            data.append(value)
        elif key == "event":
            event_type = value


def read_events(path):
    """Events saved as NDJSON (watch --events-out, or curl -H 'Accept: application/x-ndjson') or as SSE text
    (curl -N): a list of dicts."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    events = []
    if any(line.startswith(("data:", "event:", "id:")) for line in text.splitlines()[:20]):
        for line in text.splitlines():
            if line.startswith("data:"):
                events.append(json.loads(line[5:].strip()))
    else:
        for line in text.splitlines():
            if line.strip():
                events.append(json.loads(line))
    return events


# ---------------------------------------------------------------------------------------------------- results
def read_result(path):
    """Reads a result file (docs/results-format.md) into numpy arrays:

    {"attrs": {...root attributes...},
     "body_names": [...], "pair_names": [...],                        # of the final step
     "steps": [{"step": k, "iteration": i,
                "bodies": {name: {"points", "quads", "level", "von_mises", "displacement", "stress_cell", ...}},
                "contacts": {pair: {"position", "x", "arc_length", "pressure", "gap", "normal_gap", "active",
                                    "attrs": {...}}}}, ...],                   # in step order; the last is final
     "history": {"iterations": {"iteration", "fixed_point_residual", "max_pressure" (I, P), ...,
                                "body_names", "pair_names"},
                 "steps": {...}}}
    """
    import h5py
    import numpy as np

    def attr(value):
        if isinstance(value, bytes):
            return value.decode()
        if isinstance(value, np.ndarray):
            if value.dtype.kind in "OSU":
                return [v.decode() if isinstance(v, bytes) else str(v) for v in value.tolist()]
            return value
        if isinstance(value, np.generic):
            return value.item()
        return value

    def group(g):
        out = {}
        for key, item in g.items():
            if isinstance(item, h5py.Dataset):
                if item.dtype.kind in "OS" or h5py.check_string_dtype(item.dtype) is not None:
                    v = item.asstr()[()]
                    out[key] = v if isinstance(v, str) else [str(s) for s in np.asarray(v).tolist()]
                else:
                    out[key] = item[()]
        return out

    result = {"path": os.fspath(path)}
    with h5py.File(path, "r") as f:
        result["attrs"] = {k: attr(v) for k, v in f.attrs.items()}
        if result["attrs"].get("format") != "contact-ddm-result":
            raise BadInput(f"{path}: not a contact-ddm result file")
        if int(result["attrs"].get("format_version", 0)) > 1:
            raise BadInput(f"{path}: result format version {result['attrs']['format_version']} is newer than "
                           "this client knows (1)")
        steps = []
        if "steps" in f:
            count = int(f["steps"].attrs.get("count", len(f["steps"])))
            for k in range(count):
                g = f["steps"][str(k)]
                body_names = attr(g.attrs.get("body_names", np.array(list(g["bodies"].keys()), dtype=object)))
                pair_names = attr(g.attrs.get("pair_names", np.array(list(g["contacts"].keys()), dtype=object)))
                step = {"step": k, "iteration": int(g.attrs.get("iteration", 0)), "bodies": {}, "contacts": {},
                        "body_names": list(body_names), "pair_names": list(pair_names)}
                for name in body_names:
                    step["bodies"][name] = group(g["bodies"][name])
                for name in pair_names:
                    c = g["contacts"][name]
                    d = group(c)
                    d["attrs"] = {a: attr(v) for a, v in c.attrs.items()}
                    if "position" in d and len(d["position"]):
                        d["x"] = d["position"][:, 0]
                    step["contacts"][name] = d
                steps.append(step)
        result["steps"] = steps
        result["body_names"] = steps[-1]["body_names"] if steps else []
        result["pair_names"] = steps[-1]["pair_names"] if steps else []
        history = {}
        for name in ("iterations", "steps"):
            if "history" in f and name in f["history"]:
                h = f["history"][name]
                history[name] = group(h)
                for a, v in h.attrs.items():
                    history[name][a] = attr(v)
        result["history"] = history
        if "input" in f and "job" in f["input"]:
            try:
                result["job"] = json.loads(f["input/job"].asstr()[()])
            except ValueError:
                pass
    return result


def _spread(n, k):
    """At most k indices of range(n), evenly spread, the first and the last included."""
    if n <= k:
        return list(range(n))
    return sorted({round(i * (n - 1) / (k - 1)) for i in range(k)})


def plot_result(result, png, events=None, warp=0.0, title=None, max_curves=12):
    """Draws one figure of 1000 x 800 pixels (10 x 8 inches at 100 dpi) into png:

    top: the contact pressure against x along each pair (one panel per pair), one curve per adaptive step;
         with a single step, the pressure profile of each iteration when `events` (the job's events, a list of
         dicts or a path to saved events) are given (at most max_curves of them, spread over the run), and the
         final profile from the file;
    bottom: each body's final mesh, cells coloured by von Mises stress, edges drawn (refinement shows as
         smaller cells), one colour bar. warp > 0 draws the mesh displaced by warp x displacement.

    result is a path or the dict of read_result(). Returns png."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.cm
    import matplotlib.colors
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.collections import PolyCollection

    if not isinstance(result, dict):
        result = read_result(result)
    if isinstance(events, (str, os.PathLike)):
        events = read_events(events)
    steps = result["steps"]
    if not steps:
        raise BadInput(f"{result.get('path', 'the result')}: no step in the file (the solve failed before its "
                       "first iteration)")
    final = steps[-1]
    pair_names = final["pair_names"]
    attrs = result["attrs"]

    fig = plt.figure(figsize=(10, 8), dpi=100)
    npairs = max(1, len(pair_names))
    gs = fig.add_gridspec(2, npairs, height_ratios=[1.0, 1.25], left=0.08, right=0.92, top=0.92, bottom=0.07,
                          hspace=0.32, wspace=0.4)
    name = attrs.get("name") or os.path.basename(result.get("path", ""))
    stop = attrs.get("stop_reason", "")
    fig.suptitle(title or f"{name}: {attrs.get('iterations', '?')} iterations, {stop}, "
                 f"{len(steps)} step{'s' if len(steps) != 1 else ''}", fontsize=12)

    iteration_profiles = {}
    if len(steps) == 1 and events:
        for e in events:
            if e.get("type") == "iteration":
                for p in e.get("pairs", []):
                    if p.get("positions") and p.get("pressures"):
                        iteration_profiles.setdefault(p["name"], []).append(
                            (e["iteration"], np.asarray(p["positions"], float), np.asarray(p["pressures"], float)))

    for j, pair in enumerate(pair_names or [None]):
        ax = fig.add_subplot(gs[0, j])
        if pair is None:
            ax.text(0.5, 0.5, "no contact pair", ha="center", va="center", transform=ax.transAxes)
            continue
        c_final = final["contacts"][pair]
        cmap = plt.get_cmap("viridis")
        # (number, x, pressure, extra label) per curve, coloured by its place in the run.
        curves, what = [], "step"
        if len(steps) > 1:
            for k in _spread(len(steps), max_curves):
                c = steps[k]["contacts"].get(pair)
                if c is not None and "x" in c:
                    curves.append((k, c["x"], c["pressure"], f" (iter {steps[k]['iteration']}, {len(c['x'])} nodes)"))
            span = (0, len(steps) - 1)
        else:
            profiles = iteration_profiles.get(pair, [])
            what = "iteration"
            arc, xs = c_final.get("arc_length"), c_final.get("x")
            if xs is None or arc is None or len(arc) < 2:
                arc = None
            for i in _spread(len(profiles), max_curves):
                it, sv, pv = profiles[i]
                curves.append((it, np.interp(sv, arc, xs) if arc is not None else sv, pv, ""))
            span = (profiles[0][0], profiles[-1][0]) if profiles else (0, 1)
        norm = matplotlib.colors.Normalize(vmin=span[0], vmax=max(span[1], span[0] + 1))
        labelled = len(curves) <= 6
        for number, x, pv, extra in curves:
            ax.plot(x, pv, color=cmap(norm(number)), lw=1.0, marker="." if len(x) < 80 else None, ms=2.5,
                    label=f"{what} {number}{extra}" if labelled else None)
        if len(curves) > 1 and not labelled:
            sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
            fig.colorbar(sm, ax=ax, fraction=0.05, pad=0.02).set_label(what, fontsize=8)
        if "x" in c_final:
            ax.plot(c_final["x"], c_final["pressure"], color="black", lw=1.5, ls=(0, (5, 3)) if curves else "-",
                    label=f"final (iter {final['iteration']}, from the file)", zorder=5)
        ax.set_xlabel("x of the slave edge node")
        ax.set_ylabel("contact pressure")
        total = len(steps) if what == "step" else len(iteration_profiles.get(pair, []))
        shown = f"{len(curves)} of {total}" if len(curves) < total else f"all {total}"
        ax.set_title(pair + (f" ({shown} {what}s)" if len(curves) > 1 else ""), fontsize=10)
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="best", framealpha=0.8)

    ax = fig.add_subplot(gs[1, :])
    polys, values, levels = [], [], []
    for body in final["body_names"]:
        b = final["bodies"][body]
        xy = b["points"]
        if warp and "displacement" in b and len(b["displacement"]) == len(xy):
            xy = xy + warp * b["displacement"]
        quads = b["quads"]
        polys.append(xy[quads])
        vm = b.get("von_mises")
        values.append(vm if vm is not None and len(vm) == len(quads) else np.full(len(quads), np.nan))
        lv = b.get("level")
        levels.append((body, len(quads), int(lv.max()) if lv is not None and len(lv) else 0))
    for body, xy in zip(final["body_names"], polys):
        if len(xy):
            flat = xy.reshape(-1, 2)
            centre = (flat.min(axis=0) + flat.max(axis=0)) / 2
            ax.text(centre[0], centre[1], body, ha="center", va="center", fontsize=9, zorder=5,
                    bbox=dict(boxstyle="round,pad=0.2", facecolor="white", alpha=0.75, edgecolor="none"))
    verts = np.concatenate(polys) if polys else np.zeros((0, 4, 2))
    vals = np.concatenate(values) if values else np.zeros(0)
    # Edges thin out on fine meshes so that the colours still show.
    lw = float(np.clip(0.3 * np.sqrt(1000.0 / max(1, len(verts))), 0.05, 0.3))
    pc = PolyCollection(verts, array=vals, cmap="viridis", edgecolors=(0, 0, 0, 0.8), linewidths=lw)
    ax.add_collection(pc)
    if len(verts):
        lo, hi = verts.reshape(-1, 2).min(axis=0), verts.reshape(-1, 2).max(axis=0)
        pad = 0.02 * max(hi - lo)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal", adjustable="datalim")  # the panel keeps its size; the shorter side's range grows
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title("final mesh" + (f" (displacement x {warp:g})" if warp else "") + ": "
                 + ", ".join(f"{b} {m} cells" + (f", refinement level <= {lv}" if lv else "")
                             for b, m, lv in levels), fontsize=10)
    cb = fig.colorbar(pc, ax=ax, fraction=0.04, pad=0.02)
    cb.set_label("von Mises stress")
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return png


# ---------------------------------------------------------------------------------------------------- command
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
            msg = f": {e['message']}" if e.get("message") else ""
            self._line(f"state {e.get('state')}{msg}")
        elif t == "step":
            bodies = ", ".join(f"{b.get('name')} {b.get('elements')} cells" for b in e.get("bodies", []))
            if self.pending_text:
                self._live(self.pending_text, force=True)
            self._line(f"step {e.get('step')} at iteration {e.get('iteration')}: {bodies}")
        elif t == "end":
            if self.pending_text:
                self._live(self.pending_text, force=True)
            if self.tty and self.pending:
                self.out.write("\n")
                self.pending = ""
            conv = e.get("stop_reason") or "?"
            if conv != "converged" and e.get("state") == "SUCCEEDED":
                conv += ", not converged"
            msg = f": {e['message']}" if e.get("message") else ""
            self.out.write(f"end {e.get('state')} ({conv}) after {e.get('iterations')} "
                           f"iterations, {e.get('solve_seconds', 0):.3g} s{msg}\n")
            self.out.flush()


def format_iteration(e):
    """ "iter 12  paper 1.23e-03  residual 2.22e-02  dofs upper 528 lower 528  | pair: force 140.9 p_max 166.4" """
    parts = [f"iter {e.get('iteration', 0):5d}",
             f"paper {e.get('paper_criterion', float('nan')):.3e}",
             f"residual {e.get('fixed_point_residual', float('nan')):.3e}"]
    bodies = e.get("bodies") or []
    if bodies:
        parts.append("dofs " + " ".join(f"{b.get('name')} {b.get('dofs')}" for b in bodies))
    for p in e.get("pairs") or []:
        parts.append(f"| {p.get('name')}: force {p.get('force', 0):.5g} p_max {p.get('max_pressure', 0):.5g}")
    if e.get("elapsed_seconds") is not None:
        parts.append(f"{e['elapsed_seconds']:.2f}s")
    note = str(e.get("note") or "").strip().rstrip(";").strip()
    if note:
        parts.append(f"({note})")
    return "  ".join(parts)


def compact_iterations(e):
    """The terminal's live line, in forms from the fullest to the shortest (the first that fits is drawn):
    "iter 12  paper 1.23e-03  res 2.22e-02  force 140.9  p_max 166.4  dofs 528/528  0.05s" (several pairs or
    bodies: values joined by '/', in the order of the job)."""
    pairs, bodies = e.get("pairs") or [], e.get("bodies") or []
    parts = [f"iter {e.get('iteration', 0)}",
             f"paper {e.get('paper_criterion', float('nan')):.2e}",
             f"res {e.get('fixed_point_residual', float('nan')):.2e}"]
    if pairs:
        parts.append("force " + "/".join(f"{p.get('force', 0):.5g}" for p in pairs))
        parts.append("p_max " + "/".join(f"{p.get('max_pressure', 0):.5g}" for p in pairs))
    if bodies:
        parts.append("dofs " + "/".join(str(b.get("dofs")) for b in bodies))
    elapsed = [f"{e['elapsed_seconds']:.1f}s"] if e.get("elapsed_seconds") is not None else []
    return ["  ".join(parts + elapsed), " ".join(parts + elapsed), " ".join(parts)]


def _print_job(job, out):
    prog = job.get("progress") or {}
    rows = [("id", job.get("id")), ("name", job.get("name")), ("state", job.get("state"))]
    if job.get("queue_position") is not None:
        rows.append(("queue position", job["queue_position"]))
    rows.append(("iterations", job.get("iterations")))
    if prog:
        rows.append(("progress", format_iteration(prog)))
    if job.get("stop_reason"):
        rows.append(("stop", f"{job['stop_reason']} (converged: {str(job.get('converged')).lower()})"))
    if job.get("message"):
        rows.append(("message", _one_line(job["message"])))
    if job.get("error"):
        rows.append(("error", _one_line(job["error"].get("message", ""))))
    t = job.get("timings") or {}
    if t:
        rows.append(("timings", ", ".join(f"{k.replace('_seconds', '')} {v:.3g} s" for k, v in t.items()
                                          if isinstance(v, (int, float)))))
    for key in ("created", "started", "finished"):
        if job.get(key):
            rows.append((key, job[key]))
    rows.append(("result", "available" if job.get("result_available") else "none"))
    for k, v in rows:
        out.write(f"{k + ':':16}{v}\n")


def _cmd_submit(c, a):
    if (a.output or a.events_out or a.xmf) and not a.wait:
        raise BadInput("-o, --xmf and --events-out need --wait")
    job = c.submit(a.file, idempotency_key=a.idempotency_key)
    print(job["id"], flush=True)
    if not a.wait:
        return EXIT_OK
    return _follow(c, job["id"], a)


def _follow(c, job_id, a):
    out = None
    try:
        if a.events_out:
            try:
                out = open(a.events_out, "w", encoding="utf-8")
            except OSError as exc:
                raise BadInput(f"cannot write {a.events_out}: {exc.strerror}") from None
        progress = Progress(quiet=a.quiet, events_out=out)
        c.log = progress.note
        end = None
        for e in c.events(job_id, max_retries=a.retries):
            progress(e)
            if e.get("type") == "end":
                end = e
    finally:
        if out:
            out.close()
    state = end.get("state") if end else None
    if getattr(a, "output", None):
        if end and end.get("result_available"):
            c.download(job_id, a.output, xmf=getattr(a, "xmf", False))
            sys.stderr.write(f"wrote {a.output} ({os.path.getsize(a.output)} bytes)\n")
        else:
            sys.stderr.write(f"no result to download (job {state})\n")
    if state != "SUCCEEDED":
        sys.stderr.write(f"job {job_id} ended {state}\n")
        return EXIT_JOB
    return EXIT_OK


def _cmd_watch(c, a):
    return _follow(c, a.id, a)


def _cmd_status(c, a):
    job = c.status(a.id)
    if a.json:
        print(json.dumps(job, indent=2))
    else:
        _print_job(job, sys.stdout)
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
        outcome = j.get("stop_reason") or (f"queue {j['queue_position']}" if j.get("queue_position") else "")
        print(f"{j.get('id')}  {j.get('state', ''):9}  {j.get('iterations', 0):>7}  {outcome:14}  "
              f"{j.get('created', '')}  {j.get('name', '')}")
    if page.get("next_page_token"):
        print(f"more: --page-token {page['next_page_token']}")
    return EXIT_OK


def _cmd_cancel(c, a):
    job = c.cancel(a.id)
    if job.get("state") == "CANCELLED":
        print(f"{job.get('id', a.id)} CANCELLED")
    else:
        print(f"{job.get('id', a.id)} {job.get('state')}: cancellation requested (stops within one iteration)")
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
    bodies = ", ".join(f"{b.get('name')} {b.get('elements')} cells {b.get('nodes')} nodes"
                       for b in r.get("bodies", []))
    print(f"valid: {r.get('name')}: {r.get('dofs')} dofs ({bodies}), {r.get('contacts')} contact pair(s)")
    if a.normalized:
        print(json.dumps(r.get("normalized"), indent=2))
    return EXIT_OK


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
    try:
        result = read_result(a.file)
    except OSError as exc:
        raise BadInput(f"cannot read {a.file}: {_one_line(exc)}") from None
    events = None
    if a.events:
        try:
            events = read_events(a.events)
        except (OSError, ValueError) as exc:
            raise BadInput(f"cannot read events from {a.events}: {_one_line(exc)}") from None
    plot_result(result, a.output, events=events, warp=a.warp, title=a.title)
    print(f"wrote {a.output} (1000 x 800 px)")
    return EXIT_OK


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
                        help=f"seconds to wait for an answer (default {DEFAULT_TIMEOUT:g})")
    p = _Parser(prog="contact_client.py", parents=[common],
                description="Client of contactd, the contact solver service. Exit codes: 0 ok, 1 server or job "
                            "error, 2 usage or invalid job, 3 job ended but not SUCCEEDED.")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    def follow_opts(sp):
        sp.add_argument("-q", "--quiet", action="store_true",
                        help="no iteration lines when not on a terminal (state changes and the end only)")
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
                       help="plot a result: pressure along each pair, final mesh by von Mises stress")
    s.add_argument("file", metavar="FILE.hdf")
    s.add_argument("-o", "--output", required=True, metavar="PNG")
    s.add_argument("--events", metavar="FILE",
                   help="the job's saved events (--events-out, or NDJSON/SSE from curl): one curve per iteration")
    s.add_argument("--warp", type=float, default=0.0, help="draw the mesh displaced by this factor")
    s.add_argument("--title")
    s.set_defaults(func=_cmd_plot)
    return p


def main(argv=None):
    a = build_parser().parse_args(argv)
    try:
        if a.command == "plot":
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


if __name__ == "__main__":
    sys.exit(main())
