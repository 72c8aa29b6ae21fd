// The selected job: its state and outcome, the live plots fed by its event stream, the mesh sizes per body, the
// event log, the download links and the cancel / delete buttons.

import {ApiError, api, download, getToken} from "./api.js";
import {CapacityPlot, ConvergencePlot, PressurePlot} from "./plots.js";
import {followEvents} from "./stream.js";

const $ = (id) => document.getElementById(id);
const TERMINAL = new Set(["SUCCEEDED", "FAILED", "CANCELLED"]);
const MAX_LOG = 300;
const MAX_PAIR_PLOTS = 24;     // pressure panels at most (the events' pairs and the ones picked)
const PICK_INTERVAL_MS = 1000; // the picked pairs are fetched again at most this often while the job runs

export class JobView {
  // onChange(): the job list should be refreshed (a state changed, the job was deleted).
  constructor({onChange}) {
    this.onChange = onChange;
    this.id = null;
    this.controller = null;
    this.convergence = new ConvergencePlot($("convergence"), $("convergence-title"));
    this.capacity = new CapacityPlot($("collapse-curve"));
    this.pairs = new Map();
    this.picked = "";        // the names or patterns shown on request (GET v1/jobs/{id}/pairs)
    this.pickPending = false;
    this.pickLast = 0;
    $("pairs-form").addEventListener("submit", (ev) => {
      ev.preventDefault();
      this.pick($("pairs-names").value.trim());
    });
    $("cancel").addEventListener("click", () => this.cancel());
    $("delete").addEventListener("click", () => this.remove());
    for (const [id, file] of [["result-link", "result"], ["xmf-link", "result.xmf"]]) {
      $(id).addEventListener("click", (ev) => {
        // A link cannot send the token: with one, fetch the file and save it.
        if (!getToken()) return;
        ev.preventDefault();
        const name = `${this.name || "result"}.${file === "result" ? "hdf" : "xmf"}`;
        download(`v1/jobs/${this.id}/${file}`, name).catch((e) => this.message(e.message, true));
      });
    }
    window.addEventListener("resize", () => {
      this.convergence.resize();
      for (const p of this.pairs.values()) p.resize();
      this.capacity.resize();
    });
  }

  show(id) {
    if (id === this.id) return;
    this.close();
    this.id = id;
    this.name = "";
    this.state = "";
    $("no-job").hidden = true;
    $("job").hidden = false;
    $("job-name").textContent = "";
    $("job-id").textContent = id;
    $("job-outcome").textContent = "";
    $("job-iteration").textContent = "";
    $("mesh").replaceChildren();
    $("log").replaceChildren();
    this.message("");
    this.warnings([]);
    this.setState("");
    this.links(false);
    this.refresh();
    this.follow();
  }

  close() {
    if (this.controller) this.controller.abort();
    this.controller = null;
    this.convergence.reset();
    for (const p of this.pairs.values()) p.destroy();
    this.pairs.clear();
    $("pressure").replaceChildren();
    $("pressure").dataset.iteration = "0";
    $("pairs-summary").textContent = "";
    $("pairs-message").textContent = "";
    this.picked = "";
    this.id = null;
  }

  hide() {
    this.close();
    $("job").hidden = true;
    $("no-job").hidden = false;
  }

  message(text, error = false) {
    const el = $("job-message");
    el.textContent = text;
    el.className = "message" + (text ? (error ? " error" : " ok") : "");
  }

  setState(state) {
    this.state = state;
    const el = $("job-state");
    el.textContent = state;
    el.className = "state state-" + state;
    $("cancel").hidden = !state || TERMINAL.has(state);
    $("delete").hidden = !TERMINAL.has(state);
  }

  links(available) {
    for (const [id, file] of [["result-link", "result"], ["xmf-link", "result.xmf"]]) {
      const a = $(id);
      a.hidden = !available;
      if (available) {
        a.href = `v1/jobs/${this.id}/${file}`;
        a.download = `${this.name || "result"}.${file === "result" ? "hdf" : "xmf"}`;
      } else {
        a.removeAttribute("href");
      }
    }
  }

