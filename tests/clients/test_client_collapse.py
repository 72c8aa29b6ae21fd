#!/usr/bin/env python3
"""A collapse analysis through the server and the client (issue 48, items 1, 2 and 4): a running-bond wall of 2:1
stones on a clamped base, precompressed (dead) and sheared at its top (live), Coulomb mu = 0.6 on every joint.

- contact-solve and contactd give the same collapse multiplier (the bracket [held, failed] to 1e-3), below the
  rigid-block statics' bound (an upper bound: the elastic solution's contact forces are the blocks' too), and name
  a mechanism;
- the job resource and its end event carry `collapse`; the progress events carry each trial's `multiplier`;
- `submit --wait` prints the verdict; the result file's /collapse is what the end event says; the file's steps are
  the states that held, their multipliers rising to the one that held last;
- `contact_client collapse` draws the capacity curve and the mechanism and prints the verdict; on a file without a
  collapse analysis it says so (exit 2).

Standard library + h5py (Debian). Starts contactd through tests/server/harness.py. Exits 1 on any failure."""
import json
import os
import subprocess
import sys
import tempfile

from client_paths import CLIENT, EXAMPLES, SRC  # noqa: E402  (sets the import path)

import contact_client as cc  # noqa: E402
from harness import Server  # noqa: E402
from checks import check, finish, section  # noqa: E402

BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
SOLVE = os.path.join(BIN, "contact-solve")


def client(url, *args):
    return subprocess.run([sys.executable, CLIENT, *args], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "CONTACT_URL": url})


def close(a, b, rel=1e-3):
    return abs(a - b) <= rel * max(abs(a), abs(b))


with tempfile.TemporaryDirectory() as tmp:
    job = os.path.join(tmp, "wall.json")
    subprocess.run([sys.executable, os.path.join(SRC, "scripts", "make_brick_wall.py"), "--rows", "4", "--bricks",
                    "4", "--head-joints", "--friction", "0.6", "--brick-height", "0.12", "--collapse", "-o", job],
                   check=True, capture_output=True, timeout=60)
    reference = os.path.join(tmp, "reference.hdf")
    r = subprocess.run([SOLVE, job, "-o", reference, "-q"], capture_output=True, text=True, timeout=300)
    check("contact-solve: the collapse analysis ends converged (exit 0)", r.returncode == 0, r.stderr[-500:])
    with cc.ResultFile(reference) as f:
        ref = f.collapse()
    check("contact-solve: the verdict is a collapse, bracketed to the tolerance",
          ref is not None and ref["verdict"] == "collapse" and ref["failed"] - ref["held"] <=
          ref["tolerance"] * ref["held"] * (1 + 1e-9), ref and {k: ref[k] for k in ("verdict", "held", "failed")})
    check("contact-solve: lambda_c below the rigid-block statics' bound, and a mechanism named",
          ref["failed"] <= ref["statics_bound"] * (1 + ref["tolerance"]) and ref["mechanism"]["kind"] != "",
          (ref["held"], ref["statics_bound"], ref["mechanism"].get("kind")))
    t = ref.get("trials", {})
    held = sorted((m, d) for m, h, d in zip(t.get("multiplier", []), t.get("held", []), t.get("displacement", [])) if h)
    check("ResultFile.collapse(): the trials with the capacity curve's displacement, growing with the multiplier",
          len(held) >= 2 and all(d > 0 for _, d in held) and all(b[1] > a[1] for a, b in zip(held, held[1:])) and
          all(d != d for h, d in zip(t.get("held", []), t.get("displacement", [])) if not h), held)

    with Server() as server:
        url = f"http://127.0.0.1:{server.port}"
        with section("through contactd: submit --wait"):
            out = os.path.join(tmp, "wall.hdf")
            s = client(url, "submit", "--wait", "-o", out, job)
            check("exit 0, and the verdict printed", s.returncode == 0 and "collapse: lambda_c between" in s.stderr,
                  (s.returncode, s.stderr[-800:]))
            job_id = s.stdout.strip().splitlines()[0]
            resource = server.job(job_id)
            served = resource.get("collapse") or {}
            check("the job resource's collapse: the same bracket as contact-solve's, to 1e-3",
                  served.get("verdict") == "collapse" and close(served.get("held", 0), ref["held"]) and
                  close(served.get("failed", 0), ref["failed"]), (served.get("held"), served.get("failed"), ref["held"]))
            events = list(cc.Client(url).events(job_id))
            ends = [e for e in events if e.get("type") == "end"]
            check("the end event carries it", len(ends) == 1 and ends[0].get("collapse", {}).get("held") ==
                  served.get("held"), ends and ends[0].get("collapse", {}).get("held"))
            reported = [e for e in events if e.get("type") == "load_step"]
            check("one load_step event per trial, in order, saying whether it held",
                  len(reported) == served.get("solves") and all(e.get("kind") == "trial" for e in reported) and
                  [e.get("held") for e in reported] == [t.get("held") for t in served.get("trials", [])],
                  (len(reported), served.get("solves")))
            check("submit --wait printed the trials in their own words",
                  s.stdout.count("collapse trial ") + s.stderr.count("collapse trial ") == served.get("solves"),
                  s.stderr[-500:])
            trials = sorted({e["multiplier"] for e in events if e.get("type") == "iteration" and "multiplier" in e})
            check("the iteration events carry the trials' multipliers, the largest that held among them",
                  len(trials) >= 2 and served.get("held") in trials, trials)
            with cc.ResultFile(out) as f:
                stored = f.collapse()
                multipliers = list(f.history("steps").get("multiplier", []))
            check("the result file's /collapse is what the job says",
                  stored["verdict"] == served["verdict"] and stored["held"] == served["held"] and
                  stored["mechanism"]["kind"] == served["mechanism"]["kind"], (stored["held"], served.get("held")))
            check("the steps: the loading's end (0), then the states that held, rising to the last",
                  multipliers[0] == 0 and all(b > a for a, b in zip(multipliers, multipliers[1:])) and
                  multipliers[-1] == stored["held"], multipliers)

        with section("the collapse view"):
            png = os.path.join(tmp, "wall.png")
            v = client(url, "collapse", out, "-o", png)
            check("contact_client collapse: exit 0, a PNG, the verdict printed",
                  v.returncode == 0 and os.path.getsize(png) > 10000 and "verdict: collapse at lambda_c" in v.stdout,
                  (v.returncode, v.stdout[-300:], v.stderr[-300:]))
            drawn = cc.plot_collapse(out, png, body="b3_0", point=(0.0, 0.48))
            curve = drawn["curve"]
            check("the capacity curve follows the node asked for, one point per state that held",
                  curve["body"] == "b3_0" and len(curve["multiplier"]) == len(multipliers) and
                  curve["multiplier"] == multipliers, (curve["body"], curve["multiplier"], multipliers))
            plain = os.path.join(tmp, "plain.hdf")
            subprocess.run([SOLVE, os.path.join(EXAMPLES, "flat_patch.json"), "-o", plain, "-q"], check=True,
                           capture_output=True, timeout=120)
            n = client(url, "collapse", plain, "-o", png)
            check("a file without a collapse analysis: exit 2, and why", n.returncode == 2 and
                  "no collapse analysis" in n.stderr, (n.returncode, n.stderr))

finish()
