#!/usr/bin/env python3
"""Connection floods never starve the service (issue 10, item 5): /healthz and /readyz answer while 300 slowloris
connections (one header line at a time) and then 500 idle connections are open, without waiting for them (the
worst probe is printed; its bound only catches a starved server); a request head has a deadline (408) that a
dripping head does not renew; header count and size are limited (431), the request line too (414); connections are
capped in total and per address (503 beyond, after the connection waiting longest is closed to make room); the
listen backlog is large; keep-alive and pipelining still work."""
import os
import re
import socket
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/: checks.py
from harness import HOST, Server  # noqa: E402
from checks import check, finish  # noqa: E402

# A probe answers in milliseconds under the floods (printed). A server starved by them answers a probe only when a
# held connection's 10 s head deadline frees it, or never; a loaded 2-core machine makes it slower, but not by
# seconds: 5 s is broken only by starvation.
PROBE_BOUND = 5.0


def timed_get(server, path, timeout=10):
    """(status, seconds) of one GET on a fresh connection; status None if it failed or timed out."""
    start = time.time()
    try:
        status = server.request("GET", path, timeout=timeout).status
    except OSError:
        status = None
    return status, time.time() - start


def open_slow(server, n, first=b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n"):
    socks = []
    for _ in range(n):
        s = socket.create_connection((HOST, server.port), timeout=5)
        if first:
            s.sendall(first)
        socks.append(s)
    return socks


def answer_of(sock, timeout=3.0):
    """What the server sent on a connection until it closed it (or the timeout)."""
    sock.settimeout(timeout)
    data = b""
    try:
        while True:
            chunk = sock.recv(65536)
            if not chunk:
                break
            data += chunk
    except (socket.timeout, ConnectionResetError):
        pass
    return data


def probe_latencies(server, rounds, drip=None, pause=0.25):
    worst = 0.0
    statuses = set()
    for _ in range(rounds):
        if drip:
            drip()
        for path in ("/healthz", "/readyz"):
            status, seconds = timed_get(server, path)
            statuses.add(status)
            worst = max(worst, seconds)
        time.sleep(pause)
    return worst, statuses


with Server(args=["--workers", "1"]) as server:
    # --- 300 slowloris connections: each sends one more header line every round --------------------------------
    slow = open_slow(server, 300)
    line = [0]

    def drip():
        line[0] += 1
        for s in slow:
            try:
                s.sendall(b"X-Slow-%d: 1\r\n" % line[0])
            except OSError:
                pass

    worst, statuses = probe_latencies(server, 12, drip)
    print(f"/healthz and /readyz with 300 slow connections: worst {worst * 1000:.1f} ms", flush=True)
    check("300 slow connections: /healthz and /readyz all 200", statuses == {200}, statuses)
    check(f"300 slow connections: no probe waits for the slow heads ({worst * 1000:.0f} ms measured)",
          worst < PROBE_BOUND, worst)
    open_now = server.metric("contactd_connections")
    check("the slow connections are held open (by the gate, not by threads)", open_now is not None and open_now >= 300,
          open_now)
    ok = server.submit(__import__("harness").flat_patch())
    check("the API serves meanwhile", ok.status == 202, ok)
    for s in slow:
        s.close()

    # --- 500 idle connections (connected, nothing sent) -------------------------------------------------------
    idle = open_slow(server, 500, first=None)
    worst, statuses = probe_latencies(server, 6)
    print(f"/healthz and /readyz with 500 idle connections: worst {worst * 1000:.1f} ms", flush=True)
    check(f"500 idle connections: /healthz and /readyz all 200, none waits for the idle ones ({worst * 1000:.0f} ms "
          "measured)", statuses == {200} and worst < PROBE_BOUND, (statuses, worst))
    for s in idle:
        s.close()

    # --- limits on the head ------------------------------------------------------------------------------------
    many = b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n" + b"".join(b"X-H%d: v\r\n" % k for k in range(70)) + b"\r\n"
    raw = server.raw(many)
    check("70 header fields -> 431", raw.startswith(b"HTTP/1.1 431") and b"problem+json" in raw, raw[:200])
    big = b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Big: " + b"a" * 20000 + b"\r\n\r\n"
    raw = server.raw(big)
    check("a 20 kB header -> 431", raw.startswith(b"HTTP/1.1 431"), raw[:200])
    raw = server.raw(b"GET /" + b"a" * 5000 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    check("a 5000-byte request line -> 414", raw.startswith(b"HTTP/1.1 414"), raw[:200])
    raw = server.raw(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n folded: value\r\n\r\n")
    check("obs-fold -> 400", raw.startswith(b"HTTP/1.1 400"), raw[:200])
    raw = server.raw(b"GET /healthz HTTP/1.1\nHost: 127.0.0.1\n\n")
    check("bare LF line endings -> 400", raw.startswith(b"HTTP/1.1 400"), raw[:200])

    # --- keep-alive and pipelining still work -------------------------------------------------------------------
    conn = server.connection()
    ports = set()
    for _ in range(3):
        conn.request("GET", "/healthz")
        r = conn.getresponse()
        r.read()
        ports.add(conn.sock.getsockname()[1])
    conn.close()
    check("keep-alive: three requests on one connection", len(ports) == 1 and r.status == 200, ports)
    with socket.create_connection((HOST, server.port), timeout=5) as s:
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\nGET /readyz HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                  b"Connection: close\r\n\r\n")
        both = answer_of(s)
    check("pipelining: both requests answered", both.count(b"HTTP/1.1 200") == 2, both[:300])

    # --- the backlog --------------------------------------------------------------------------------------------
    listing = subprocess.run(["ss", "-ltnH", f"sport = :{server.port}"], capture_output=True, text=True).stdout
    backlog = [int(m.group(1)) for m in re.finditer(r"LISTEN\s+\d+\s+(\d+)", listing)]
    check("listen backlog 1024 (was 5)", backlog == [1024], listing)

# --- the request-head deadline ---------------------------------------------------------------------------------
with Server(args=["--workers", "1", "--request-head-timeout-seconds", "1"]) as server:
    # The head keeps dripping (a line every 0.3 s) for up to DRIP_FOR: the 1 s deadline must cut it off while it
    # drips. Only a deadline that each line renews lets it drip to the end; DRIP_FOR is a bound only that breaks.
    DRIP_FOR = 30.0
    dripping = open_slow(server, 1)[0]
    silent = open_slow(server, 1, first=None)[0]
    start = time.time()
    answers = []
    while time.time() - start < DRIP_FOR and len(answers) < 1:
        try:
            dripping.sendall(b"X-Drip: 1\r\n")
        except OSError:
            break
        time.sleep(0.3)
        dripping.settimeout(0.01)
        try:
            chunk = dripping.recv(4096)
            if chunk:
                answers.append(chunk)
        except (socket.timeout, BlockingIOError):
            pass
    elapsed = time.time() - start
    got = b"".join(answers) + answer_of(dripping, 2)
    print(f"a head dripping one line at a time: cut off {elapsed:.2f} s after its first line (deadline 1 s)",
          flush=True)
    check(f"a head dripping one line at a time gets 408 while it still drips: the lines do not renew the deadline "
          f"({elapsed:.2f} s measured)", got.startswith(b"HTTP/1.1 408") and elapsed < DRIP_FOR, (elapsed, got[:200]))
    got = answer_of(silent, 3)
    check("a silent connection gets 408 and is closed", got.startswith(b"HTTP/1.1 408"), got[:200])

# --- connection caps -----------------------------------------------------------------------------------------
with Server(args=["--workers", "1", "--max-connections", "20", "--max-connections-per-client", "0"]) as server:
    time.sleep(0.3)  # the harness's readiness probe has closed its connection: the caps count only ours
    held = open_slow(server, 20, first=None)
    time.sleep(0.2)
    extra = socket.create_connection((HOST, server.port), timeout=5)
    extra.sendall(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    got = answer_of(extra)
    check("over --max-connections with nothing to evict: 503 + Retry-After",
          got.startswith(b"HTTP/1.1 503") and b"Retry-After: 5" in got, got[:300])
    time.sleep(1.2)  # the held connections have now waited over a second for a head: the oldest makes room
    status, seconds = timed_get(server, "/healthz")
    check("at the cap, a whole request still gets in (the longest-waiting connection is closed)", status == 200,
          (status, seconds))
    evicted = sum(1 for s in held if answer_of(s, 0.2).startswith(b"HTTP/1.1 408"))
    check("the evicted connection was told 408", evicted >= 1, evicted)
    for s in held:
        s.close()

with Server(args=["--workers", "1", "--max-connections-per-client", "5"]) as server:
    time.sleep(0.3)
    held = open_slow(server, 5, first=None)
    extra = socket.create_connection((HOST, server.port), timeout=5)
    extra.sendall(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    got = answer_of(extra)
    check("over --max-connections-per-client: 503", got.startswith(b"HTTP/1.1 503") and b"this address" in got,
          got[:300])
    for s in held:
        s.close()

finish()
