// The live plots of a job, drawn with uPlot (server/web/vendor/, a global `uPlot`):
//   ConvergencePlot: what decides convergence, per iteration, on a log scale. The iteration event's `measure`
//     says what that is: fixed_point -> the fixed-point residual and the paper's criterion; complementarity ->
//     the complementarity residual and, on a linear axis at the right, the active-set changes; gradient -> the
//     relative energy gradient (carried in fixed_point_residual).
//   PressurePlot: one pair's contact pressure along its slave edge (arc length), the latest iteration's profile;
//     for a friction pair (its events carry `tangential_tractions` and `stick`) the tangential traction below it,
//     on the same arc length, with the stick zone shaded green.
//   CapacityPlot: a collapse analysis's capacity curve: the multiplier of every trial that held against the live
//     loads' displacement (the job's collapse.trials), drawn once the job has its answer.
// Each keeps its data and redraws at most a few times a second; the container's data-points / data-iteration
// (and data-tangential-points / data-stick-zones) attributes say what has been drawn (what the browser test
// reads).

const COLOURS = ["#1f6fb2", "#d9480f", "#2b8a3e", "#862e9c"];
const STICK_FILL = "rgba(44, 160, 44, 0.2)";  // the client plot's stick zone (tab:green, alpha 0.2)

const SERIES = {
  fixed_point: [
    {key: "fixed_point_residual", label: "fixed-point residual"},
    {key: "paper_criterion", label: "paper's criterion"},
  ],
  complementarity: [
    {key: "complementarity", label: "complementarity"},
    {key: "active_set_changes", label: "active-set changes", linear: true},
  ],
  gradient: [
    {key: "fixed_point_residual", label: "energy gradient"},
  ],
};

// Tick labels of a log axis: plain numbers near 1, powers of ten beyond (uPlot's default rounds 1e-5 to "0").
function logTicks(u, splits) {
  return splits.map((v) => (v === null || v === undefined ? "" :
                            v >= 1e-3 && v < 1e4 ? String(+v.toPrecision(3)) : v.toExponential(0)));
}

function width(el) {
  return Math.max(320, Math.floor(el.clientWidth || el.parentElement.clientWidth || 640));
}

// A positive finite number, or null (a gap: log scales cannot show 0).
function positive(v) {
  return typeof v === "number" && isFinite(v) && v > 0 ? v : null;
}

function finite(v) {
  return typeof v === "number" && isFinite(v) ? v : null;
}

class Throttled {
  constructor(draw, ms = 200) {
    this.draw = draw;
    this.ms = ms;
    this.timer = null;
  }
  request() {
    if (this.timer === null) this.timer = setTimeout(() => { this.timer = null; this.draw(); }, this.ms);
  }
  cancel() {
    if (this.timer !== null) clearTimeout(this.timer);
    this.timer = null;
  }
}

export class ConvergencePlot {
  constructor(el, titleEl) {
    this.el = el;
    this.titleEl = titleEl;
    this.throttle = new Throttled(() => this.draw());
    this.reset();
  }

  reset() {
    this.throttle.cancel();
    if (this.plot) this.plot.destroy();
    this.plot = null;
    this.measures = [];  // the measures seen, in order (one, except for unusual jobs)
    this.x = [];
    this.values = {};    // key -> array aligned with x
    this.el.dataset.points = "0";
    this.titleEl.textContent = "Convergence";
  }

  add(event) {
    const it = finite(event.iteration);
    if (it === null) return;
    // A job run again from the start (after a server restart) numbers its iterations from 1 again.
    if (this.x.length && it <= this.x[this.x.length - 1]) this.reset();
    const measure = SERIES[event.measure] ? event.measure : "fixed_point";
    if (!this.measures.includes(measure)) {
      this.measures.push(measure);
      if (this.plot) this.plot.destroy();
      this.plot = null;  // rebuilt with the new series at the next draw
    }
    this.x.push(it);
    for (const spec of Object.values(SERIES).flat()) {
      if (!this.values[spec.key]) this.values[spec.key] = [];
      const v = event[spec.key];
      this.values[spec.key].push(spec.linear ? finite(v) : positive(v));
    }
    this.throttle.request();
  }

  series() {
    const seen = new Set();
    const out = [];
    for (const m of this.measures)
      for (const spec of SERIES[m])
        if (!seen.has(spec.key)) {
          seen.add(spec.key);
          out.push(spec);
        }
    return out;
  }

