#!/usr/bin/env python3
"""clients/contact_client.py against the real contactd, as a module and as a command (subprocess):
submit, watch to the end, download, read the result into numpy arrays, plot (a PNG of the documented size that
is not blank); a progress stream cut mid-way resumed with Last-Event-ID; cancel and delete; the adaptive
example's plot; and the error paths: an invalid job file (exit 2, every pointer), a file that is not JSON, an
unknown id (404), the server down (connection refused), no answer (timeout), a token required but missing.

Standard library + numpy/h5py/matplotlib (Debian). Starts contactd through tests/server/harness.py (free loopback
port, temporary data directory, killed at exit). Prints "N passed, M failed"; exits 1 on any failure."""
import json
import os
import re
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

from client_paths import CLIENT, EXAMPLES, HERE, SRC  # noqa: E402,F401  (sets the import path)

import numpy as np  # noqa: E402

import contact_client as cc  # noqa: E402
import harness  # noqa: E402
from harness import HOST, Server, example, flat_patch, long_job  # noqa: E402
from checks import check, finish, section  # noqa: E402

SEED = os.path.join(EXAMPLES, "seed_layers.json")
ADAPTIVE = os.path.join(EXAMPLES, "seed_layers_adaptive.json")
UUID_RE = re.compile(r"^[0-9a-f]{8}-[0-9a-f]{4}-4[0-9a-f]{3}-[89ab][0-9a-f]{3}-[0-9a-f]{12}$")
UNKNOWN_ID = "00000000-0000-4000-8000-000000000000"

START = time.time()


def run(*args, url=None, token=None, stdin=None, timeout=60):
    """The client as a user runs it: a subprocess with CONTACT_URL (and CONTACT_TOKEN when given)."""
    env = {k: v for k, v in os.environ.items() if k not in ("CONTACT_URL", "CONTACT_TOKEN")}
    if url:
        env["CONTACT_URL"] = url
    if token:
        env["CONTACT_TOKEN"] = token
    return subprocess.run([sys.executable, CLIENT, *args], input=stdin, capture_output=True, text=True,
                          env=env, timeout=timeout)


def run_tty(*args, url=None, columns=120, timeout=60):
    """The client with its stderr on a terminal (a pseudo-terminal of `columns` columns), as a user sees it:
    (exit code, stdout, what the terminal received)."""
    import fcntl
    import pty
    import select
    import termios
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, columns, 0, 0))
    env = {k: v for k, v in os.environ.items() if k not in ("CONTACT_URL", "CONTACT_TOKEN")}
    env.update(CONTACT_URL=url, COLUMNS=str(columns))
    proc = subprocess.Popen([sys.executable, CLIENT, *args], stdout=subprocess.PIPE, stderr=slave, env=env)
    os.close(slave)
    received, deadline = b"", time.time() + timeout
    while time.time() < deadline:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            try:
                chunk = os.read(master, 65536)
            except OSError:  # the child closed its end
                break
            if not chunk:
                break
            received += chunk
        elif proc.poll() is not None:
            break
    os.close(master)
    out = proc.stdout.read().decode()
    proc.wait(timeout=10)
    return proc.returncode, out, received.decode("utf-8", "replace")


def png_size(path):
    """(width, height) from the PNG header."""
    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return None
    return struct.unpack(">II", head[16:24])


def check_png(name, path):
    if not check(f"{name}: PNG written", os.path.exists(path) and os.path.getsize(path) > 0, path):
        return
    check(f"{name}: 1000 x 800 pixels", png_size(path) == (1000, 800), png_size(path))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    img = mpimg.imread(path)[:, :, :3]
    non_white = float((img.min(axis=2) < 0.95).mean())
    check(f"{name}: not blank (pixel variance)", float(img.std()) > 0.05, img.std())
    check(f"{name}: drawn on (non-white pixels {non_white:.2f})", non_white > 0.15, non_white)
    # The mesh is coloured by stress: many distinct colours, not just black lines on white.
    colours = len(np.unique((img.reshape(-1, 3) * 255).astype(np.uint8), axis=0))
    check(f"{name}: coloured ({colours} colours)", colours > 50, colours)


def free_port():
    with socket.socket() as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


