#!/usr/bin/env python3
"""contactd's web page in a real browser: Debian's chromium, headless, driven by python3-selenium through
chromium-driver, against the real contactd.

Without a token: the page lists jobs; a job pasted into the form and submitted through the page runs, and while
it runs (the API still says RUNNING) the convergence plot gains points, the pressure plot and the mesh table
follow the iterations; the page's Cancel stops it; an example picked from the list fills the form with the
file's text and solves, and the page's download link serves the HDF5 result (a frictionless job: no tangential
plot); a friction job (the roller between two plates) shows under each pair's pressure its tangential traction,
the final event's, with the stick zone shaded where the event's stick flags say; an invalid job shows every error
with its pointer; the page's Delete removes a job. With a token: the page says it needs one, works once it is
entered (the list, submit, the live plot through the stream read with the Authorization header, the download
saved by the browser), and keeps it across a reload. Throughout: no script error and no Content-Security-Policy
violation in the browser's console.

Exits 77 (CTest: skipped) with a message saying why only when chromium cannot be started here."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request

from client_paths import CLIENT, EXAMPLES, HERE, SRC  # noqa: E402,F401  (sets the import path)
from contact_client.plot import AXIS_LABELS  # noqa: E402
from harness import Server, example, flat_patch, long_job, read_all_events, roller_job  # noqa: E402
from checks import check, finish, section, skip  # noqa: E402
from limit_jobs import column  # noqa: E402

CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--no-first-run", "--window-size=1400,1000"]


try:
    from selenium import webdriver
    from selenium.common.exceptions import WebDriverException
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select
except ImportError as exc:
    skip(f"python3-selenium is not installed ({exc}); bash scripts/setup.sh installs it")


class Browser:
    """A headless chromium with a fresh profile, and the waits the checks need."""

    def __init__(self, downloads):
        self.profile = tempfile.mkdtemp(prefix="contactd-chromium-")
        chromium = shutil.which("chromium") or "/usr/bin/chromium"
        driver = shutil.which("chromedriver") or "/usr/bin/chromedriver"
        options = webdriver.ChromeOptions()
        options.binary_location = chromium
        for flag in CHROMIUM_FLAGS + [f"--user-data-dir={self.profile}"]:
            options.add_argument(flag)
        options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        try:
            self.driver = webdriver.Chrome(service=Service(driver), options=options)
        except (WebDriverException, OSError) as exc:
            shutil.rmtree(self.profile, ignore_errors=True)
            skip(f"chromium cannot start here ({str(exc).strip().splitlines()[0][:300]}); "
                 "it needs Debian's chromium and chromium-driver (bash scripts/setup.sh)")
        self.driver.set_script_timeout(30)
        self.driver.execute_cdp_cmd("Page.setDownloadBehavior", {"behavior": "allow", "downloadPath": downloads})
        self.console = []

    def quit(self):
        try:
            self.driver.quit()
        finally:
            shutil.rmtree(self.profile, ignore_errors=True)

    def el(self, element_id):
        return self.driver.find_element(By.ID, element_id)

    def text(self, element_id):
        return self.el(element_id).text

    def attr(self, element_id, name):
        return self.el(element_id).get_attribute(name)

    def wait(self, predicate, timeout=30, interval=0.1):
        """predicate() until true (exceptions count as false); returns its last value."""
        deadline = time.time() + timeout
        value = None
        while time.time() < deadline:
            try:
                value = predicate()
            except WebDriverException:
                value = None
            if value:
                return value
            time.sleep(interval)
        return value

    def rows(self, element_id):
        """The cells' text of a table body, read at one instant (the page rebuilds some tables as events come)."""
        return self.driver.execute_script(
            "return Array.from(document.getElementById(arguments[0]).rows)"
            "  .map(r => Array.from(r.cells).map(c => c.textContent));", element_id)

    def click(self, selector, timeout=10):
        """Finds the element by CSS selector and clicks it, again if the page replaced it in between (the job
        list is rebuilt whenever the server's list changes, which makes a row found a moment ago stale)."""
        def attempt():
            self.driver.find_element(By.CSS_SELECTOR, selector).click()
            return True
        if not self.wait(attempt, timeout):
            raise AssertionError(f"could not click {selector} within {timeout} s")

    def set_job_text(self, text):
        box = self.el("job-text")
        box.clear()
        box.send_keys(text)

    def logs(self):
        """New console entries since the last call."""
        entries = self.driver.get_log("browser")
        self.console += entries
        return entries