  draw() {
    if (!this.x.length) return;
    const specs = this.series();
    const data = [this.x, ...specs.map((s) => this.values[s.key])];
    if (!this.plot) {
      const linear = specs.some((s) => s.linear);
      this.plot = new uPlot({
        width: width(this.el),
        height: 280,
        scales: {x: {time: false}, y: {distr: 3, log: 10}, n: {range: (u, lo, hi) => [0, Math.max(1, hi)]}},
        axes: [
          {label: "iteration"},
          {label: "relative residual (log)", scale: "y", size: 70, values: logTicks},
          ...(linear ? [{label: "active-set changes", scale: "n", side: 1, grid: {show: false}}] : []),
        ],
        series: [
          {label: "iteration"},
          ...specs.map((s, i) => ({
            label: s.label,
            scale: s.linear ? "n" : "y",
            stroke: COLOURS[i % COLOURS.length],
            width: s.linear ? 1 : 1.5,
            dash: s.linear ? [4, 3] : undefined,
            points: {show: (u) => u.data[0].length < 60},
            spanGaps: false,
          })),
        ],
      }, data, this.el);
    } else {
      this.plot.setData(data);
    }
    const names = this.measures.map((m) => m.replace("_", "-")).join(", ");
    this.titleEl.textContent = `Convergence (${names}: ${this.x.length} iterations)`;
    this.el.dataset.points = String(this.x.length);
  }

  resize() {
    if (this.plot) this.plot.setSize({width: width(this.el), height: 280});
  }
}

// Where the nodes stick along the sorted arc lengths x (stick[i] 1: node i sticks): [[lo, hi], ...], one per run
// of neighbouring sticking nodes, each reaching halfway to the next node that does not stick (to the node itself
// at an end of the edge): the client plot's stick_zones().
export function stickZones(x, stick) {
  const zones = [];
  for (let i = 0; i < x.length; ++i) {
    if (stick[i] !== 1) continue;
    let j = i;
    while (j + 1 < x.length && stick[j + 1] === 1) ++j;
    zones.push([i > 0 ? (x[i - 1] + x[i]) / 2 : x[i], j + 1 < x.length ? (x[j] + x[j + 1]) / 2 : x[j]]);
    i = j;
  }
  return zones;
}

// A uPlot draw hook that shades the zones [[lo, hi], ...] (x values) across the plotting area, under the series.
function shadeZones(getZones) {
  return (u) => {
    const {top, height} = u.bbox;
    u.ctx.save();
    u.ctx.fillStyle = STICK_FILL;
    for (const [lo, hi] of getZones()) {
      const a = u.valToPos(lo, "x", true);
      const b = u.valToPos(hi, "x", true);
      u.ctx.fillRect(Math.min(a, b), top, Math.max(1, Math.abs(b - a)), height);
    }
    u.ctx.restore();
  };
}

// A friction pair's tangential traction along the slave edge, the stick zone shaded: the chart under its
// pressure (PressurePlot makes it when the events carry tangential tractions).
class TangentialChart {
  constructor(el) {
    this.caption = document.createElement("div");
    this.caption.className = "muted";
    this.chart = document.createElement("div");
    this.chart.className = "chart tangential";
    el.append(this.chart, this.caption);
    this.el = el;
    this.plot = null;
    this.zones = [];
  }

  // d: the latest profile (PressurePlot.add), zones: its stick zones.
  draw(d, zones) {
    this.zones = zones;
    const data = [d.x, d.t];
    if (!this.plot) {
      this.plot = new uPlot({
        width: width(this.chart),
        height: 220,
        scales: {x: {time: false}},
        axes: [{label: "arc length along the slave edge"}, {label: "tangential traction", size: 70}],
        series: [{label: "s"},
                 {label: "tangential traction", stroke: COLOURS[0], width: 1.5,
                  points: {show: (u) => u.data[0].length < 80}}],
        hooks: {drawClear: [shadeZones(() => this.zones)]},
      }, data, this.chart);
    } else {
      this.plot.setData(data);
    }
    const num = (v, digits) => (typeof v === "number" && isFinite(v) ? v.toPrecision(digits) : "?");
    const where = this.zones.map(([lo, hi]) => `${num(lo, 4)} to ${num(hi, 4)}`).join(", ");
    this.caption.textContent = `tangential force ${num(d.pair.tangential_force, 6)}; ` +
        (where ? `stick zone (shaded): ${where}` : "no node sticks");
    this.el.dataset.tangentialPoints = String(d.x.length);
    this.el.dataset.stickZones = JSON.stringify(this.zones);
  }

  resize() {
    if (this.plot) this.plot.setSize({width: width(this.chart), height: 220});
  }

  destroy() {
    if (this.plot) this.plot.destroy();
  }
}

export class PressurePlot {
  constructor(el, name) {
    this.el = el;
    this.name = name;
    this.caption = document.createElement("div");
    this.caption.className = "muted";
    this.chart = document.createElement("div");
    this.chart.className = "chart";
    const title = document.createElement("strong");
    title.textContent = name;
    el.append(title, this.caption, this.chart);
    this.plot = null;
    this.tangential = null;  // a TangentialChart once the events carry tangential tractions
    this.latest = null;
    this.throttle = new Throttled(() => this.draw());
    el.dataset.iteration = "0";
  }

