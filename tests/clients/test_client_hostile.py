#!/usr/bin/env python3
"""The client against a broken server or proxy (issue 10, item 14): every command, for every kind of bad answer,
ends with "error: ..." lines and exit code 1 (or 2, 3), never a traceback; a redirect is not success (delete does
not say "deleted", download writes no file); a download must be an HDF5 file (an HTML page or garbage is not
saved); watch honours --timeout on a silent stream.

A fake server on a loopback port answers every request with the raw bytes of the scenario under test. The
commands run in this process (contact_client.main with stdout and stderr captured; an exception escaping main
is what would print a traceback) and a few as subprocesses. Standard library only."""
import contextlib
import io
import json
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time

from client_paths import CLIENT, EXAMPLES, HERE, SRC  # noqa: E402,F401  (sets the import path)

import contact_client as cc  # noqa: E402
from checks import check, finish  # noqa: E402

JOB_ID = "00000000-0000-4000-8000-000000000000"
HOST = "127.0.0.1"


def http(status, body=b"", content_type="application/json", extra=b"", length=None):
    if isinstance(body, str):
        body = body.encode()
    head = b"HTTP/1.1 %d X\r\n" % status
    if content_type:
        head += b"Content-Type: " + content_type.encode() + b"\r\n"
    head += b"Content-Length: " + (str(len(body)) if length is None else length).encode() + b"\r\n"
    return head + extra + b"Connection: close\r\n\r\n" + body