def errors_in(entries):
    """Console entries that are script errors or policy violations. The browser also logs every failed request
    ("Failed to load resource: ... 400"), which the tests cause on purpose."""
    return [e["message"] for e in entries if e.get("level") == "SEVERE"
            and "Failed to load resource" not in e.get("message", "")]


def points(b):
    return int(b.attr("convergence", "data-points") or 0)


# Records the text drawn into the pressure plots' canvases (uPlot draws its axis labels there, not in the DOM).
RECORD_PRESSURE_TEXT = """
(() => {
  const texts = window.pressureCanvasTexts = [];
  const fillText = CanvasRenderingContext2D.prototype.fillText;
  CanvasRenderingContext2D.prototype.fillText = function (text, ...rest) {
    if (this.canvas.closest && this.canvas.closest("#pressure")) texts.push(String(text));
    return fillText.call(this, text, ...rest);
  };
})();
"""


def test_without_token(server, b, downloads):
    base = f"http://127.0.0.1:{server.port}/"
    b.driver.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": RECORD_PRESSURE_TEXT})
    b.driver.get(base)
    check("page: title", b.driver.title == "contactd", b.driver.title)
    check("page: the empty job list says so", b.wait(lambda: b.text("jobs-status") == "no jobs yet"),
          b.text("jobs-status"))
    check("page: the version from the server", b.wait(lambda: b.text("version").startswith("version ")),
          b.text("version"))
    check("page: the plotting library loaded", b.driver.execute_script("return typeof uPlot") == "function")

    # 1. A long job pasted into the form and submitted through the page; its plot grows while it runs.
    b.set_job_text(json.dumps(long_job(name="web-long")))
    b.el("submit").click()
    job_id = b.wait(lambda: b.text("job-id"), 10)
    if not check("submit: the page selects the new job",
                 bool(job_id) and server.get(f"/v1/jobs/{job_id}").status == 200, (job_id, b.text("submit-message"))):
        return
    check("submit: the address names the job", b.driver.current_url.endswith(f"#job={job_id}"), b.driver.current_url)
    check("running: the page shows RUNNING", b.wait(lambda: b.text("job-state") == "RUNNING", 20), b.text("job-state"))
    first = b.wait(lambda: points(b) > 0, 20) and points(b)
    time.sleep(1.0)
    second = points(b)
    running = server.job(job_id)["state"]
    check("running: the convergence plot receives points", bool(first) and first > 0, first)
    check("running: more points a second later, while the job still runs",
          second > first and running == "RUNNING", (first, second, running))
    check("running: the plot is drawn (a canvas)",
          len(b.driver.find_elements(By.CSS_SELECTOR, "#convergence canvas")) >= 1)
    check("running: the convergence title names the measure",
          "fixed-point" in b.text("convergence-title"), b.text("convergence-title"))
    check("running: one pressure plot for the pair, at a recent iteration",
          len(b.driver.find_elements(By.CSS_SELECTOR, "#pressure .pair canvas")) == 1
          and int(b.attr("pressure", "data-iteration")) > 0
          and "upper.bottom-lower.top" in b.text("pressure"), b.text("pressure"))
    labels = b.driver.execute_script("return window.pressureCanvasTexts || null;")
    check("running: the pressure is plotted against the client plot's default coordinate (arc length)",
          labels is not None and AXIS_LABELS["arc"] in labels, (labels and sorted(set(labels))[:20], AXIS_LABELS))
    rows = b.rows("mesh")
    progress = server.job(job_id)["progress"]
    expected = [[x["name"], str(x["elements"]), str(x["dofs"])] for x in progress["bodies"]]
    check("running: the mesh table has each body's elements and unknowns",
          [r[:3] for r in rows] == expected, (rows, expected))
    check("running: the job list shows it RUNNING",
          b.wait(lambda: b.driver.find_element(By.CSS_SELECTOR, f'#jobs tr[data-id="{job_id}"]')
                 .get_attribute("data-state") == "RUNNING", 10))

    # 2. Cancel through the page.
    b.el("cancel").click()
    check("cancel: the page shows CANCELLED", b.wait(lambda: b.text("job-state") == "CANCELLED", 30),
          b.text("job-state"))
    check("cancel: the server says CANCELLED", server.wait_done(job_id, 30)["state"] == "CANCELLED")
    check("cancel: the event log ends with the end event", "end CANCELLED" in b.text("log"), b.text("log")[-300:])
    # Every iteration the job's stream holds is plotted (the page may still be drawing the last few events when
    # it shows the state: wait for the plot to catch up rather than read it once).
    long_iterations = sum(1 for e in read_all_events(server, job_id) if e["type"] == "iteration")
    check("cancel: every iteration of the stream is plotted", b.wait(lambda: points(b) == long_iterations, 10),
          (points(b), long_iterations))
    long_points = points(b)

    # 3. An example picked from the list, submitted, solved; its result downloadable from the page.
    Select(b.el("example")).select_by_value("flat_patch")
    with open(os.path.join(EXAMPLES, "flat_patch.json")) as f:
        patch_text = f.read()
    check("example: the form holds the file's text",
          b.wait(lambda: b.el("job-text").get_attribute("value") == patch_text, 10))
    b.el("submit").click()
    patch_id = b.wait(lambda: b.text("job-id") if b.text("job-id") != job_id else None, 10)
    check("example: solved", b.wait(lambda: b.text("job-state") == "SUCCEEDED", 30), b.text("job-state"))
    end = server.wait_done(patch_id, 30) if patch_id else {}
    check("example: every iteration plotted",
          b.wait(lambda: points(b) == end.get("iterations"), 5), (points(b), end.get("iterations")))
    check("example: the plot of the new job starts afresh", points(b) < long_points, (points(b), long_points))
    check("example: the active-set method's measure",
          "complementarity" in b.text("convergence-title"), b.text("convergence-title"))
    check("example: frictionless, no tangential-traction plot",
          not b.driver.find_elements(By.CSS_SELECTOR, "#pressure .tangential"))
    link = b.wait(lambda: b.el("result-link").is_displayed() and b.attr("result-link", "href"), 10)
    check("example: a download link to the result", bool(link) and link.endswith(f"/v1/jobs/{patch_id}/result"),
          link)
    check("example: and to the XDMF sidecar", (b.attr("xmf-link", "href") or "").endswith("/result.xmf"))
    if link:
        with urllib.request.urlopen(link, timeout=10) as r:
            check("example: the link serves the HDF5 file", r.read(8) == b"\x89HDF\r\n\x1a\n")

    test_friction(server, b)
    test_wall(server, b)
    test_warnings(server, b)
    test_collapse(server, b)

    # 4. An invalid job: every error with its pointer, no job created.
    bad = example("flat_patch.json")
    bad["bodies"][1]["material"]["nu"] = 0.5
    bad["solver"] = {"gama": 0.1}
    jobs_before = len(server.get("/v1/jobs").json()["jobs"])
    b.set_job_text(json.dumps(bad))
    b.el("submit").click()
    message = b.wait(lambda: "/solver/gama" in b.text("submit-message") and b.text("submit-message"), 10)
    check("invalid job: every error with its pointer", bool(message) and "/bodies/1/material/nu" in message
          and "error" in b.attr("submit-message", "class"), b.text("submit-message"))
    check("invalid job: no job created", len(server.get("/v1/jobs").json()["jobs"]) == jobs_before)
    b.el("validate").click()
    check("validate: the same errors", b.wait(lambda: "/bodies/1/material/nu" in b.text("submit-message"), 10))

    # 5. Select the cancelled job in the list and delete it through the page.
    b.click(f'#jobs tr[data-id="{job_id}"]')
    check("select: the list selects the job", b.wait(lambda: b.text("job-id") == job_id, 10), b.text("job-id"))
    check("select: its stream is replayed into the plot", b.wait(lambda: points(b) == long_points, 20),
          (points(b), long_points))
    b.wait(lambda: b.el("delete").is_displayed(), 10)
    b.el("delete").click()
    check("delete: gone from the server", b.wait(lambda: server.get(f"/v1/jobs/{job_id}").status == 404, 10))
    check("delete: gone from the list",
          b.wait(lambda: not b.driver.find_elements(By.CSS_SELECTOR, f'#jobs tr[data-id="{job_id}"]'), 10))
    errors = errors_in(b.logs())
    check("no script error or CSP violation in the console", not errors, errors)