  add(iteration, pair) {
    if (!Array.isArray(pair.positions) || !Array.isArray(pair.pressures)) return;
    const n = Math.min(pair.positions.length, pair.pressures.length);
    // A friction pair: its tangential tractions and stick flags, node by node with the positions.
    const friction = Array.isArray(pair.tangential_tractions) && Array.isArray(pair.stick) &&
        pair.tangential_tractions.length === n && pair.stick.length === n;
    // uPlot wants x increasing: arc lengths are, but sort anyway.
    const rows = [];
    for (let i = 0; i < n; ++i)
      if (finite(pair.positions[i]) !== null)
        rows.push([pair.positions[i], finite(pair.pressures[i]),
                   friction ? finite(pair.tangential_tractions[i]) : null, friction ? pair.stick[i] : 0]);
    rows.sort((a, b) => a[0] - b[0]);
    this.latest = {iteration, x: rows.map((r) => r[0]), p: rows.map((r) => r[1]), pair,
                   t: friction ? rows.map((r) => r[2]) : null, stick: rows.map((r) => r[3])};
    this.throttle.request();
  }

  draw() {
    const d = this.latest;
    if (!d) return;
    const data = [d.x, d.p];
    this.zones = d.t ? stickZones(d.x, d.stick) : [];
    if (!this.plot) {
      this.plot = new uPlot({
        width: width(this.chart),
        height: 220,
        scales: {x: {time: false}, y: {range: (u, lo, hi) => [Math.min(0, lo), hi > 0 ? hi * 1.05 : 1]}},
        axes: [{label: "arc length along the slave edge"}, {label: "pressure", size: 70}],
        series: [{label: "s"},
                 {label: "pressure", stroke: COLOURS[1], width: 1.5, points: {show: (u) => u.data[0].length < 80}}],
        hooks: d.t ? {drawClear: [shadeZones(() => this.zones)]} : {},  // a friction pair: its stick zone too
      }, data, this.chart);
    } else {
      this.plot.setData(data);
    }
    const num = (v, digits) => (typeof v === "number" && isFinite(v) ? v.toPrecision(digits) : "?");
    this.caption.textContent = `iteration ${d.iteration}: force ${num(d.pair.force, 6)}, ` +
        `max pressure ${num(d.pair.max_pressure, 6)}, ${d.pair.active_nodes ?? "?"} nodes in contact`;
    if (d.t) {
      if (!this.tangential) this.tangential = new TangentialChart(this.el);
      this.tangential.draw(d, this.zones);
    }
    this.el.dataset.iteration = String(d.iteration);
  }

  resize() {
    if (this.plot) this.plot.setSize({width: width(this.chart), height: 220});
    if (this.tangential) this.tangential.resize();
  }

  destroy() {
    this.throttle.cancel();
    if (this.plot) this.plot.destroy();
    if (this.tangential) this.tangential.destroy();
  }
}

// The capacity curve of a collapse analysis (docs/limit-analysis.md): the held trials' multiplier against the live
// loads' displacement, sorted by multiplier, with the bracket's top (the smallest multiplier that did not hold) as a
// dashed level. The container's data-points says how many held trials are drawn (what the browser test reads).
export class CapacityPlot {
  constructor(el) {
    this.el = el;
    this.plot = null;
    this.el.dataset.points = "0";
  }

  show(collapse) {
    if (this.plot) this.plot.destroy();
    this.plot = null;
    const held = (collapse && collapse.trials ? collapse.trials : [])
      .filter((t) => t.held && finite(t.displacement) !== null)
      .sort((a, b) => a.multiplier - b.multiplier);
    this.el.dataset.points = String(held.length);
    this.el.hidden = held.length < 2;
    if (held.length < 2) return;
    // From the loading's end (multiplier 0: the dead loads' state) where the job says where that was.
    const start = finite(collapse.start_displacement);
    const x = [...(start === null ? [] : [start]), ...held.map((t) => t.displacement)];
    const y = [...(start === null ? [] : [0]), ...held.map((t) => t.multiplier)];
    const top = finite(collapse.failed);
    const data = [x, y, x.map(() => top)];
    this.plot = new uPlot({
      width: width(this.el),
      height: 240,
      scales: {x: {time: false}},
      axes: [{label: "live loads' displacement"}, {label: "multiplier", size: 60}],
      series: [
        {label: "displacement"},
        {label: "held", stroke: COLOURS[0], width: 1.5, points: {show: true}},
        {label: "did not hold", stroke: COLOURS[1], width: 1, dash: [4, 3], points: {show: false}},
      ],
    }, data, this.el);
  }

  resize() {
    if (this.plot) this.plot.setSize({width: width(this.el), height: 240});
  }
}
