"""Shared helpers of the contactd integration tests: start the real server on a free loopback port with a
temporary data directory, talk HTTP to it (standard library only), read progress streams. The checks are counted
by tests/checks.py; when one failed, its finish() prints the logs of the servers started here.

Every wait is bounded; every server started is killed at the end (Server is a context manager)."""
import atexit
import http.client
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import checks  # noqa: E402  (tests/checks.py: the checks are counted there, not here)

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
# CONTACTD_BIN runs the tests against another build (e.g. an older one, to see a regression test fail).
CONTACTD = os.environ.get("CONTACTD_BIN") or os.path.join(BIN, "server", "contactd")
CONTACT_SOLVE = os.path.join(BIN, "contact-solve")
EXAMPLES = os.path.join(SRC, "api", "examples")
HOST = "127.0.0.1"  # the tests only ever contact the loopback address

_started = []  # every Server started: killed at exit even when a test dies of an exception


@atexit.register
def _kill_all():
    for server in _started:
        server.kill()
        server.cleanup()


def example(name):
    with open(os.path.join(EXAMPLES, name)) as f:
        return json.load(f)


def flat_patch(displacement=-0.001, name="flat_patch"):
    """Two blocks pressed together; solves in milliseconds. The contact force is proportional to the
    prescribed displacement of the upper block's top."""
    job = example("flat_patch.json")
    job["name"] = name
    for body in job["bodies"]:
        for bc in body.get("boundary", []):
            if bc["edge"] == "top" and "displacement" in bc:
                bc["displacement"]["y"] = displacement
    return job


def long_job(max_iterations=100000, name="long", iterate=False):
    """The paper's two layers on a tall mesh (32 x 256 per body, about 2 ms per iteration) with a tolerance the
    iteration does not reach before max_iterations: a job that runs until cancelled, or for a bounded time. With
    `iterate` its result keeps the iterate it stops on (output.iterate; without, a stopped run keeps nothing)."""
    job = example("seed_layers.json")
    job["name"] = name
    for body in job["bodies"]:
        body["mesh"]["block"]["nx"] = 32
        body["mesh"]["block"]["ny"] = 256
    # The paper's scheme spelled out (plain relaxation, penalty): slow and steady, ~2 ms per iteration.
    job["solver"].update(method="neumann", acceleration="none", enforcement="penalty", criterion="residual",
                         tolerance=1e-14, gamma=0.002, max_iterations=max_iterations)
    if iterate:
        job["output"] = {"iterate": True}
    return job