def stick_zones(x, stick):
    """The stick zones the page should shade: per run of sticking nodes (stick 1) along x (increasing), from
    halfway to the node before it to halfway to the node after it (the node itself at an end of the edge)."""
    zones, i = [], 0
    while i < len(x):
        if stick[i] != 1:
            i += 1
            continue
        j = i
        while j + 1 < len(x) and stick[j + 1] == 1:
            j += 1
        zones.append([(x[i - 1] + x[i]) / 2 if i > 0 else x[i], (x[j] + x[j + 1]) / 2 if j + 1 < len(x) else x[j]])
        i = j + 1
    return zones


def test_friction(server, b):
    """3b. A friction job: each pair's tangential traction under its pressure, the stick zone shaded."""
    b.driver.execute_script("window.pressureCanvasTexts.length = 0;")
    b.set_job_text(json.dumps(roller_job()))
    before = b.text("job-id")
    b.el("submit").click()
    job_id = b.wait(lambda: b.text("job-id") if b.text("job-id") != before else None, 10)
    check("friction: solved", b.wait(lambda: b.text("job-state") == "SUCCEEDED", 30), b.text("job-state"))
    events = read_all_events(server, job_id, ndjson=True) if job_id else []
    last = [e for e in events if e.get("type") == "iteration"][-1:]
    if not check("friction: the events carry tangential tractions and stick flags",
                 last and all("tangential_tractions" in p and "stick" in p for p in last[0]["pairs"]), last):
        return
    b.wait(lambda: b.attr("pressure", "data-iteration") == str(last[0]["iteration"]), 10)
    for pair in last[0]["pairs"]:
        shown = b.wait(lambda: [el for el in b.driver.find_elements(By.CSS_SELECTOR, "#pressure .pair")
                                if el.text.startswith(pair["name"])
                                and el.find_elements(By.CSS_SELECTOR, ".chart.tangential canvas")], 10)
        if not check(f"friction {pair['name']}: a tangential-traction plot under its pressure",
                     shown and len(shown[0].find_elements(By.CSS_SELECTOR, ".chart canvas")) == 2, b.text("pressure")):
            continue
        el = shown[0]
        order = sorted(range(len(pair["positions"])), key=lambda i: pair["positions"][i])
        x = [pair["positions"][i] for i in order]
        want = stick_zones(x, [pair["stick"][i] for i in order])
        got = json.loads(el.get_attribute("data-stick-zones") or "null")
        check(f"friction {pair['name']}: every node of the last iteration plotted",
              el.get_attribute("data-tangential-points") == str(len(x)), el.get_attribute("data-tangential-points"))
        check(f"friction {pair['name']}: the stick zone shaded where the event's stick flags say",
              got is not None and want and len(got) == len(want)
              and all(abs(a - w) < 1e-12 for g, z in zip(got, want) for a, w in zip(g, z)), (got, want))
        check(f"friction {pair['name']}: the caption gives the tangential force and the stick zone",
              "tangential force" in el.text and "stick zone (shaded)" in el.text, el.text)
    drawn = b.driver.execute_script(
        "return Array.from(document.querySelectorAll('#pressure .chart.tangential'))"
        "  .map(c => c.querySelector('.uplot') !== null);")
    check("friction: a uPlot chart per pair", drawn == [True] * len(last[0]["pairs"]), drawn)
    labels = b.driver.execute_script("return window.pressureCanvasTexts || null;")
    check("friction: the tangential axis is labelled", labels is not None and "tangential traction" in labels,
          labels and sorted(set(labels))[:20])