  // The job resource: name, state, outcome, links.
  async refresh() {
    const id = this.id;
    try {
      const job = await api(`v1/jobs/${id}`);
      if (id !== this.id) return;
      this.name = job.name || "";
      $("job-name").textContent = this.name;
      this.setState(job.state || "");
      const outcome = [];
      if (job.stop_reason) outcome.push(`stop: ${job.stop_reason}${job.converged === false ? " (not converged)" : ""}`);
      if (job.queue_position) outcome.push(`queue position ${job.queue_position}`);
      $("job-outcome").textContent = outcome.join(", ");
      if (job.message) this.message(job.message, job.state === "FAILED");
      this.warnings(job.warnings || []);
      this.collapse(job.collapse || null);
      this.links(job.result_available === true);
    } catch (e) {
      if (id === this.id) this.message(e.message, true);
    }
  }

  // The model checks' warnings (docs/job-format.md, "Warnings"): each with the JSON pointer it is about.
  warnings(list) {
    const ul = $("job-warnings");
    ul.replaceChildren(...list.map((w) => {
      const li = document.createElement("li");
      const where = document.createElement("code");
      where.textContent = w.pointer || "(the job)";
      li.append("warning ", where, `: ${w.message}`);
      return li;
    }));
    ul.hidden = list.length === 0;
  }

  // A collapse analysis's answer, or the statics' verdict on a failed step (docs/limit-analysis.md): the bracket of
  // the collapse multiplier, the statics' bound, the mechanism, and every trial with its cost.
  collapse(c) {
    const box = $("job-collapse");
    box.hidden = !c;
    this.capacity.show(c);
    if (!c) drawThrust($("collapse-thrust"), null);
    if (!c) return;
    const num = (x) => (typeof x === "number" ? x.toPrecision(5) : String(x));
    let verdict = `collapse analysis: ${c.verdict}`;
    if (c.verdict === "collapse" && !(c.trials || []).length)
      verdict = "collapse: where the step failed, the states that held last show a mechanism (below)";
    else if (c.verdict === "collapse")
      verdict = `collapse: the multiplier of the live loads held at ${num(c.held)} and did not at ${num(c.failed)}` +
        ` (${c.solves} trial solves)`;
    else if (c.verdict === "holds") verdict = `no collapse: held at ${num(c.held)} (max_multiplier)`;
    else if (c.verdict === "no_equilibrium") verdict = "no equilibrium by statics: the loads cannot be carried";
    if (c.statics_bound !== null && c.statics_bound !== undefined)
      verdict += `; rigid-block statics: at most ${num(c.statics_bound)}`;
    $("collapse-verdict").textContent = verdict;
    const m = c.mechanism || {};
    const whose = m.source === "elastic" ? " (the elastic solution's)" : m.source === "statics" ? " (the rigid blocks' statics')" : "";
    $("collapse-mechanism").textContent = m.words ? `mechanism${whose}: ${m.words}` : "";
    const rows = (c.trials || []).map((t, i) => {
      const tr = document.createElement("tr");
      const shift = typeof t.displacement === "number" ? t.displacement.toPrecision(4) : "";
      for (const v of [i + 1, num(t.multiplier), t.held ? "yes" : "no", t.iterations, num(t.seconds), shift]) {
        const td = document.createElement("td");
        td.textContent = String(v);
        tr.append(td);
      }
      return tr;
    });
    $("collapse-trials").querySelector("tbody").replaceChildren(...rows);
    $("collapse-trials").hidden = rows.length === 0;
    drawThrust($("collapse-thrust"), c);
  }

  log(text) {
    const list = $("log");
    const li = document.createElement("li");
    li.textContent = text;
    list.append(li);
    while (list.childElementCount > MAX_LOG) list.firstElementChild.remove();
    list.scrollTop = list.scrollHeight;
  }