class DroppingProxy:
    """A TCP proxy in front of contactd that cuts the first progress stream (/events) after `cut_after` bytes of
    answer and forwards everything else untouched; it keeps the head of every request. With `cut_before` (bytes),
    every progress stream is cut instead where that text first comes (a stream that never shows its end)."""

    def __init__(self, port, cut_after=None, cut_before=None):
        self.port, self.cut_after, self.cut_before = port, cut_after, cut_before
        self.cut_done = False
        self.requests = []
        self.sock = socket.socket()
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.bind((HOST, 0))
        self.sock.listen(8)
        self.url = f"http://{HOST}:{self.sock.getsockname()[1]}"
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                client, _ = self.sock.accept()
            except OSError:
                return
            index = len(self.requests)
            self.requests.append(b"")
            threading.Thread(target=self._serve, args=(client, index), daemon=True).start()

    def _serve(self, client, index):
        try:
            upstream = socket.create_connection((HOST, self.port), timeout=30)
        except OSError:
            client.close()
            return

        def up():
            try:
                while True:
                    data = client.recv(65536)
                    if not data:
                        break
                    if len(self.requests[index]) < 4096:
                        self.requests[index] += data
                    upstream.sendall(data)
            except OSError:
                pass

        threading.Thread(target=up, daemon=True).start()
        sent, cut = 0, None
        try:
            while True:
                data = upstream.recv(65536)
                if not data:
                    break
                if cut is None:  # the request has been forwarded whole before any answer comes
                    cut = b"/events" in self.requests[index] and (self.cut_before is not None or not self.cut_done)
                    self.cut_done = self.cut_done or cut
                if cut and self.cut_before is not None and self.cut_before in data:
                    client.sendall(data[:data.index(self.cut_before)])
                    break
                if cut and self.cut_after is not None and sent + len(data) >= self.cut_after:
                    client.sendall(data[:self.cut_after - sent])
                    break  # the drop: both sides closed mid-stream
                client.sendall(data)
                sent += len(data)
        except OSError:
            pass
        for s in (client, upstream):
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            s.close()

    def close(self):
        self.sock.close()


def bad_job_file(tmp):
    job = example("seed_layers.json")
    job["bodies"][1]["material"]["nu"] = 0.5
    job["solver"]["gama"] = 0.1
    path = os.path.join(tmp, "bad.json")
    with open(path, "w") as f:
        json.dump(job, f)
    return path