def test_wall(server, b):
    """3c. A 22 x 22 frictional wall (946 pairs): the page shows the totals over every pair, a bounded number of
    panels (the pairs that stand out), the bodies' totals, and any pair picked by pattern."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "wall.json")
        subprocess.run(["/usr/bin/python3", os.path.join(SRC, "scripts", "make_brick_wall.py"), "--rows", "22",
                        "--bricks", "22", "--friction", "0.6", "--shear", "0.3", "-o", path], check=True,
                       capture_output=True)
        with open(path) as f:
            job = json.load(f)
    job_id = server.submit_id(job)
    check("wall: solved", server.wait_done(job_id, 300).get("state") == "SUCCEEDED")
    b.driver.execute_script(f"window.location.hash = 'job={job_id}';")
    check("wall: the page loads the job", b.wait(lambda: b.text("job-state") == "SUCCEEDED", 30),
          b.text("job-state"))
    iterations = [e for e in read_all_events(server, job_id, ndjson=True) if e.get("type") == "iteration"]
    last = iterations[-1]
    listed = {p["name"] for e in iterations for p in e["pairs"]}
    summary = b.wait(lambda: b.text("pairs-summary") if "946 pairs" in b.text("pairs-summary") else None, 30)
    check("wall: the totals over the 946 pairs, with stick and slip",
          bool(summary) and "stick" in summary and last["pairs_summary"]["max_pressure_pair"] in summary, summary)
    panels = len(b.driver.find_elements(By.CSS_SELECTOR, "#pressure .pair"))
    check("wall: a panel per pair the events listed, not 946", panels == len(listed) and panels <= 2 * len(iterations),
          (panels, listed))
    check("wall: the mesh table gives the bodies' totals", any("496 bodies" in r[0] for r in b.rows("mesh")),
          b.rows("mesh")[:3])
    field = b.el("pairs-names")
    field.clear()
    field.send_keys("b21_1.*,b21_2.*")
    # On a loaded machine the field may not hold the typed text yet when the button is pressed: wait for it, so the
    # check is of what the page does with the request, not of how fast it took the keys.
    b.wait(lambda: field.get_attribute("value") == "b21_1.*,b21_2.*", 20)
    b.el("pairs-show").click()
    picked = [n for n in (c.get("name") or f"{c['slave']}-{c['master']}" for c in job["contacts"])
              if n.startswith(("b21_1.", "b21_2."))]
    shown = b.wait(lambda: len(b.driver.find_elements(By.CSS_SELECTOR, "#pressure .pair")) >= panels + len(picked), 60)
    check("wall: 'Show pairs' adds a panel per pair the pattern matches", bool(shown),
          (len(b.driver.find_elements(By.CSS_SELECTOR, "#pressure .pair")), panels, len(picked),
           field.get_attribute("value"), b.text("pairs-message")))
    check("wall: and says what it showed", f"{len(picked)} pairs" in b.text("pairs-message"), b.text("pairs-message"))
    texts = b.text("pressure")
    check("wall: the picked pairs are drawn by name", all(n in texts for n in picked), picked)
    field.clear()
    field.send_keys("no_such_pair")
    b.el("pairs-show").click()
    check("wall: a pattern matching nothing says so", b.wait(lambda: "no pair" in b.text("pairs-message"), 10),
          b.text("pairs-message"))


def test_warnings(server, b):
    """3d. A job whose model checks warn (the shrink fit without its "fit": its interference is an undeclared
    overlap): the job's view lists each warning with its pointer; a job without any shows none."""
    job = example("shrink_fit.json")
    for c in job["contacts"]:
        c.pop("fit", None)
    job_id = server.submit_id(job)
    check("warnings: solved", server.wait_done(job_id, 120).get("state") == "SUCCEEDED")
    b.driver.execute_script(f"window.location.hash = 'job={job_id}';")
    shown = b.wait(lambda: b.el("job-warnings").is_displayed()
                   and len(b.driver.find_elements(By.CSS_SELECTOR, "#job-warnings li")) == 2, 30)
    text = b.text("job-warnings")
    check("warnings: the view lists both pairs' warnings with their pointers",
          bool(shown) and "/contacts/0" in text and "/contacts/1" in text and "overlap by up to 0.667" in text, text)
    clean = server.submit_id(flat_patch(name="no-warnings"))
    server.wait_done(clean, 60)
    b.driver.execute_script(f"window.location.hash = 'job={clean}';")
    check("warnings: a job without any shows none",
          b.wait(lambda: b.text("job-id") == clean and not b.el("job-warnings").is_displayed(), 30),
          b.text("job-warnings"))