  async follow() {
    const id = this.id;
    const controller = new AbortController();
    this.controller = controller;
    try {
      const end = await followEvents(id, (e) => this.onEvent(e),
                                     {signal: controller.signal, onNote: (t) => this.log(t)});
      if (id === this.id && !end && !controller.signal.aborted) this.log("the stream ended without an end event");
    } catch (e) {
      if (id === this.id) this.message(e instanceof ApiError ? e.message : String(e), true);
    }
  }

  onEvent(e) {
    switch (e.type) {
      case "iteration":
        this.onIteration(e);
        break;
      case "state":
        if (e.state === "QUEUED" && this.convergence.x.length) this.convergence.reset();
        this.setState(e.state);
        this.log(`state ${e.state}${e.message ? ": " + e.message : ""}`);
        this.onChange();
        break;
      case "step": {
        const s = e.bodies_summary;
        const bodies = Array.isArray(e.bodies) && e.bodies.length <= 6
          ? e.bodies.map((b) => `${b.name} ${b.elements} cells`).join(", ")
          : s ? `${s.count} bodies, ${s.elements} cells` : "";
        this.log(`step ${e.step} at iteration ${e.iteration}: ${bodies}`);
        break;
      }
      case "adaptive_step": {
        const unknowns = (Array.isArray(e.bodies) ? e.bodies : []).reduce((n, b) => n + (b.unknowns || 0), 0);
        const pressure = typeof e.pressure_estimate === "number"
          ? `, pressure error ~${(100 * e.pressure_estimate).toPrecision(3)} %` : "";
        // The largest change the stop test reads, against the last step with at most half the unknowns.
        const changes = ["force_change", "peak_change", "extent_change", "stick_change", "tangential_change"]
          .map((k) => e[k]).filter((c) => typeof c === "number");
        const settled = Number.isInteger(e.compared_with) && e.compared_with >= 0 && changes.length
          ? `; against step ${e.compared_with}: the answer changed by at most ` +
            `${(100 * Math.max(...changes)).toPrecision(2)} %` : "";
        this.log(`adaptive step ${e.step}: ${unknowns} unknowns, estimate ${Number(e.estimate).toPrecision(3)}` +
                 `${pressure}${settled}`);
        break;
      }
      case "load_step": {
        const n = (x, d = 6) => (typeof x === "number" ? Number(x.toPrecision(d)) : x);
        if (e.kind === "trial")
          this.log(`collapse trial ${e.step}: multiplier ${n(e.multiplier)} ${e.held ? "held" : "did not hold"}` +
                   ` (${e.iterations} iterations)`);
        else if (e.kind === "cut")
          this.log(`load step ${e.step} of ${e.steps} cut: held up to ${n(100 * e.fraction, 4)} % of the step, ` +
                   `now trying ${n(100 * e.next, 4)} %`);
        else
          this.log(`load step ${e.step} of ${e.steps}: ${e.fraction < 1 ? `${n(100 * e.fraction, 4)} % ` : ""}held` +
                   ` at load factor ${n(e.load_factor)} (${e.iterations} iterations)`);
        break;
      }
      case "end":
        this.setState(e.state);
        this.log(`end ${e.state} (${e.stop_reason}) after ${e.iterations} iterations` +
                 `${e.message ? ": " + e.message : ""}`);
        this.refresh();
        this.onChange();
        break;
      default:
        break;
    }
  }

  onIteration(e) {
    if (this.state !== "RUNNING") this.setState("RUNNING");
    this.convergence.add(e);
    $("job-iteration").textContent = `iteration ${e.iteration}`;
    this.summary(e);
    for (const pair of Array.isArray(e.pairs) ? e.pairs : []) this.addPair(e.iteration, pair);
    $("pressure").dataset.iteration = String(e.iteration);
    this.meshTable(Array.isArray(e.bodies) ? e.bodies : [], e.bodies_summary);
    if (this.picked) this.pick(this.picked, false);
  }