def test_module(server, tmp):
    c = cc.Client(f"http://{HOST}:{server.port}", timeout=30)
    check("module: health", c.health().get("status") == "ok")
    v = c.validate(SEED)
    check("module: validate", v.get("valid") is True and v.get("dofs", 0) > 0 and len(v.get("bodies", [])) == 2, v)
    v = c.validate(os.path.join(EXAMPLES, "flat_patch_gmsh.json"))  # its meshes read and sent as "data"
    check("module: validate a job file with Gmsh meshes", v.get("valid") is True and v.get("dofs", 0) == 230, v)

    job = c.submit(SEED)
    jid = job.get("id", "")
    check("module: submit returns the job", UUID_RE.match(jid) and job.get("name") == "seed_layers", job)
    events = list(c.events(jid))
    seqs = [e.get("seq") for e in events]
    check("module: events numbered 1..N without gaps", seqs == list(range(1, len(seqs) + 1)), seqs)
    end = events[-1] if events else {}
    check("module: events stop at end", end.get("type") == "end" and end.get("state") == "SUCCEEDED", end)
    iterations = [e for e in events if e.get("type") == "iteration"]
    check("module: one iteration event per iteration", len(iterations) == end.get("iterations"),
          (len(iterations), end))
    final = c.wait(jid)
    check("module: wait returns the finished job", final.get("state") == "SUCCEEDED" and final.get("done")
          and final.get("result_available"), final)

    hdf = os.path.join(tmp, "module_seed.hdf")
    c.download(jid, hdf, xmf=True)
    check("module: download", os.path.getsize(hdf) > 1000)
    xmf = os.path.join(tmp, "module_seed.xmf")
    text = open(xmf).read() if os.path.exists(xmf) else ""
    check("module: sidecar refers to the downloaded name", "module_seed.hdf:/steps/0/bodies/upper/points" in text
          and "result.hdf" not in text, text[:300])

    r = cc.read_result(hdf)
    check("module: result attributes", r["attrs"].get("job_id") == jid and r["attrs"].get("name") == "seed_layers"
          and r["attrs"].get("iterations") == end.get("iterations"), r["attrs"])
    check("module: one step without adaptivity", len(r["steps"]) == 1, len(r["steps"]))
    pair = "upper.bottom-lower.top"
    cont = r["steps"][-1]["contacts"].get(pair, {})
    p = cont.get("pressure")
    check("module: pressure is a float numpy array", isinstance(p, np.ndarray) and p.dtype == np.float64
          and p.ndim == 1 and len(p) == len(cont.get("x", [])), type(p))
    last = iterations[-1]["pairs"][0] if iterations else {}
    check("module: final pressure equals the last iteration event's",
          p is not None and np.allclose(p, last.get("pressures", []), rtol=0, atol=1e-12)
          and np.allclose(cont["arc_length"], last.get("positions", [])), (p, last.get("pressures")))
    upper = r["steps"][-1]["bodies"].get("upper", {})
    check("module: mesh arrays", upper.get("points", np.zeros(0)).shape[1:] == (2,)
          and upper.get("quads", np.zeros(0)).shape[1:] == (4,)
          and len(upper.get("von_mises", [])) == len(upper.get("quads", [])),
          {k: np.shape(v) for k, v in upper.items()})
    hist = r["history"].get("iterations", {})
    check("module: iteration history", len(hist.get("iteration", [])) == end.get("iterations")
          and hist.get("pair_names") == [pair], hist.get("pair_names"))

    png = os.path.join(tmp, "module_seed.png")
    warp = cc.plot_result(r, png, events=events)["warp"]
    check_png("module plot", png)
    u = np.concatenate([b["displacement"] for b in r["steps"][-1]["bodies"].values()])
    check("module plot: the mesh drawn deformed, the largest displacement 2 to 4 % of the mesh's 4 cm",
          warp > 0 and 0.02 * 4 <= warp * np.abs(np.hypot(u[:, 0], u[:, 1])).max() <= 0.04 * 4 + 1e-12, warp)
    nodes = {"pressure": np.array([1.0, 2.0, 3.0, 4.0, 5.0]), "status": np.array([0, 1, 2, 3, 4], dtype=np.int8)}
    p = cc.plot.contact_pressure(nodes)
    check("module plot: nodes outside the contact (status 1 to 3) break the pressure curve",
          np.isnan(p[1:4]).all() and p[0] == 1.0 and p[4] == 5.0, p)

    check("module: status", c.status(jid).get("state") == "SUCCEEDED")
    listed = c.list()
    check("module: list contains the job", jid in [j["id"] for j in listed["jobs"]], listed)
    again = c.submit(flat_patch(name="second"), idempotency_key="client-test-key")
    replay = c.submit(flat_patch(name="second"), idempotency_key="client-test-key")
    check("module: idempotent submit returns the same job", again["id"] == replay["id"], (again, replay))
    c.wait(again["id"])
    paged = c.list(page_size=1, all_pages=True)
    ids = [j["id"] for j in paged["jobs"]]
    check("module: list follows next_page_token", len(ids) >= 2 and len(set(ids)) == len(ids)
          and {jid, again["id"]} <= set(ids) and paged["next_page_token"] == "", ids)
    check("module: list by state", all(j["state"] == "SUCCEEDED" for j in c.list(state="SUCCEEDED")["jobs"]))

    bad = example("seed_layers.json")
    bad["bodies"][1]["material"]["nu"] = 0.5
    try:
        c.submit(bad)
        check("module: invalid job raises", False)
    except cc.ApiError as e:
        check("module: invalid job is ApiError 400 with pointers", e.status == 400 and e.exit_code == 2
              and [x["pointer"] for x in e.errors] == ["/bodies/1/material/nu"]
              and e.lines[0].startswith("400 invalid job: /bodies/1/material/nu: nu = 0.5 is outside (-1, 0.5)"),
              e.lines)
    try:
        c.status(UNKNOWN_ID)
        check("module: unknown id raises", False)
    except cc.ApiError as e:
        check("module: unknown id is 404", e.status == 404 and e.lines[0].startswith("404 not found"), e.lines)

    # Cancel a running job; delete refused while it runs, accepted after.
    long_id = c.submit(long_job(name="to-cancel"))["id"]
    for e in c.events(long_id):
        if e.get("type") == "iteration":
            break
    try:
        c.delete(long_id)
        check("module: delete of a running job refused", False)
    except cc.ApiError as e:
        check("module: delete of a running job is 409", e.status == 409 and "state RUNNING" in e.lines[0], e.lines)
    c.cancel(long_id)
    done = c.wait(long_id)
    check("module: cancel", done.get("state") == "CANCELLED", done.get("state"))
    c.delete(long_id)
    try:
        c.status(long_id)
        check("module: deleted job gone", False)
    except cc.ApiError as e:
        check("module: deleted job gone", e.status == 404, e.lines)

    # A stream cut mid-way (a proxy drops the first connection) is resumed with Last-Event-ID: every event once.
    proxy = DroppingProxy(server.port, cut_after=20000)
    notes = []
    try:
        pc = cc.Client(proxy.url, timeout=30, log=notes.append)
        rid = pc.submit(long_job(max_iterations=300, name="resumed"))["id"]
        got = list(pc.events(rid))
    finally:
        proxy.close()
    seqs = [e.get("seq") for e in got]
    check("resume: every event exactly once, in order", seqs == list(range(1, len(seqs) + 1))
          and got[-1].get("type") == "end" and got[-1].get("iterations") == 300, (seqs[:5], seqs[-5:], len(seqs)))
    stream_requests = [r for r in proxy.requests if b"/events" in r]
    check("resume: the client reconnected", len(stream_requests) >= 2, [r[:80] for r in proxy.requests])
    if len(stream_requests) >= 2:
        m = re.search(rb"last-event-id: *(\d+)", stream_requests[1], re.I)
        first_part = next((i for i, s in enumerate(seqs) if m and s == int(m.group(1))), None)
        check("resume: reconnected with Last-Event-ID of the last event received",
              m is not None and 1 <= int(m.group(1)) < len(seqs) and first_part is not None, stream_requests[1][:300])
    check("resume: the reconnection was reported", any("reconnecting" in n for n in notes), notes)

    # A stream that closes without its end event, each time (a proxy in the way), of a job that has ended: wait()
    # returns the ended job once a reconnection brings nothing new, instead of reconnecting to the same close until
    # it gives up.
    proxy = DroppingProxy(server.port, cut_before=b"event: end")
    notes = []
    try:
        pc = cc.Client(proxy.url, timeout=30, log=notes.append)
        ended = pc.wait(rid, max_retries=2)
    except cc.ClientError as e:
        ended = {"error": str(e)}
    finally:
        proxy.close()
    check("a stream without its end, of an ended job: wait() returns the job once a reconnection brings nothing",
          ended.get("id") == rid and ended.get("done") is True and len([r for r in proxy.requests if b"/events" in r]) == 2,
          (ended, notes))
    check("... and says why", any("has ended" in n for n in notes), notes)

    # Adaptivity: several steps, refined meshes; the plot shows them.
    aid = c.submit(ADAPTIVE)["id"]
    fin = c.wait(aid)
    check("adaptive: SUCCEEDED", fin.get("state") == "SUCCEEDED", fin)
    ahdf = os.path.join(tmp, "adaptive.hdf")
    c.download(aid, ahdf)
    ar = cc.read_result(ahdf)
    lower = [s["bodies"]["lower"] for s in ar["steps"]]
    check("adaptive: several steps, the lower body refined",
          len(ar["steps"]) > 1 and int(lower[-1]["level"].max()) > 0
          and len(lower[-1]["quads"]) > len(lower[0]["quads"]),
          (len(ar["steps"]), [len(b["quads"]) for b in lower]))
    check("adaptive: pressure per pair per step", all(len(s["contacts"]["upper.bottom-lower.top"]["pressure"]) > 0
                                                      for s in ar["steps"]))
    apng = os.path.join(tmp, "adaptive.png")
    cc.plot_result(ahdf, apng)
    check_png("adaptive plot", apng)

    # A Gmsh job file: its meshes go in as "data"; triangles are read and drawn.
    gid = c.submit(os.path.join(EXAMPLES, "flat_patch_gmsh.json"))["id"]
    fin = c.wait(gid)
    check("gmsh: SUCCEEDED", fin.get("state") == "SUCCEEDED", fin)
    ghdf = os.path.join(tmp, "gmsh.hdf")
    c.download(gid, ghdf)
    gr = cc.read_result(ghdf)
    types = {name: set(b["cell_types"].tolist()) for name, b in gr["steps"][-1]["bodies"].items()}
    check("gmsh: triangles read", types == {"upper": {5}, "lower": {5}}
          and "quads" not in gr["steps"][-1]["bodies"]["upper"], types)
    gpng = os.path.join(tmp, "gmsh.png")
    cc.plot_result(ghdf, gpng)
    check_png("gmsh plot", gpng)

    # Load steps: the force-load curve (Fig. 4 as a curve) from /history/steps, drawn as its own panel.
    lid = c.submit(os.path.join(EXAMPLES, "seed_layers_steps.json"))["id"]
    fin = c.wait(lid)
    check("load steps: SUCCEEDED", fin.get("state") == "SUCCEEDED", fin)
    lhdf = os.path.join(tmp, "steps.hdf")
    c.download(lid, lhdf)
    lr = cc.read_result(lhdf)
    curve = cc.load_curve(lr)
    check("load steps: a load curve of 10 steps at load factors 0.1 ... 1",
          curve is not None and np.allclose(curve["load_factor"], np.arange(1, 11) / 10, rtol=0, atol=1e-12)
          and [s["load_factor"] for s in lr["steps"]] == list(curve["load_factor"]),
          curve and curve["load_factor"])
    if curve is not None:
        lp = curve["pairs"].get(pair, {})
        force, width = lp.get("force", np.zeros(0)), lp.get("width", np.zeros(0))
        check("load steps: force strictly and contact width weakly increasing with the load",
              len(force) == 10 and np.all(np.diff(force) > 0) and np.all(np.diff(width) >= 0) and width[0] > 0,
              (force, width))
        # With the dual mortar basis the pair's force is the trapezoidal integral of its nodal pressures
        # (D holds the lumped weights), so each step's curve point must equal the integral of that step's profile.
        trapezoid = getattr(np, "trapezoid", None) or np.trapz  # numpy 2 renamed trapz
        integrals = [trapezoid(s["contacts"][pair]["pressure"], s["contacts"][pair]["x"]) for s in lr["steps"]]
        check("load steps: each step's force = the integral of its pressure profile",
              len(force) == len(integrals) and np.allclose(force, integrals, rtol=1e-9, atol=0), (force, integrals))
    check("no load curve for an adaptive run (its steps share load factor 1)", cc.load_curve(ar) is None)
    lpng = os.path.join(tmp, "steps.png")
    cc.plot_result(lr, lpng)
    check_png("load steps plot", lpng)