def test_collapse(server, b):
    """3e. A collapse analysis: the job's view says the bracket, the statics' bound and the mechanism, and lists the
    trials; a job without one shows none of it."""
    job_id = server.submit_id(dict(column(), name="column-collapse"))
    check("collapse: solved", server.wait_done(job_id, 120).get("state") == "SUCCEEDED")
    b.driver.execute_script(f"window.location.hash = 'job={job_id}';")
    shown = b.wait(lambda: b.el("job-collapse").is_displayed()
                   and len(b.driver.find_elements(By.CSS_SELECTOR, "#collapse-trials tbody tr")) == 2, 30)
    text = b.text("job-collapse")
    check("collapse: the view gives the bracket around 1/3, the bound and the overturning mechanism",
          bool(shown) and "held at 0.33325" in text and "did not at 0.33342" in text and "at most 0.33333" in text
          and "overturning" in text and "mechanism (the elastic solution's): overturning" in text, text)
    # The capacity curve: the held trials' multiplier against the live loads' displacement (the job resource's
    # collapse.trials), drawn as a chart with one point per held trial; the table gives each displacement.
    trials = server.get(f"/v1/jobs/{job_id}").json()["collapse"]["trials"]
    held = sorted((t["multiplier"], t["displacement"]) for t in trials if t["held"])
    check("collapse: every held trial has a positive displacement, growing with the multiplier",
          len(held) == 2 and all(d > 0 for _, d in held) and held[1][1] > held[0][1], trials)
    curve = b.wait(lambda: b.el("collapse-curve").is_displayed()
                   and b.el("collapse-curve").get_attribute("data-points") == "2"
                   and b.driver.find_elements(By.CSS_SELECTOR, "#collapse-curve canvas"), 30)
    check("collapse: the capacity curve's start (the dead loads' state) below its held trials",
          server.get(f"/v1/jobs/{job_id}").json()["collapse"]["start_displacement"] < held[0][1], held)
    check("collapse: the capacity curve is drawn with its 2 held trials", bool(curve),
          b.el("collapse-curve").get_attribute("data-points"))
    cells = [r.find_elements(By.TAG_NAME, "td")[-1].text
             for r in b.driver.find_elements(By.CSS_SELECTOR, "#collapse-trials tbody tr")]
    check("collapse: the trials table gives each held trial's displacement",
          len(cells) == 2 and all(c and float(c) > 0 for c in cells), cells)
    # The thrust at the last held state: the column's three joints drawn as edges with their centres of pressure,
    # and the mechanism's hinge (the base's toe) marked.
    thrust = server.get(f"/v1/jobs/{job_id}").json()["collapse"]["thrust"]
    check("collapse: the job resource has the thrust, a centre of pressure per joint that carries force",
          len(thrust) == 3 and all(t["point"] and t["force"] > 0 for t in thrust), thrust)
    drawn = b.wait(lambda: b.el("collapse-thrust").get_attribute("data-joints") == "3"
                   and b.el("collapse-thrust").get_attribute("data-points") == "3"
                   and b.el("collapse-thrust").get_attribute("data-hinges") == "1"
                   and b.el("collapse-thrust").is_displayed(), 30)
    check("collapse: the thrust drawn, 3 joints with their centres of pressure and the hinge",
          bool(drawn), {k: b.el("collapse-thrust").get_attribute(k) for k in ("data-joints", "data-points", "data-hinges")})
    clean = server.submit_id(flat_patch(name="no-collapse"))
    server.wait_done(clean, 60)
    b.driver.execute_script(f"window.location.hash = 'job={clean}';")
    check("collapse: a job without one shows none",
          b.wait(lambda: b.text("job-id") == clean and not b.el("job-collapse").is_displayed()
                 and b.el("collapse-curve").get_attribute("data-points") == "0"
                 and b.el("collapse-thrust").get_attribute("data-joints") == "0", 30),
          b.text("job-collapse"))