  // A pair's panel, made on its first data; past MAX_PAIR_PLOTS no new panel (false).
  addPair(iteration, pair) {
    let plot = this.pairs.get(pair.name);
    if (!plot) {
      if (this.pairs.size >= MAX_PAIR_PLOTS) return false;
      const el = document.createElement("div");
      el.className = "pair";
      $("pressure").append(el);
      plot = new PressurePlot(el, String(pair.name));
      this.pairs.set(pair.name, plot);
    }
    plot.add(iteration, pair);
    return true;
  }

  // The totals over every pair (the events' pairs_summary), whatever the number of pairs.
  summary(e) {
    const s = e.pairs_summary;
    if (!s || typeof s !== "object") return;
    const n = (v, digits = 5) => (typeof v === "number" ? Number(v.toPrecision(digits)).toString() : "?");
    let text = `${n(s.count)} pairs: force ${n(s.force)}, ${n(s.active_nodes)} contact nodes ` +
               `(${n(s.changed_nodes)} changed in ${n(s.pairs_changed)} pairs)`;
    if (s.friction_pairs) text += `, stick ${n(s.stick_nodes)} / slip ${n(s.slip_nodes)} nodes, ` +
                                  `tangential force ${n(s.tangential_force)}`;
    if (s.max_pressure_pair) text += `; highest pressure ${n(s.max_pressure)} at ${s.max_pressure_pair}`;
    if (s.most_changed_pair) text += `; most change at ${s.most_changed_pair} (${n(s.most_changed_nodes)} nodes)`;
    if (e.pairs_listed === "selected") text += ". Panels: the pairs that stand out or are selected.";
    $("pairs-summary").textContent = text;
  }

  // Shows the pairs `names` (comma-separated names or patterns) from GET v1/jobs/{id}/pairs; again at each
  // iteration while the job runs (`asked`: the user's request, which reports its outcome), at most every
  // PICK_INTERVAL_MS and one request at a time.
  async pick(names, asked = true) {
    if (!names) return;
    const now = Date.now();
    if (!asked && (this.pickPending || now - this.pickLast < PICK_INTERVAL_MS)) return;
    const id = this.id;
    this.picked = names;
    this.pickPending = true;
    this.pickLast = now;
    try {
      const answer = await api(`v1/jobs/${id}/pairs?names=${encodeURIComponent(names)}`);
      if (id !== this.id) return;
      let shown = 0;
      for (const pair of Array.isArray(answer.pairs) ? answer.pairs : []) shown += this.addPair(answer.iteration, pair) ? 1 : 0;
      if (asked) {
        const more = answer.matched > shown ? ` (${answer.matched} matched; ${shown} shown)` : "";
        $("pairs-message").textContent = `iteration ${answer.iteration}: ${shown} pair${shown === 1 ? "" : "s"}${more}`;
      }
    } catch (e) {
      if (id === this.id && asked) $("pairs-message").textContent = e.message;
      if (id === this.id) this.picked = asked ? "" : this.picked;
    } finally {
      this.pickPending = false;
    }
  }

  meshTable(bodies, summary) {
    if (!bodies.length && summary && typeof summary === "object") {
      bodies = [{name: `${summary.count} bodies (totals)`, elements: summary.elements, dofs: summary.dofs,
                 elements_refined: summary.elements_refined}];
    }
    const rows = bodies.map((b) => {
      const tr = document.createElement("tr");
      for (const v of [b.name, b.elements, b.dofs, b.elements_refined]) {
        const td = document.createElement("td");
        td.textContent = v === undefined || v === null ? "" : String(v);
        tr.append(td);
      }
      return tr;
    });
    $("mesh").replaceChildren(...rows);
  }