def sse(*data_lines):
    body = b"".join(b"data: " + d.encode() + b"\n\n" for d in data_lines)
    return (b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nConnection: close\r\n\r\n" + body)


class Silent:
    """Sends the head of an event stream, then nothing for `seconds`."""

    def __init__(self, seconds):
        self.seconds = seconds

    def __call__(self, sock):
        sock.sendall(b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nTransfer-Encoding: chunked\r\n\r\n")
        time.sleep(self.seconds)


# Every kind of bad answer (the same for every path asked).
SCENARIOS = {
    "problem with non-string fields": http(400, json.dumps({"type": 42, "title": ["x"], "status": "400",
                                                             "detail": {"a": 1}, "errors": "nope",
                                                             "state": [1]}), "application/problem+json"),
    "problem with odd errors": http(400, json.dumps({"type": "/problems/invalid-job", "errors": [
        1, None, {"pointer": 5, "message": ["m"]}]}), "application/problem+json"),
    "JSON null": http(200, "null"),
    "JSON list": http(200, "[1, 2]"),
    "no id": http(202, json.dumps({"state": "QUEUED", "jobs": 5, "bodies": 3})),
    "odd field types": http(200, json.dumps({"id": JOB_ID, "state": ["x"], "jobs": [1, {"id": 3, "state": None}],
                                             "next_page_token": 7, "progress": [1], "timings": "t",
                                             "error": "e", "bodies": [1], "iterations": "many"})),
    "HTML page (a proxy)": http(200, "<html><body>Sign in to the portal</body></html>", "text/html"),
    "HTML error page": http(502, "<html>Bad Gateway</html>", "text/html"),
    "redirect": http(302, "", None, extra=b"Location: http://elsewhere.example/\r\n"),
    "moved permanently": http(301, "", None, extra=b"Location: /login\r\n"),
    "Content-Length abc": http(200, "{}", length="abc"),
    "short body": http(200, '{"id": "x"}', length="500"),
    "bad chunked encoding": (b"HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n"
                             b"zz\r\n{}\r\n0\r\n\r\n"),
    "not HTTP": b"SSH-2.0-OpenSSH_9.2\r\n",
    "garbage status line": b"HTTP/1.1 abc def\r\n\r\n",
    "nothing": b"",
    "deep JSON": http(200, "[" * 100000 + "]" * 100000),
    "deep problem": http(400, "[" * 100000 + "]" * 100000, "application/problem+json"),
    "SSE data not JSON": sse("this is not json"),
    "SSE list": sse("[1, 2, 3]"),
    "SSE odd iteration": sse(json.dumps({"seq": 1, "type": "iteration", "iteration": "x", "paper_criterion": "p",
                                         "bodies": "b", "pairs": [1, {"name": 3, "force": "f"}],
                                         "elapsed_seconds": [1]}),
                             json.dumps({"seq": "2", "type": "step", "bodies": [{"elements": "e"}]}),
                             json.dumps({"seq": 3, "type": "end", "state": ["S"], "iterations": "i",
                                         "solve_seconds": "s", "result_available": "yes"})),
    "HDF5 of the wrong size": http(200, b"\x89HDF\r\n\x1a\nrest", "application/x-hdf5", length="999"),
    "garbage as HDF5": http(200, b"GIF89a" + b"\x00" * 100, "application/x-hdf5"),
}


class FakeServer:
    def __init__(self):
        self.sock = socket.socket()
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.bind((HOST, 0))
        self.sock.listen(16)
        self.url = f"http://{HOST}:{self.sock.getsockname()[1]}"
        self.answer = b""
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            threading.Thread(target=self._serve, args=(conn,), daemon=True).start()

    def _serve(self, conn):
        try:
            conn.settimeout(5)
            data = b""
            while b"\r\n\r\n" not in data:
                chunk = conn.recv(65536)
                if not chunk:
                    break
                data += chunk
            answer = self.answer
            if callable(answer):
                answer(conn)
            else:
                conn.sendall(answer)
        except OSError:
            pass
        finally:
            try:
                conn.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            conn.close()


def run_main(args):
    """(exit code, stdout, stderr, escaped exception) of contact_client.main(args)."""
    out, err = io.StringIO(), io.StringIO()
    escaped = None
    code = None
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = cc.main(args)
        except SystemExit as exc:
            code = exc.code
        except BaseException as exc:  # what would be a traceback
            escaped = exc
    return code, out.getvalue(), err.getvalue(), escaped


server = FakeServer()
tmp = tempfile.mkdtemp(prefix="client-hostile-")
job_file = os.path.join(tmp, "job.json")
with open(job_file, "w") as f:
    json.dump({"name": "x", "bodies": []}, f)
download_to = os.path.join(tmp, "result.hdf")

COMMANDS = [
    ["submit", job_file],
    ["submit", job_file, "--wait", "--retries", "0"],
    ["status", JOB_ID],
    ["status", JOB_ID, "--json"],
    ["list"],
    ["list", "--all"],
    ["cancel", JOB_ID],
    ["delete", JOB_ID],
    ["download", JOB_ID, "-o", download_to],
    ["download", JOB_ID, "-o", download_to, "--xmf"],
    ["validate", job_file],
    ["watch", JOB_ID, "--retries", "0"],
]

runs = tracebacks = 0
start = time.time()
for name, answer in SCENARIOS.items():
    server.answer = answer
    for command in COMMANDS:
        args = command + ["--url", server.url, "--timeout", "2"]
        if os.path.exists(download_to):
            os.remove(download_to)
        code, out, err, escaped = run_main(args)
        runs += 1
        label = f"{name}: {' '.join(command[:2])}"
        if escaped is not None:
            tracebacks += 1
            check(f"{label}: no traceback", False, repr(escaped))
            continue
        check(f"{label}: an exit code, not a crash", code in (0, 1, 2, 3), (code, err[-300:]))
        if code != 0:
            check(f"{label}: says what is wrong on stderr", err.strip() != "" and ("error: " in err or "ended" in err),
                  err[-300:])
        check(f"{label}: handled, not caught by the last-resort handler", "internal error of the client" not in err,
              err[-300:])
        if command[0] == "download":
            check(f"{label}: no file written unless it is HDF5", not os.path.exists(download_to) or code == 0,
                  code)
        if command[0] == "delete":
            check(f"{label}: nothing but 204 is 'deleted'", code != 0 and "deleted" not in out, (code, out))
print(f"{runs} runs of {len(COMMANDS)} commands against {len(SCENARIOS)} bad answers in {time.time() - start:.1f} s, "
      f"{tracebacks} tracebacks", flush=True)

# The cases of the issue, by name.
server.answer = SCENARIOS["HTML page (a proxy)"]
code, out, err, _ = run_main(["download", JOB_ID, "-o", download_to, "--url", server.url])
check("a proxy's HTML page is not saved as .hdf", code == 1 and not os.path.exists(download_to) and
      "not an HDF5 file" in err, err)
server.answer = SCENARIOS["garbage as HDF5"]
code, out, err, _ = run_main(["download", JOB_ID, "-o", download_to, "--url", server.url])
check("a download without the HDF5 signature is not saved", code == 1 and not os.path.exists(download_to) and
      "HDF5 signature" in err, err)
server.answer = SCENARIOS["redirect"]
code, out, err, _ = run_main(["delete", JOB_ID, "--url", server.url])
check("delete answered 302: exit 1, a line naming the redirect", code == 1 and "302" in err and "redirect" in err and
      out == "", (code, out, err))
code, out, err, _ = run_main(["download", JOB_ID, "-o", download_to, "--url", server.url])
check("download answered 302: no 0-byte file", code == 1 and not os.path.exists(download_to), (code, err))

# watch honours --timeout on a stream that goes silent (it used to wait 60 s per attempt). Two attempts of 1 s take
# a few seconds (printed); without the timeout the first attempt alone lasts the stream's 30 s of silence. 20 s is
# broken only by that, not by a loaded machine.
server.answer = Silent(30)
begin = time.time()
code, out, err, _ = run_main(["watch", JOB_ID, "--url", server.url, "--timeout", "1", "--retries", "1"])
took = time.time() - begin
print(f"watch --timeout 1 --retries 1 on a silent stream: gave up after {took:.1f} s", flush=True)
check(f"watch --timeout 1 on a silent stream: gives up by its timeout, not the stream's end ({took:.1f} s measured)",
      code == 1 and took < 20 and "no event or heartbeat for 1 s" in err, (code, took, err))

# As commands: the same answers print no traceback.
for name in ("problem with non-string fields", "JSON null", "SSE data not JSON", "Content-Length abc",
             "bad chunked encoding", "deep JSON"):
    server.answer = SCENARIOS[name]
    command = ["watch", JOB_ID, "--retries", "0"] if name.startswith("SSE") else ["status", JOB_ID]
    r = subprocess.run([sys.executable, CLIENT, *command, "--url", server.url, "--timeout", "2"],
                       capture_output=True, text=True, timeout=60)
    check(f"as a command, {name}: exit 1 and no traceback", r.returncode == 1 and "Traceback" not in r.stderr and
          r.stderr.startswith("error: "), (r.returncode, r.stderr[-400:]))


# Issue 22, defect 8: the download wrote 1.7 GB of a broken server's endless zeros (no Content-Length) before it
# checked the HDF5 signature at the end. Now the first bytes are checked and nothing beyond the announced size is
# written. What the client writes is counted through its module's open().
class Endless:
    """Answers a download with `head` (status line and headers), then `body_start` and zeros, up to `limit`
    bytes (so that a client that does not stop fails the test instead of filling the disk)."""

    def __init__(self, head, body_start=b"", limit=64 << 20):
        self.head, self.body_start, self.limit = head, body_start, limit

    def __call__(self, sock):
        sock.sendall(self.head + b"\r\n" + self.body_start)
        block, sent = b"\x00" * 65536, 0
        try:
            while sent < self.limit:
                sock.sendall(block)
                sent += len(block)
        except OSError:  # the client closed the connection
            pass


written = []


def counting_open(path, mode="r", *args, **kwargs):
    f = open(path, mode, *args, **kwargs)
    if "w" in mode and path.endswith(".part"):
        write = f.write
        written.append(0)

        def counted(data):
            written[-1] += len(data)
            return write(data)
        f.write = counted
    return f


client_module = sys.modules["contact_client.client"]
client_module.open = counting_open
HDF5_HEAD = b"HTTP/1.1 200 OK\r\nContent-Type: application/x-hdf5\r\nConnection: close\r\n"
for name, answer, expect_file in (
        ("no Content-Length, endless zeros", Endless(HDF5_HEAD), False),
        ("no Content-Length, the HDF5 signature then endless zeros", Endless(HDF5_HEAD, cc.client.HDF5_SIGNATURE),
         False),
        ("1 MB announced, zeros", Endless(HDF5_HEAD + b"Content-Length: 1000000\r\n"), False),
        ("1000 bytes announced, the signature then endless zeros",
         Endless(HDF5_HEAD + b"Content-Length: 1000\r\n", cc.client.HDF5_SIGNATURE), True)):
    server.answer = answer
    written.clear()
    if os.path.exists(download_to):
        os.remove(download_to)
    begin = time.time()
    code, out, err, escaped = run_main(["download", JOB_ID, "-o", download_to, "--url", server.url, "--timeout", "5"])
    took = time.time() - begin
    total = sum(written)
    if expect_file:
        check(f"download, {name}: saves exactly the announced 1000 bytes", code == 0 and total == 1000 and
              os.path.getsize(download_to) == 1000, (code, total, err[-300:]))
    else:
        check(f"download, {name}: exit 1 with a message, no file", code == 1 and err.startswith("error: ") and
              not os.path.exists(download_to), (code, err[-300:], escaped))
        check(f"download, {name}: at most a few KB written before the error", total <= 4096, total)
    # What it stops is checked above (the bytes written); the time is printed, and 60 s only catches a hang.
    print(f"download, {name}: {took:.2f} s", flush=True)
    check(f"download, {name}: ends (no hang; {took:.2f} s measured)", took < 60, took)
client_module.open = open

# Issue 22, defect 9: escape sequences in what a server sends reached the terminal. Every string field of every
# answer carries ESC (a colour, a clear screen, a window title), BEL, the one-byte C1 CSI and a bidi override.
EVIL = "x\x1b[31m\x1b[2J\x1b]0;owned\x07\x9b1m\u202e"
evil_job = {"id": EVIL, "state": "FAILED" + EVIL, "name": EVIL, "message": EVIL, "stop_reason": EVIL,
            "error": {"message": EVIL}, "created": EVIL, "iterations": EVIL, "progress": {"note": EVIL}}
evil_event = {"seq": 1, "type": "state", "state": EVIL, "message": EVIL}
evil_end = {"seq": 2, "type": "end", "state": EVIL, "stop_reason": EVIL, "message": EVIL}
EVIL_ANSWERS = {
    "job resource": http(200, json.dumps({**evil_job, "jobs": [evil_job], "next_page_token": EVIL})),
    "problem document": http(400, json.dumps({"type": "/problems/" + EVIL, "title": EVIL, "detail": EVIL,
                                              "state": EVIL}), "application/problem+json"),
    "invalid-job errors": http(400, json.dumps({"type": "/problems/invalid-job", "errors": [
        {"pointer": "/" + EVIL, "message": EVIL}]}), "application/problem+json"),
    "events": sse(json.dumps(evil_event), json.dumps({"seq": 2, "type": "iteration", "iteration": 1, "note": EVIL,
                                                      "pairs": [{"name": EVIL}], "bodies": [{"name": EVIL}]}),
                  json.dumps({"seq": 3, "type": "step", "bodies": [{"name": EVIL}]}), json.dumps(evil_end)),
    "redirect": http(302, "", None, extra=b"Location: http://x/\x1b[2J\r\n"),
}
for name, answer in EVIL_ANSWERS.items():
    server.answer = answer
    for command in COMMANDS:
        code, out, err, escaped = run_main(command + ["--url", server.url, "--timeout", "2"])
        shown = out + err
        label = f"control characters in the {name}: {' '.join(command[:2])}"
        check(f"{label}: none printed raw", not any(c in shown for c in "\x1b\x07\x9b\u202e"),
              repr(shown[-400:]))
        if (name, command[0]) in (("job resource", "status"), ("job resource", "list"), ("events", "watch"),
                                  ("invalid-job errors", "validate"), ("problem document", "status")) \
                and "--json" not in command:  # JSON output escapes them itself (\\u001b)
            check(f"{label}: shown escaped", "x\\x1b[31m\\x1b[2J\\x1b]0;owned\\x07\\x9b1m\\u202e" in shown,
                  repr(shown[-400:]))

check("python3 -m contact_client works", subprocess.run(
    [sys.executable, "-m", "contact_client", "--help"], capture_output=True, text=True,
    cwd=os.path.join(SRC, "clients")).returncode == 0)
server.sock.close()
finish()
