"""Client: contactd over HTTP with the standard library. Every answer is checked before it is used: its status
(a redirect is not success), its media type, the JSON and the fields the caller needs; a download must be an HDF5
file of the announced length. Anything else is a ClientError with one line saying what came back."""
import http.client
import json
import os
import re
import socket
import sys
import time
import urllib.parse

from .errors import (ApiError, BadAnswer, BadInput, ClientError, ConnectionFailed, RequestTimeout,
                     connection_error, one_line)
from .sse import read_sse

DEFAULT_URL = "http://127.0.0.1:8080"
DEFAULT_TIMEOUT = 30.0
# A progress stream sends a heartbeat at least every --heartbeat-seconds (15 s by default): a stream silent for
# longer than this is taken as dropped and resumed with Last-Event-ID (unless the caller gives its own timeout).
STREAM_READ_TIMEOUT = 60.0
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
MAX_ANSWER_BYTES = 64 << 20  # a JSON answer larger than this is not one of contactd's


def content_length(resp):
    """The Content-Length of a response as an int, or None (absent or not a number)."""
    value = resp.getheader("Content-Length")
    if value is None:
        return None
    value = value.strip()
    return int(value) if value.isdigit() and len(value) < 19 else None


def media_type(headers):
    return (headers.get("content-type") or "").split(";")[0].strip().lower()


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

    def _timeout_error(self, timeout):
        return RequestTimeout(f"no answer from {self.url} within {timeout:g} s (timeout)")

    def _open(self, method, path, body=None, headers=None, timeout=None):
        """Sends a request; returns (connection, response) with the body unread. An error status raises ApiError,
        a redirect or an informational status BadAnswer."""
        timeout = self.timeout if timeout is None else timeout
        conn = self._connection(timeout)
        try:
            conn.request(method, self._prefix + path, body=body, headers=self._headers(headers))
            resp = conn.getresponse()
        except socket.timeout:
            conn.close()
            raise self._timeout_error(timeout) from None
        except (OSError, http.client.HTTPException, ValueError) as exc:
            conn.close()
            raise connection_error(self.url, exc) from None
        if 200 <= resp.status < 300:
            return conn, resp
        headers_lower = {k.lower(): v for k, v in resp.getheaders()}
        try:
            data = self._read(resp, limit=1 << 20, timeout=timeout) if resp.status >= 400 else b""
        except ClientError:
            data = b""
        finally:
            conn.close()
        if 300 <= resp.status < 400:
            where = headers_lower.get("location")
            raise BadAnswer(f"{method} {path}: the server answered {resp.status} {one_line(resp.reason)[:60]}"
                            + (f" (to {one_line(where)[:200]})" if where else "")
                            + "; contactd never redirects: is the URL right, or is a proxy in the way?")
        if resp.status < 200:
            raise BadAnswer(f"{method} {path}: unexpected status {resp.status}")
        try:
            problem = json.loads(data.decode("utf-8", "replace")) if data else {}
        except (ValueError, RecursionError):
            problem = {"detail": data.decode("utf-8", "replace")[:200]}
        raise ApiError(resp.status, problem, headers_lower)

    def _read(self, resp, limit=MAX_ANSWER_BYTES, timeout=None):
        """The body of a response, at most `limit` bytes; transport failures become ClientErrors."""
        try:
            data = resp.read(limit + 1)
        except socket.timeout:
            raise self._timeout_error(self.timeout if timeout is None else timeout) from None
        except (OSError, http.client.HTTPException, ValueError) as exc:
            raise connection_error(self.url, exc) from None
        if len(data) > limit:
            raise BadAnswer(f"the answer from {self.url} is larger than {limit} bytes")
        return data

    def _request(self, method, path, body=None, headers=None, timeout=None):
        """Returns (status, headers dict with lower-case names, body bytes)."""
        conn, resp = self._open(method, path, body, headers, timeout)
        try:
            data = self._read(resp, timeout=timeout)
        finally:
            conn.close()
        return resp.status, {k.lower(): v for k, v in resp.getheaders()}, data

    def _json(self, method, path, body=None, headers=None, require=()):
        """A JSON object answer; `require` names fields that must be there (strings)."""
        status, answer_headers, data = self._request(method, path, body, headers)
        if status == 204 and not require:
            return {}
        where = f"the answer to {method} {path}"
        kind = media_type(answer_headers)
        if kind != "application/json" and not kind.endswith("+json"):
            raise BadAnswer(f"{where} is not JSON ({kind or 'no Content-Type'}, {len(data)} bytes): "
                            f"{one_line(data[:80].decode('utf-8', 'replace'))!r} - is a proxy in the way?")
        try:
            doc = json.loads(data.decode("utf-8"))
        except (ValueError, RecursionError):  # UnicodeDecodeError is a ValueError
            raise BadAnswer(f"{where} is not valid JSON: {one_line(data[:80].decode('utf-8', 'replace'))!r}") from None
        if not isinstance(doc, dict):
            raise BadAnswer(f"{where} is a JSON {type(doc).__name__}, not an object")
        for field in require:
            if not isinstance(doc.get(field), str) or not doc.get(field):
                raise BadAnswer(f"{where} has no '{field}'")
        return doc

    @staticmethod
    def _job_body(job):
        """The bytes to send for a job: a dict is serialised; a path (str or os.PathLike) is read and sent
        unchanged (after checking that it is JSON), except that the Gmsh meshes it names by "file" are put in as
        "data" (read relative to the job file, as contact-solve does: the server reads no files); bytes are sent
        as they are; '-' reads standard input."""
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
            doc = json.loads(data.decode("utf-8"))
        except UnicodeDecodeError as exc:
            raise BadInput(f"{where}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
        except ValueError as exc:
            raise BadInput(f"{where}: not JSON: {exc}") from None
        if isinstance(job, (str, os.PathLike)) and where != "standard input":
            return Client._with_meshes(doc, os.path.dirname(where)) or data
        return data

    @staticmethod
    def _with_meshes(doc, directory):
        """The job serialised with its Gmsh mesh files put in as text, each file once (the server reads no files,
        and a file sent once per body can overflow its request limit): an entry of the job's "meshes" table given
        by "file" gets the file's text as "data", and a body's {"gmsh": {"file": f, ...}} becomes
        {"gmsh": {"mesh": name, ...}} with f's text in the table under name (one entry per distinct file). Files
        are read relative to `directory`, as contact-solve reads them. None when the job names no mesh file."""
        if not isinstance(doc, dict) or not isinstance(doc.get("meshes", {}), dict):
            return None  # {"meshes": 3}: sent as it is, for the server to name /meshes
        table = doc.get("meshes", {})
        bodies = doc.get("bodies") if isinstance(doc.get("bodies"), list) else []
        by_file = [b["mesh"]["gmsh"] for b in bodies if isinstance(b, dict) and isinstance(b.get("mesh"), dict)
                   and isinstance(b["mesh"].get("gmsh"), dict) and isinstance(b["mesh"]["gmsh"].get("file"), str)
                   and not {"data", "mesh"} & set(b["mesh"]["gmsh"])]  # several: left for the server to refuse
        entries = {name: e for name, e in table.items()
                   if isinstance(e, dict) and isinstance(e.get("file"), str) and "data" not in e}
        if not by_file and not entries:
            return None
        names = {}  # the file's path -> its entry's name

        def put(name, entry):
            path = os.path.normpath(os.path.join(directory, entry.pop("file")))
            try:
                with open(path, encoding="utf-8") as f:
                    entry["data"] = f.read()
            except (OSError, UnicodeDecodeError) as exc:
                raise BadInput(f"cannot read the Gmsh mesh {path}: {getattr(exc, 'strerror', None) or exc}") from None
            names.setdefault(path, name)

        for name, entry in entries.items():
            put(name, entry)
        for gmsh in by_file:
            path = os.path.normpath(os.path.join(directory, gmsh["file"]))
            if path not in names:
                name = Client._mesh_name(gmsh["file"], table)
                table[name] = {"file": gmsh["file"]}
                put(name, table[name])
            rest = {k: v for k, v in gmsh.items() if k != "file"}
            gmsh.clear()
            gmsh.update({"mesh": names[path], **rest})
        doc["meshes"] = table
        return json.dumps(doc).encode()

    @staticmethod
    def _mesh_name(file, table):
        """A name for the file in the job's "meshes" table: its base name without extension made a valid name
        (letters, digits, '_', '-'), numbered if the table has it already."""
        base = re.sub(r"[^A-Za-z0-9_-]", "_", os.path.splitext(os.path.basename(file))[0])[:56] or "mesh"
        name, k = base, 2
        while name in table:
            name, k = f"{base}_{k}", k + 1
        return name

    @staticmethod
    def _check_id(job_id):
        job_id = str(job_id).strip()
        if not job_id or "/" in job_id or "?" in job_id or "#" in job_id:
            raise BadInput(f"'{one_line(job_id)}' is not a job id")
        return urllib.parse.quote(job_id)

    # -- the API ----------------------------------------------------------------------------------------------
    def submit(self, job, idempotency_key=None):
        """Submits a job (a dict, a path to a JSON file, JSON bytes, or '-' for standard input); returns the job
        resource (state QUEUED, or whatever an idempotent replay finds). An invalid job raises ApiError with
        .errors (exit code 2)."""
        headers = {"Content-Type": "application/json"}
        if idempotency_key:
            headers["Idempotency-Key"] = str(idempotency_key)
        return self._json("POST", "/v1/jobs", self._job_body(job), headers, require=("id",))

    def validate(self, job):
        """Validates a job without running it: {"valid": true, "dofs": ..., "bodies": [...], "normalized": {...}};
        an invalid job raises ApiError with .errors."""
        return self._json("POST", "/v1/validate", self._job_body(job), {"Content-Type": "application/json"})

    def status(self, job_id):
        """The job resource (state, progress, timings, outcome, links)."""
        return self._json("GET", f"/v1/jobs/{self._check_id(job_id)}", require=("id", "state"))

    def list(self, state=None, page_size=None, page_token=None, all_pages=False):
        """One page of jobs, newest first: {"jobs": [...], "next_page_token": "..."}; with all_pages=True every
        page is fetched and the jobs are concatenated (next_page_token is then "")."""
        jobs = []
        seen_tokens = set()
        while True:
            query = {k: v for k, v in (("state", state), ("page_size", page_size), ("page_token", page_token))
                     if v not in (None, "")}
            path = "/v1/jobs" + ("?" + urllib.parse.urlencode(query) if query else "")
            page = self._json("GET", path)
            listed = page.get("jobs")
            if not isinstance(listed, list):
                raise BadAnswer(f"the answer to GET {path} has no list of jobs")
            jobs.extend(j for j in listed if isinstance(j, dict))
            page_token = page.get("next_page_token") or ""
            if not isinstance(page_token, str):
                raise BadAnswer(f"the answer to GET {path} has a next_page_token that is not a string")
            if not all_pages or not page_token:
                return {"jobs": jobs, "next_page_token": page_token}
            if page_token in seen_tokens:
                raise BadAnswer(f"the server gave the page token {page_token!r} twice")
            seen_tokens.add(page_token)

    def cancel(self, job_id):
        """Cancels a queued or running job; returns the job resource (a running job stops within one
        iteration: follow it with wait())."""
        return self._json("POST", f"/v1/jobs/{self._check_id(job_id)}/cancel", b"", {"Content-Length": "0"})

    def delete(self, job_id):
        """Deletes a finished job and its files (409 while QUEUED or RUNNING)."""
        # contactd itself waits for a job whose `end` event is still being written, so a DELETE right after
        # `end` succeeds without retries here.
        status, _, _ = self._request("DELETE", f"/v1/jobs/{self._check_id(job_id)}")
        if status != 204:  # contactd's only success answer; a 200 page comes from something else
            raise BadAnswer(f"DELETE answered {status}, not 204 No Content: the job may not be deleted - is a "
                            "proxy in the way?")

    def health(self):
        return self._json("GET", "/healthz")

    def schema(self):
        return self._json("GET", "/v1/schema")

    def events(self, job_id, last_event_id=None, max_retries=5, read_timeout=None):
        """Iterates over the job's progress events (dicts with seq, type, time, ...) from the first one (or after
        last_event_id) to the `end` event included. If the connection drops, or the stream closes without
        `end` (a server shutdown), it reconnects with Last-Event-ID after a backoff, at most max_retries times in
        a row; events are never repeated or skipped. `read_timeout`: how long the stream may stay silent
        (default: the client's timeout, at least STREAM_READ_TIMEOUT)."""
        path = f"/v1/jobs/{self._check_id(job_id)}/events"
        read_timeout = max(self.timeout, STREAM_READ_TIMEOUT) if read_timeout is None else float(read_timeout)
        last = None if last_event_id is None else int(last_event_id)
        failures = 0
        while True:
            headers = {"Accept": "text/event-stream", "Cache-Control": "no-cache"}
            if last is not None:
                headers["Last-Event-ID"] = str(last)
            problem, wait, delivered = None, None, False
            try:
                conn, resp = self._open("GET", path, headers=headers, timeout=read_timeout)
                try:
                    kind = media_type({k.lower(): v for k, v in resp.getheaders()})
                    if kind != "text/event-stream":
                        raise BadAnswer(f"the progress stream of {one_line(job_id)} is not an event stream "
                                        f"({kind or 'no Content-Type'}) - is a proxy in the way?")
                    for event in read_sse(resp):
                        seq = event.get("seq")
                        if isinstance(seq, int) and not isinstance(seq, bool):
                            if last is not None and seq <= last:
                                continue  # never repeat an event
                            last = seq
                        failures, delivered = 0, True
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
            except (OSError, http.client.HTTPException, ValueError) as exc:
                problem = f"connection lost ({one_line(exc)[:200] or type(exc).__name__})"
            # A connection that brought nothing new, of a job that has ended: there is nothing more to wait for,
            # whatever cut the stream (a proxy that cuts it each time, a log that lost its end); the job's resource
            # is the answer. (One that brought events is resumed: the rest of them may still come.)
            if not delivered:
                ended = self._ended(job_id)
                if ended:
                    self.log(f"{problem}; the job has ended ({ended}) and its stream brings no more events: "
                             "not waiting for its end event")
                    return
            failures += 1
            if failures > max_retries:
                raise ConnectionFailed(f"progress stream of {one_line(job_id)} lost after {max_retries} reconnections: "
                                       f"{problem}")
            delay = min(0.5 * 2 ** (failures - 1), 10.0)
            if wait:
                delay = max(delay, min(wait, 30.0))
            where = f"after event {last}" if last is not None else "from the start"
            self.log(f"{problem}; reconnecting in {delay:g} s ({failures}/{max_retries}), resuming {where}")
            time.sleep(delay)

    def _ended(self, job_id):
        """The job's state when it has ended (SUCCEEDED, FAILED or CANCELLED), else None (also when it cannot be
        read now: the stream's own retries decide then)."""
        try:
            job = self.status(job_id)
        except ClientError:
            return None
        return job.get("state") if job.get("done") else None

    def wait(self, job_id, on_event=None, max_retries=5, read_timeout=None):
        """Follows the job's events to its end (on_event(event) is called for each) and returns the final job
        resource."""
        for event in self.events(job_id, max_retries=max_retries, read_timeout=read_timeout):
            if on_event:
                on_event(event)
        return self.status(job_id)

    def download(self, job_id, path, xmf=False):
        """Downloads the HDF5 result to path (written to path + '.part' then renamed, only once it is whole). The
        answer must announce its size (Content-Length) and start with the HDF5 signature, checked on its first 8
        bytes before anything is written; nothing beyond the announced size is written. With xmf=True the XDMF sidecar is saved next to it (same name, .xmf)
        with its data references renamed to the file's name. Returns path."""
        base = f"/v1/jobs/{self._check_id(job_id)}"
        path = os.fspath(path)
        self._download_to(base + "/result", path)
        if xmf:
            _, answer_headers, data = self._request("GET", base + "/result.xmf")
            kind = media_type(answer_headers)
            try:
                text = data.decode("utf-8")
            except UnicodeDecodeError:
                text = None
            if kind not in ("application/xml", "text/xml") or text is None or "<Xdmf" not in text:
                raise BadAnswer(f"the XDMF sidecar of {one_line(job_id)} is not XDMF ({kind or 'no Content-Type'})")
            name = os.path.basename(path)
            text = text.replace('result.hdf:/', name + ":/")
            side = os.path.splitext(path)[0] + ".xmf"
            try:
                with open(side + ".part", "w", encoding="utf-8") as f:
                    f.write(text)
                os.replace(side + ".part", side)
            except OSError as exc:
                raise ClientError(f"cannot write {side}: {exc.strerror or exc}") from None
        return path

    def _download_to(self, api_path, path):
        conn, resp = self._open("GET", api_path)
        tmp = path + ".part"
        try:
            if resp.status != 200:
                raise BadAnswer(f"GET {api_path} answered {resp.status}, not 200")
            kind = media_type({k.lower(): v for k, v in resp.getheaders()})
            if kind not in ("application/x-hdf5", "application/octet-stream"):
                raise BadAnswer(f"the result of {api_path} is not an HDF5 file ({kind or 'no Content-Type'}) - "
                                "is a proxy in the way?")
            expected = content_length(resp)
            if expected is None:
                raise BadAnswer(f"the result of {api_path} does not announce its size (no Content-Length; contactd "
                                "always does) - is a proxy in the way? Not saved")
            head = resp.read(min(len(HDF5_SIGNATURE), expected))
            if head != HDF5_SIGNATURE:
                raise BadAnswer(f"the result of {api_path} does not start with the HDF5 signature "
                                f"({one_line(repr(head))[:40]}): not saved")
            size = self._write_body(resp, head, tmp, expected)
            if size != expected:
                raise ConnectionFailed(f"download of {api_path} cut short ({size} of {expected} bytes)")
            os.replace(tmp, path)
        except socket.timeout:
            raise RequestTimeout(f"download from {self.url} stalled for {self.timeout:g} s (timeout)") from None
        except (OSError, http.client.HTTPException, ValueError) as exc:
            if isinstance(exc, OSError) and getattr(exc, "filename", None):
                raise ClientError(f"cannot write {exc.filename}: {exc.strerror or exc}") from None
            raise connection_error(self.url, exc) from None
        finally:
            conn.close()
            if os.path.exists(tmp):
                os.remove(tmp)


    @staticmethod
    def _write_body(resp, head, tmp, expected):
        """Writes `head` and the rest of the body to tmp, never more than `expected` bytes in all (the announced
        Content-Length); returns the number of bytes written."""
        try:
            f = open(tmp, "wb")
        except OSError as exc:
            raise ClientError(f"cannot write {tmp}: {exc.strerror or exc}") from None
        with f:
            f.write(head)
            size = len(head)
            while size < expected:
                chunk = resp.read(min(1 << 16, expected - size))
                if not chunk:
                    break
                f.write(chunk)
                size += len(chunk)
        return size


def _retry_after(headers):
    try:
        return float(headers.get("retry-after", ""))
    except (TypeError, ValueError):
        return None