def test_with_token(b, downloads):
    token = "web-page-test-token"
    ITERATIONS = 600  # about 1 s on an idle machine: long enough to see points arrive while it runs
    with Server(token=token) as server:
        base = f"http://127.0.0.1:{server.port}/"
        b.driver.get(base)
        check("token: the page says one is needed",
              b.wait(lambda: b.el("banner").is_displayed() and "requires a bearer token" in b.text("banner"), 10),
              b.text("banner"))
        b.el("token").send_keys("wrong-token")
        b.el("token-save").click()
        check("token: a wrong one is refused", b.wait(lambda: "refused the token" in b.text("banner"), 10),
              b.text("banner"))
        b.el("token").clear()
        b.el("token").send_keys(token)
        b.el("token-save").click()
        if not check("token: with it the list loads", b.wait(lambda: not b.el("banner").is_displayed()
                                                              and b.text("jobs-status") == "no jobs yet", 10),
                     (b.text("banner"), b.text("jobs-status"))):
            return
        check("token: the examples load", b.wait(lambda: len(Select(b.el("example")).options) > 5, 10))

        # A job that runs a few seconds, followed live through the stream read with the token.
        b.set_job_text(json.dumps(long_job(max_iterations=ITERATIONS, name="web-token", iterate=True)))
        b.el("submit").click()
        job_id = b.wait(lambda: b.text("job-id"), 10)
        if not check("token: submitted through the page", bool(job_id), b.text("submit-message")):
            return
        live = b.wait(lambda: points(b) > 0 and server.job(job_id)["state"] == "RUNNING" and points(b), 20)
        check("token: points arrive while the job runs", bool(live), points(b))
        end = server.wait_done(job_id, 60)
        # It stops at its max_iterations short of its tolerance: FAILED (not converged), its last iterate kept
        # (asked for: output.iterate).
        check("token: the job runs to its end (FAILED at max_iterations, its result kept)",
              end.get("state") == "FAILED" and end.get("stop_reason") == "max_iterations"
              and end.get("result_available"), end)
        check("token: every iteration reached the plot", b.wait(lambda: points(b) == ITERATIONS, 20), points(b))

        # The download link cannot carry the header: the page fetches the file with it and saves it.
        link = b.wait(lambda: b.el("result-link").is_displayed(), 10)
        check("token: download link shown", bool(link))
        if link:
            b.el("result-link").click()
            saved = os.path.join(downloads, "web-token.hdf")
            got = b.wait(lambda: os.path.exists(saved) and os.path.getsize(saved) > 0
                         and not os.path.exists(saved + ".crdownload"), 20)
            body = open(saved, "rb").read() if got else b""
            check("token: the browser saved the result", body[:8] == b"\x89HDF\r\n\x1a\n", len(body))
            check("token: the saved file is the job's result", body == server.get(f"/v1/jobs/{job_id}/result").body)

        b.driver.refresh()
        check("token: kept across a reload", b.wait(lambda: b.el("token").get_attribute("value") == token
                                                    and f'data-id="{job_id}"' in b.el("jobs").get_attribute("innerHTML"),
                                                    10))
        check("token: the reloaded page follows the job in the address",
              b.wait(lambda: b.text("job-id") == job_id and points(b) == ITERATIONS, 20), (b.text("job-id"), points(b)))
        errors = errors_in(b.logs())
        check("token: no script error or CSP violation in the console", not errors, errors)


def run_with_server(browser, downloads):
    with Server() as server:
        test_without_token(server, browser, downloads)


def main():
    downloads = tempfile.mkdtemp(prefix="contactd-downloads-")
    browser = Browser(downloads)
    try:
        for name, run in (("without a token", lambda: run_with_server(browser, downloads)),
                          ("with a token", lambda: test_with_token(browser, downloads))):
            with section(name):  # a crash of one part is a failure; the other part still runs
                run()
    finally:
        browser.quit()
        shutil.rmtree(downloads, ignore_errors=True)
    finish()


if __name__ == "__main__":
    main()