def test_cli(server, tmp):
    url = f"http://{HOST}:{server.port}"
    hdf, ev, png = (os.path.join(tmp, n) for n in ("cli_seed.hdf", "cli_events.ndjson", "cli_seed.png"))
    r = run("submit", SEED, "--wait", "-o", hdf, "--events-out", ev, url=url)
    out = r.stdout.splitlines()
    check("cli submit --wait exits 0", r.returncode == 0, r.stdout + r.stderr)
    jid = out[0] if out else ""
    check("cli submit prints the id", UUID_RE.match(jid) is not None and len(out) == 1, r.stdout)
    lines = [l for l in r.stderr.splitlines() if l.startswith("iter ")]
    check("cli progress: one line per iteration (not a terminal)", len(lines) >= 2, r.stderr[:500])
    if lines:
        check("cli progress line: residuals, dofs per body, force, max pressure",
              all(w in lines[-1] for w in ("paper ", "residual ", "dofs upper ", " lower ", "force ", "p_max ")),
              lines[-1])
    check("cli progress ends with the state", "end SUCCEEDED (converged)" in r.stderr, r.stderr[-400:])

    # On a terminal: a tqdm counter redrawn in place with the iteration, the measure, the active set and the
    # elapsed time; the state changes above it; the end line after it.
    code, out, screen = run_tty("submit", SEED, "--wait", url=url)
    check("cli on a terminal: exit 0, the id on stdout", code == 0 and UUID_RE.match(out.strip()), (code, out))
    redraws = [part.split("\n")[0].rstrip() for part in screen.split("\r") if part.startswith("iter ")]
    counter = r"^iter \d+ .*  \[\d\d:\d\d, [0-9.?]+ ?it/s\]$"
    check("cli on a terminal: a tqdm counter redrawn in place",
          len(redraws) >= 2 and all(re.match(counter, part) for part in redraws), screen[:600])
    last = redraws[-1] if redraws else ""
    check("cli on a terminal: iteration, residuals, active set, force, elapsed in the counter",
          all(w in last for w in ("paper ", "res ", "active ", "force ", "p_max ")), last)
    check("cli on a terminal: lines fit the terminal", all(len(line) <= 120 for part in screen.split("\r")
                                                           for line in part.split("\n")), screen[:300])
    check("cli on a terminal: states above, the end after",
          "state RUNNING" in screen and re.search(r"end SUCCEEDED \(converged\) after \d+ iterations", screen)
          and screen.index("state RUNNING") < screen.index("end SUCCEEDED"), screen[-400:])

    # -q: nothing but errors.
    r = run("submit", SEED, "--wait", "-q", "-o", os.path.join(tmp, "quiet.hdf"), url=url)
    check("cli -q: silent on success (only the id on stdout)", r.returncode == 0 and r.stderr == ""
          and UUID_RE.match(r.stdout.strip()) and os.path.exists(os.path.join(tmp, "quiet.hdf")), r)
    code, out, screen = run_tty("watch", out.strip() or jid, "-q", url=url)
    check("cli -q on a terminal: silent", code == 0 and screen.strip() == "", repr(screen[:300]))
    check("cli submit -o downloads", os.path.exists(hdf) and os.path.getsize(hdf) > 1000)
    saved = cc.read_events(ev) if os.path.exists(ev) else []
    check("cli --events-out saves every event", [e["seq"] for e in saved] == list(range(1, len(saved) + 1))
          and saved and saved[-1]["type"] == "end", len(saved))

    # A FAILED job with load steps that held (issue 31): a 4 x 4 frictional wall sheared past mu in step 2 is
    # refused there; the client still downloads its result, which keeps step 1, and exits with the job's error.
    wall = subprocess.run(["/usr/bin/python3", os.path.join(SRC, "scripts", "make_brick_wall.py"), "--rows", "4",
                           "--bricks", "4", "--head-joints", "--friction", "0.6", "--shear", "0.65", "-o", "-"],
                          capture_output=True, text=True)
    failed_hdf = os.path.join(tmp, "refused.hdf")
    r = run("submit", "-", "--wait", "-q", "-o", failed_hdf, url=url, stdin=wall.stdout)
    check("cli: a FAILED job exits non-zero naming the refused step",
          r.returncode != 0 and "ended FAILED" in r.stderr and "load step 2 of 2: friction cannot hold" in r.stderr,
          r.stderr[-400:])
    held = []
    if os.path.exists(failed_hdf):
        import h5py
        with h5py.File(failed_hdf, "r") as f:
            held = list(f["history/steps/converged"][()])
    check("cli: the FAILED job's result is downloaded with the step that held", held == [1], (held, r.stderr[-300:]))

    r = run("submit", "-", url=url, stdin=json.dumps(flat_patch(name="from-stdin")))
    check("cli submit - reads standard input", r.returncode == 0 and UUID_RE.match(r.stdout.strip()), r)
    stdin_id = r.stdout.strip()

    r = run("watch", jid, url=url)
    check("cli watch of a finished job replays to the end", r.returncode == 0 and "end SUCCEEDED" in r.stderr,
          r.stderr[-300:])
    r = run("status", jid, url=url)
    check("cli status", r.returncode == 0 and re.search(r"state:\s+SUCCEEDED", r.stdout), r.stdout)
    r = run("status", jid, "--json", url=url)
    check("cli status --json", r.returncode == 0 and json.loads(r.stdout).get("id") == jid, r.stdout[:200])
    r = run("list", url=url)
    check("cli list", r.returncode == 0 and jid in r.stdout and stdin_id in r.stdout, r.stdout)
    r = run("list", "--json", "--all", "--page-size", "1", url=url)
    try:
        listed = [j["id"] for j in json.loads(r.stdout)["jobs"]]
    except (ValueError, KeyError):
        listed = []
    check("cli list --all follows the pages", jid in listed and len(listed) == len(set(listed)) >= 2, r.stdout[:300])

    dl = os.path.join(tmp, "cli_download.hdf")
    r = run("download", jid, "-o", dl, "--xmf", url=url)
    check("cli download", r.returncode == 0 and os.path.exists(dl) and open(dl, "rb").read() == open(hdf, "rb").read(),
          r.stdout + r.stderr)
    check("cli download --xmf", os.path.exists(os.path.join(tmp, "cli_download.xmf")))
    r = run("plot", dl, "-o", png, "--events", ev)
    check("cli plot exits 0", r.returncode == 0, r.stdout + r.stderr)
    check_png("cli plot", png)
    m = re.search(r"mesh displaced x ([0-9.e+-]+)\)", r.stdout)
    check("cli plot draws the deformed mesh by default (a scale that shows the displacement)",
          m is not None and float(m.group(1)) >= 10, r.stdout)
    r = run("plot", dl, "-o", os.path.join(tmp, "flat.png"), "--warp", "0")
    check("cli plot --warp 0: undeformed", r.returncode == 0 and "undeformed mesh" in r.stdout, r.stdout + r.stderr)
    check("the deformed and undeformed plots differ",
          open(png, "rb").read() != open(os.path.join(tmp, "flat.png"), "rb").read())
    r = run("plot", os.path.join(tmp, "missing.hdf"), "-o", os.path.join(tmp, "x.png"))
    check("cli plot of a missing file: exit 2", r.returncode == 2 and r.stderr.startswith("error: "), r.stderr)

    r = run("validate", SEED, url=url)
    check("cli validate", r.returncode == 0 and r.stdout.startswith("valid: seed_layers"), r.stdout + r.stderr)
    bad = bad_job_file(tmp)
    for cmd in ("validate", "submit"):
        r = run(cmd, bad, url=url)
        err = r.stderr.splitlines()
        check(f"cli {cmd} of an invalid job: exit 2", r.returncode == 2, r.returncode)
        check(f"cli {cmd} of an invalid job: one line per error with its pointer",
              len(err) == 2 and err[0].startswith("error: 400 invalid job: /bodies/1/material/nu: nu = 0.5 is outside")
              and err[1].startswith("error: 400 invalid job: /solver/gama: "), r.stderr)
        check(f"cli {cmd} of an invalid job: nothing on stdout", r.stdout == "", r.stdout)
    notjson = os.path.join(tmp, "notjson.json")
    with open(notjson, "w") as f:
        f.write('{"name": "x",\n')
    r = run("submit", notjson, url=url)
    check("cli submit of a file that is not JSON: exit 2, where", r.returncode == 2 and "not JSON" in r.stderr
          and "line 2" in r.stderr and len(r.stderr.splitlines()) == 1, r.stderr)
    r = run("submit", os.path.join(tmp, "nope.json"), url=url)
    check("cli submit of a missing file: exit 2", r.returncode == 2 and "cannot read" in r.stderr, r.stderr)

    for args in (("status", UNKNOWN_ID), ("watch", UNKNOWN_ID), ("cancel", UNKNOWN_ID), ("delete", UNKNOWN_ID),
                 ("download", UNKNOWN_ID, "-o", os.path.join(tmp, "u.hdf"))):
        r = run(*args, url=url)
        check(f"cli {args[0]} of an unknown id: exit 1, one 404 line", r.returncode == 1
              and r.stderr.startswith("error: 404 not found") and len(r.stderr.splitlines()) == 1, r.stderr)

    # Cancel from the command line; watch reports the state and exits 3.
    long_id = run("submit", "-", url=url, stdin=json.dumps(long_job(name="cli-cancel"))).stdout.strip()
    watcher = subprocess.Popen([sys.executable, CLIENT, "watch", long_id, "--url", url], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    server.wait_for(long_id, lambda j: j.get("state") == "RUNNING" and j.get("iterations", 0) > 0, timeout=30)
    r = run("cancel", long_id, url=url)
    check("cli cancel", r.returncode == 0 and long_id in r.stdout, r.stdout + r.stderr)
    try:
        wout, werr = watcher.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        watcher.kill()
        wout, werr = watcher.communicate()
    check("cli watch of a cancelled job: exit 3, state printed", watcher.returncode == 3
          and "end CANCELLED" in werr and "error: job " + long_id + " ended CANCELLED (cancelled)" in werr,
          (watcher.returncode, werr[-300:]))
    r = run("watch", long_id, "-q", url=url)
    check("cli watch -q of a cancelled job: exit 3, one error line",
          r.returncode == 3 and r.stderr.startswith("error: job ") and len(r.stderr.splitlines()) == 1, r.stderr)
    r = run("delete", long_id, url=url)
    check("cli delete", r.returncode == 0, r.stderr)

    # Usage errors.
    check("cli without a command: exit 2", run().returncode == 2)
    check("cli download without -o: exit 2", run("download", jid, url=url).returncode == 2)
    r = run("status", jid, "--url", "ftp://host")
    check("cli bad --url: exit 2", r.returncode == 2 and "bad server URL" in r.stderr, r.stderr)


def test_unreachable(tmp):
    port = free_port()  # nothing listens there now
    url = f"http://{HOST}:{port}"
    r = run("status", UNKNOWN_ID, url=url)
    check("server down: exit 1", r.returncode == 1, r.returncode)
    check("server down: one line, connection refused", r.stderr ==
          f"error: cannot connect to {url} (connection refused) - is contactd running?\n", r.stderr)
    r = run("submit", SEED, "--url", url)
    check("server down: submit exit 1", r.returncode == 1 and "connection refused" in r.stderr, r.stderr)
    try:
        cc.Client(url).list()
        check("server down: module raises", False)
    except cc.ConnectionFailed as e:
        check("server down: module raises ConnectionFailed", "connection refused" in str(e), str(e))

    # A socket that accepts connections (the kernel's backlog) but never answers: the timeout.
    with socket.socket() as silent:
        silent.bind((HOST, 0))
        silent.listen(4)
        surl = f"http://{HOST}:{silent.getsockname()[1]}"
        t0 = time.time()
        r = run("status", UNKNOWN_ID, "--timeout", "1", url=surl)
        took = time.time() - t0
        check("no answer: exit 1 with a timeout line", r.returncode == 1 and "timeout" in r.stderr
              and len(r.stderr.splitlines()) == 1, r.stderr)
        print(f"no answer, --timeout 1: gave up after {took:.1f} s", flush=True)
        # About a second (printed); a client that ignored --timeout would wait its default 30 s. 20 s is broken only
        # by that, not by a loaded machine.
        check(f"no answer: gives up by --timeout, not the default 30 s ({took:.1f} s measured)", took < 20, took)


def test_token(tmp):
    with Server(token="client-test-token") as server:
        url = f"http://{HOST}:{server.port}"
        r = run("list", url=url)
        check("token missing: exit 1", r.returncode == 1, r.returncode)
        check("token missing: one 401 line naming the fix", r.stderr.startswith("error: 401 ")
              and "CONTACT_TOKEN" in r.stderr and len(r.stderr.splitlines()) == 1, r.stderr)
        r = run("list", "--token", "wrong", url=url)
        check("token wrong: 401", r.returncode == 1 and "401" in r.stderr, r.stderr)
        r = run("list", "--token", "client-test-token", url=url)
        check("token from --token", r.returncode == 0, r.stderr)
        r = run("submit", "-", "--wait", url=url, token="client-test-token",
                stdin=json.dumps(flat_patch(name="with-token")))
        check("token from CONTACT_TOKEN: submit --wait", r.returncode == 0 and "end SUCCEEDED" in r.stderr, r.stderr)
        c = cc.Client(url, token="client-test-token")
        job = c.submit(flat_patch(name="module-token"))
        check("token: module submit and wait", c.wait(job["id"]).get("state") == "SUCCEEDED")


def test_adaptive_step_words():
    """The progress display's words for an adaptive step (issue 50): the unknowns over the bodies, the estimated
    pressure error, and the largest change the stop test reads against the step it names; nothing of the changes
    before there is such a step (null in the event)."""
    event = {"type": "adaptive_step", "step": 5, "bodies": [{"unknowns": 1200}, {"unknowns": 800}],
             "pressure_estimate": 0.0042, "compared_with": 2, "force_change": 0.001, "peak_change": 0.0031,
             "extent_change": 0.0007, "stick_change": None, "tangential_change": None}
    words = cc.display.adaptive_step_words(event)
    check("adaptive step words: unknowns summed, pressure error, the largest change and its step",
          words == "adaptive step 5: 2000 unknowns, pressure error ~0.42 %; against step 2: the answer changed by at "
                   "most 0.31 %", words)
    first = cc.display.adaptive_step_words(dict(event, step=0, compared_with=-1, force_change=None, peak_change=None,
                                                extent_change=None, pressure_estimate=None))
    check("adaptive step words before a step to compare with: no changes, no estimate",
          first == "adaptive step 0: 2000 unknowns", first)


def main():
    test_adaptive_step_words()
    if not os.path.exists(harness.CONTACTD):
        check(f"contactd not built: {harness.CONTACTD}", False)
        finish()
    with tempfile.TemporaryDirectory(prefix="contact-client-test-") as tmp:
        with Server() as server:
            for name, fn in (("module", lambda: test_module(server, tmp)), ("cli", lambda: test_cli(server, tmp))):
                # a crash of one group is a failure, the others still run
                with section(name, f"{name} tests ran to the end"):
                    fn()
        for name, fn in (("unreachable", lambda: test_unreachable(tmp)), ("token", lambda: test_token(tmp))):
            with section(name, f"{name} tests ran to the end"):
                fn()
    print(f"total {time.time() - START:.1f} s", flush=True)
    finish()


if __name__ == "__main__":
    main()