def roller_job():
    """The roller between two plates, loaded by a force alone, held by friction (issue 21; Coulomb mu = 0.2 on both
    contacts, roller.bottom-base.top and roller.top-plate.bottom): one step, partial stick on both."""
    arcs = {"bottom": {"arc": {"center": [0, 1], "radius": 1}}, "top": {"arc": {"center": [0, 1], "radius": 1}}}
    steel = {"E": 2.1e5, "nu": 0.3}
    return {"name": "roller", "bodies": [
        {"name": "base", "material": steel,
         "mesh": {"block": {"corners": [[-2, -1], [2, -1], [2, 0], [-2, 0]], "nx": 32, "ny": 8}},
         "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
        {"name": "roller", "material": steel,
         "mesh": {"block": {"corners": [[-0.5, 0.1339745962155614], [0.5, 0.1339745962155614],
                                        [0.5, 1.8660254037844386], [-0.5, 1.8660254037844386]],
                            "nx": 24, "ny": 24, "edges": arcs}}},
        {"name": "plate", "material": steel,
         "mesh": {"block": {"corners": [[-2, 2], [2, 2], [2, 3], [-2, 3]], "nx": 32, "ny": 8}},
         "boundary": [{"edge": "top", "force": [0, -10000]}]}],
        "contacts": [{"slave": "roller.bottom", "master": "base.top", "friction": {"coefficient": 0.2}},
                     {"slave": "roller.top", "master": "plate.bottom", "friction": {"coefficient": 0.2}}]}


@checks.at_failure
def _print_logs():
    """At the end of a failed test (checks.finish()): the last lines of every contactd it started."""
    for server in _started:
        print(f"--- contactd log (port {server.port}), last lines:\n{server.output()[-2000:]}", flush=True)


class Response:
    def __init__(self, status, headers, body):
        self.status = status
        self.headers = headers  # dict, lower-case names
        self.body = body

    def json(self):
        try:
            return json.loads(self.body)
        except ValueError:
            return None

    @property
    def content_type(self):
        return self.headers.get("content-type", "")

    def is_problem(self):
        """An RFC 9457 problem document whose status matches the response's."""
        doc = self.json()
        return (self.content_type.startswith("application/problem+json") and isinstance(doc, dict)
                and all(k in doc for k in ("type", "title", "status", "detail")) and doc["status"] == self.status)

    def __repr__(self):
        return f"<{self.status} {self.content_type} {self.body[:300]!r}>"


class Server:
    """A contactd process on a free port. Use as a context manager, or call stop()/kill()."""

    def __init__(self, data_dir=None, args=(), env=None, token=None, prefix=()):
        self.prefix = list(prefix)  # a command to run contactd through (e.g. nsenter ... --)
        self.owns_dir = data_dir is None
        self.data_dir = data_dir or tempfile.mkdtemp(prefix="contactd-test-")
        self.args = list(args)
        self.env = dict(os.environ)
        self.env.update(env or {})
        self.token = token
        if token:
            self.env["CONTACTD_TOKEN"] = token
        self.proc = None
        self.port = None
        self.log_path = None

    def start(self, timeout=20, ready=True):
        """Starts contactd and waits until /readyz says 200 (with ready=False: until /healthz answers)."""
        fd, self.log_path = tempfile.mkstemp(prefix="contactd-log-", suffix=".txt")
        self.log = os.fdopen(fd, "w")
        beat = [] if "--heartbeat-seconds" in self.args else ["--heartbeat-seconds", "1"]  # a test's own wins
        cmd = [*self.prefix, CONTACTD, "--host", HOST, "--port", "0", "--data-dir", self.data_dir, *beat, *self.args]
        self.proc = subprocess.Popen(cmd, stdout=self.log, stderr=subprocess.STDOUT, env=self.env)
        _started.append(self)
        deadline = time.time() + timeout
        while time.time() < deadline:
            with open(self.log_path) as f:
                m = re.search(r"listening on http://[0-9.]+:(\d+)", f.read())
            if m:
                self.port = int(m.group(1))
                break
            if self.proc.poll() is not None:
                raise RuntimeError(f"contactd exited with {self.proc.returncode}: {self.output()}")
            time.sleep(0.02)
        else:
            self.kill()
            raise RuntimeError("contactd did not start: " + self.output())
        # Ready means the store is read back and the workers run.
        deadline = time.time() + timeout
        while time.time() < deadline:
            try:
                if self.request("GET", "/readyz" if ready else "/healthz", timeout=5).status == 200:
                    return self
            except OSError:
                pass
            time.sleep(0.05)
        raise RuntimeError("contactd never became ready: " + self.output())

    def output(self):
        try:
            with open(self.log_path) as f:
                return f.read()[-4000:]
        except (OSError, TypeError):
            return ""

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.kill()  # the log and data directory go at exit (checks.finish() shows the logs of a failed run)

    def kill(self):
        """SIGKILL (if still running) and reap."""
        if self.proc and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=10)
        if getattr(self, "log", None):
            self.log.close()
            self.log = None

    def cleanup(self):
        """Removes the log file, and the data directory if this Server made it."""
        if self.log_path and os.path.exists(self.log_path):
            os.remove(self.log_path)
        if self.owns_dir:
            shutil.rmtree(self.data_dir, ignore_errors=True)

    def terminate(self, timeout=10):
        """SIGTERM; returns (exit code, seconds taken) or (None, timeout) if it did not exit in time."""
        start = time.time()
        self.proc.send_signal(signal.SIGTERM)
        try:
            code = self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return None, timeout
        return code, time.time() - start

    # -- HTTP ------------------------------------------------------------------------------------------------
    def connection(self, timeout=30):
        return http.client.HTTPConnection(HOST, self.port, timeout=timeout)

    def auth_headers(self, headers=None):
        h = dict(headers or {})
        if self.token and "Authorization" not in h:
            h["Authorization"] = "Bearer " + self.token
        return h

    def request(self, method, path, body=None, headers=None, timeout=30, json_body=None, auth=True):
        if json_body is not None:
            body = json.dumps(json_body).encode()
            headers = dict(headers or {})
            headers.setdefault("Content-Type", "application/json")
        if isinstance(body, str):
            body = body.encode()
        h = self.auth_headers(headers) if auth else dict(headers or {})
        if method in ("POST", "DELETE") and "Content-Type" not in h:
            # What every client of the API sends with a body-less POST or a DELETE (the cross-site rule).
            h.setdefault("X-Requested-With", "contactd-tests")
        conn = self.connection(timeout)
        try:
            conn.request(method, path, body=body, headers=h)
            r = conn.getresponse()
            data = r.read()
            return Response(r.status, {k.lower(): v for k, v in r.getheaders()}, data)
        finally:
            conn.close()

    def get(self, path, **kw):
        return self.request("GET", path, **kw)

    def submit(self, job, headers=None):
        return self.request("POST", "/v1/jobs", json_body=job, headers=headers)

    def submit_id(self, job):
        r = self.submit(job)
        if r.status != 202:
            raise RuntimeError(f"submission refused: {r}")
        return r.json()["id"]

    def job(self, job_id):
        return self.get(f"/v1/jobs/{job_id}").json()

    def wait_for(self, job_id, predicate, timeout=60, interval=0.05):
        """Polls the job resource until predicate(resource) holds; returns the resource (or the last one)."""
        deadline = time.time() + timeout
        resource = None
        while time.time() < deadline:
            resource = self.job(job_id)
            if resource is not None and predicate(resource):
                return resource
            time.sleep(interval)
        return resource

    def wait_done(self, job_id, timeout=60):
        return self.wait_for(job_id, lambda j: j.get("done"), timeout)

    def rss_kb(self, field="VmRSS"):
        """The server's resident memory (kB): VmRSS now, or VmHWM for its peak so far."""
        with open(f"/proc/{self.proc.pid}/status") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1])
        return None

    def cpu_seconds(self):
        """The server's CPU time so far (user + system, all threads, seconds): unlike a wall time, about the same on a
        loaded machine as on an idle one."""
        with open(f"/proc/{self.proc.pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime, stime (fields 14, 15)

    def metric(self, name):
        """The value of one sample of /metrics, e.g. metric('contactd_jobs{state="SUCCEEDED"}')."""
        text = self.get("/metrics").body.decode()
        for line in text.splitlines():
            if line.startswith(name + " "):
                return float(line.split()[-1])
        return None

    def raw(self, data, timeout=10):
        """Sends raw bytes on a fresh connection; returns what comes back until the server closes or the
        timeout (bytes)."""
        with socket.create_connection((HOST, self.port), timeout=timeout) as s:
            s.sendall(data)
            chunks = []
            try:
                while True:
                    chunk = s.recv(65536)
                    if not chunk:
                        break
                    chunks.append(chunk)
                    if b"\r\n\r\n" in b"".join(chunks):
                        # Enough for the status line and headers; read the rest if Content-Length says so.
                        head, _, rest = b"".join(chunks).partition(b"\r\n\r\n")
                        m = re.search(rb"content-length:\s*(\d+)", head, re.I)
                        if m and len(rest) >= int(m.group(1)):
                            break
            except socket.timeout:
                pass
            return b"".join(chunks)


class PrivateTmpfs:
    """A tmpfs of `size` (e.g. "6m") in a private mount namespace held by a `sleep`: a data directory that can be
    filled or grown without touching the machine's disks. contactd runs inside it with `prefix` (nsenter); the
    test reads its files through path(). Needs root (mount) and util-linux (unshare, nsenter): without them the
    test is skipped (exit 77) with the reason."""

    def __init__(self, size, name="contactd-tmpfs-"):
        self.mount_point = tempfile.mkdtemp(prefix=name)
        self.holder = subprocess.Popen(
            ["unshare", "--mount", "--propagation", "private", "sh", "-c",
             f"mount -t tmpfs -o size={size} tmpfs {self.mount_point} && echo mounted && exec sleep 600"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if self.holder.stdout.readline().strip() != "mounted":
            self.holder.kill()
            reason = f"cannot mount a tmpfs in a private namespace here ({self.holder.stderr.read().strip()[:200]})"
            os.rmdir(self.mount_point)
            checks.skip(reason)
        self.prefix = ["nsenter", "-t", str(self.holder.pid), "-m", "--"]

    def path(self, *parts):
        """A path inside the tmpfs as this process sees it."""
        return os.path.join(f"/proc/{self.holder.pid}/root", self.mount_point.lstrip("/"), *parts)

    def remount(self, size):
        """Grows (or shrinks) the tmpfs; the completed process."""
        return subprocess.run([*self.prefix, "mount", "-o", f"remount,size={size}", self.mount_point],
                              capture_output=True, text=True)

    def close(self):
        self.holder.send_signal(signal.SIGKILL)
        self.holder.wait(timeout=10)
        try:
            os.rmdir(self.mount_point)
        except OSError:
            pass


class Stream:
    """A progress stream read incrementally: SSE (default) or NDJSON. next_event() returns the next event as a
    dict with the SSE fields attached (_id, _event), or None at the end of the stream."""

    def __init__(self, server, job_id, ndjson=False, last_event_id=None, query="", timeout=30):
        self.ndjson = ndjson
        self.conn = server.connection(timeout)
        headers = server.auth_headers({"Accept": "application/x-ndjson" if ndjson else "text/event-stream"})
        if last_event_id is not None:
            headers["Last-Event-ID"] = str(last_event_id)
        self.conn.request("GET", f"/v1/jobs/{job_id}/events{query}", headers=headers)
        self.response = self.conn.getresponse()
        self.status = self.response.status
        self.content_type = self.response.getheader("Content-Type", "")
        self.heartbeats = 0
        self.comments = []

    def next_event(self):
        if self.ndjson:
            while True:
                line = self.response.readline()
                if not line:
                    return None
                if not line.strip():
                    self.heartbeats += 1
                    continue
                return json.loads(line)
        fields = {}
        while True:
            line = self.response.readline()
            if not line:
                return None
            line = line.decode().rstrip("\n")
            if line == "":
                if "data" in fields:
                    event = json.loads(fields["data"])
                    event["_id"] = fields.get("id")
                    event["_event"] = fields.get("event")
                    return event
                continue
            if line.startswith(":"):
                self.comments.append(line)
                if "heartbeat" in line:
                    self.heartbeats += 1
                continue
            key, _, value = line.partition(":")
            fields[key] = value[1:] if value.startswith(" ") else value

    def events_until_end(self, limit=10 ** 7):
        events = []
        while len(events) < limit:
            e = self.next_event()
            if e is None:
                break
            events.append(e)
            if e.get("type") == "end":
                break
        return events

    def close(self):
        self.conn.close()


def read_all_events(server, job_id, ndjson=False, timeout=60):
    """Every event of the job up to its end (or the stream's close), without the SSE framing fields."""
    s = Stream(server, job_id, ndjson=ndjson, timeout=timeout)
    try:
        return [{k: v for k, v in e.items() if not k.startswith("_")} for e in s.events_until_end()]
    finally:
        s.close()