  async cancel() {
    try {
      await api(`v1/jobs/${this.id}/cancel`, {method: "POST"});
      this.message("cancellation requested: the job stops within one iteration");
    } catch (e) {
      this.message(e.message, true);
    }
  }

  async remove() {
    const id = this.id;
    try {
      await api(`v1/jobs/${id}`, {method: "DELETE"});
      this.hide();
      if (window.location.hash === `#job=${id}`) history.replaceState(null, "", window.location.pathname);
      this.onChange();
    } catch (e) {
      this.message(e.message, true);
    }
  }
}

// The thrust at the last state that held (collapse.thrust, docs/limit-analysis.md): every joint as its slave edge
// (grey), its centre of pressure (blue dot), joined into the thrust line where consecutive pairs share a body (an
// arch, a column), and the mechanism's hinges (red rings). The svg's data-joints / data-points / data-hinges say what
// was drawn (what the browser test reads).
const SVG = "http://www.w3.org/2000/svg";
function drawThrust(svg, c) {
  svg.replaceChildren();
  const thrust = (c && c.thrust) || [];
  const hinges = ((c && c.mechanism && c.mechanism.joints) || []).filter((j) => j.kind === "hinge" && j.point);
  svg.dataset.joints = String(thrust.length);
  svg.dataset.points = "0";
  svg.dataset.hinges = "0";
  svg.parentElement.hidden = thrust.length === 0;  // its box (hidden is not an SVGElement property)
  if (!thrust.length) return;
  let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  for (const t of thrust)
    for (const [x, y] of t.edge) {
      x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
    }
  const span = Math.max(x1 - x0, y1 - y0, 1e-300), pad = 0.05 * span;
  const width = 480, scale = width / (x1 - x0 + 2 * pad || 1);
  const height = Math.min(480, Math.max(120, (y1 - y0 + 2 * pad) * scale));
  const s = Math.min(scale, height / (y1 - y0 + 2 * pad || 1));
  const X = (x) => (x - x0 + pad) * s, Y = (y) => height - (y - y0 + pad) * s;
  svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
  svg.setAttribute("width", String(width));
  svg.setAttribute("height", String(Math.round(height)));
  const add = (name, attrs) => {
    const el = document.createElementNS(SVG, name);
    for (const [k, v] of Object.entries(attrs)) el.setAttribute(k, String(v));
    svg.append(el);
    return el;
  };
  for (const t of thrust)
    add("line", {x1: X(t.edge[0][0]), y1: Y(t.edge[0][1]), x2: X(t.edge[1][0]), y2: Y(t.edge[1][1]),
                 stroke: "#999", "stroke-width": 2});
  const shares = (a, b) => [a.slave_body, a.master_body].some((n) => n === b.slave_body || n === b.master_body);
  for (let i = 1; i < thrust.length; ++i) {
    const a = thrust[i - 1], b = thrust[i];
    if (a.point && b.point && shares(a, b))
      add("line", {x1: X(a.point[0]), y1: Y(a.point[1]), x2: X(b.point[0]), y2: Y(b.point[1]),
                   stroke: "#1f6fb2", "stroke-width": 1.5});
  }
  let points = 0;
  for (const t of thrust) {
    if (!t.point) continue;
    add("circle", {cx: X(t.point[0]), cy: Y(t.point[1]), r: 3, fill: "#1f6fb2"}).append(
      Object.assign(document.createElementNS(SVG, "title"), {textContent: `${t.pair}: normal force ${t.force.toPrecision(4)}` +
        (typeof t.eccentricity === "number" ? `, eccentricity ${t.eccentricity.toFixed(3)} of the half-length` : "")}));
    ++points;
  }
  for (const h of hinges)
    add("circle", {cx: X(h.point[0]), cy: Y(h.point[1]), r: 6, fill: "none", stroke: "#d9480f", "stroke-width": 2});
  svg.dataset.points = String(points);
  svg.dataset.hinges = String(hinges.length);
}
