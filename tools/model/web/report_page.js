// resolver-model report page: draws the plots of the inline JSON (#report-data,
// written by tools/model/report_data.cpp) with uPlot, embedded before this script.
//
// Per plot: one uPlot chart; a legend whose entries show and hide their series; a
// readout of the values under the pointer; zoom (drag across, mouse wheel), pan
// (shift-drag), reset (double-click or the button); a CSV download of the plot's
// data. Plots of one group (the same x, e.g. the resolver angle) zoom together.
//
// window.resolverReport is the page's API (the Chromium tests drive it):
//   ready                true once every plot is drawn
//   plots                the JSON plot specs
//   chart(id)            the uPlot instance
//   xRange(id)           [min, max] of the visible x
//   setX(id, lo, hi)     zoom x (the group follows); reset(id): the full range
//   setShown(id, k, on)  show or hide the plot's series k (as its legend entry does); shown(id, k)
//   csv(id)              the plot's data as CSV text; download(id) saves it
(function () {
  "use strict";

  const source = document.getElementById("report-data");
  if (!source || typeof uPlot === "undefined") return;
  const data = JSON.parse(source.textContent);
  const charts = {};     // id -> {u, spec, full: [lo, hi], map: spec series -> uPlot series}
  const groups = {};     // group -> [id]
  let syncing = false;   // a group zoom in progress: do not echo it back

  function axisTitle(a) { return a.label + " [" + a.unit + "]"; }

  function withAlpha(color, alpha) {
    const m = /^#([0-9a-f]{2})([0-9a-f]{2})([0-9a-f]{2})$/i.exec(color);
    if (!m) return color;
    return "rgba(" + parseInt(m[1], 16) + "," + parseInt(m[2], 16) + "," + parseInt(m[3], 16) + "," + alpha + ")";
  }

  // A value uPlot can draw on this axis: null is a gap (and no point on a log axis at <= 0).
  function drawable(v, log) {
    if (v === null || v === undefined || !isFinite(v)) return null;
    return log && v <= 0 ? null : v;
  }

  function fullRange(spec) {
    let lo = spec.x.lo, hi = spec.x.hi;
    if (lo === null || hi === null) {
      let min = Infinity, max = -Infinity;
      for (const s of spec.series) for (const x of s.x) { if (x < min) min = x; if (x > max) max = x; }
      if (lo === null) lo = isFinite(min) ? min : 0;
      if (hi === null) hi = isFinite(max) ? max : 1;
      if (hi <= lo) { lo -= 0.5; hi += 0.5; }
    }
    return [lo, hi];
  }

  // uPlot series options for one mark.
  function seriesOptions(s, mark, label) {
    const o = { label: label, stroke: s.color, width: s.width, show: !s.hidden, spanGaps: false };
    if (s.dashed) o.dash = [6, 4];
    if (mark === "points") {
      o.paths = () => null;
      o.points = { show: true, size: s.width, fill: s.color, stroke: s.color, width: 0 };
    } else if (mark === "linepoints") {
      o.points = { show: true, size: 6, fill: s.color, stroke: s.color };
    } else {
      o.points = { show: false };
    }
    return o;
  }

  // Ticks at the plot's own step while a handful of them fit, else uPlot's choice.
  function splitsFor(step) {
    return (u, axisIdx, min, max, incr) => {
      const st = step > 0 && (max - min) / step >= 3 && (max - min) / step <= 16 ? step : incr;
      const out = [];
      for (let v = Math.ceil(min / st - 1e-9) * st; v <= max + 1e-9 * st; v += st) out.push(+v.toFixed(10));
      return out;
    };
  }

  // Log axes: a label at each decade ("1e-4", "0.01", "100"), none in between.
  function decadeLabels(u, splits) {
    return splits.map(v => {
      if (!(v > 0)) return "";
      const e = Math.log10(v);
      if (Math.abs(e - Math.round(e)) > 1e-6) return "";
      return Math.abs(e) <= 3 ? String(+v.toPrecision(1)) : "1e" + Math.round(e);
    });
  }

  function setX(id, lo, hi) {
    const c = charts[id];
    if (!c || !(hi > lo)) return;
    c.u.setScale("x", { min: lo, max: hi });
  }

  function reset(id) {
    const c = charts[id];
    if (c) setX(id, c.full[0], c.full[1]);
  }

  function follow(u, key) {
    if (key !== "x" || syncing) return;
    const me = Object.values(charts).find(c => c.u === u);
    if (!me || !me.spec.group) return;
    syncing = true;
    try {
      for (const id of groups[me.spec.group]) {
        if (charts[id] && charts[id].u !== u) charts[id].u.setScale("x", { min: u.scales.x.min, max: u.scales.x.max });
      }
    } finally {
      syncing = false;
    }
  }

  function csvField(v) {
    if (typeof v === "string") return '"' + v.replace(/"/g, '""') + '"';
    return v === null || v === undefined || !isFinite(v) ? "NaN" : String(v);
  }

  // One row per point, in the axes' units: series, x, y (and spread, samples for binned data).
  function csv(id) {
    const spec = charts[id] ? charts[id].spec : data.plots.find(p => p.id === id);
    if (!spec) throw new Error("no plot " + id);
    const bands = spec.series.some(s => s.mark === "band");
    const head = ["series", spec.x.column, spec.y.column];
    if (bands) head.push(spec.y.column + "_sd", "samples");
    const lines = [head.join(",")];
    for (const s of spec.series) {
      for (let i = 0; i < s.x.length; i++) {
        const row = [s.label, s.x[i], s.y[i]];
        if (bands) row.push(s.spread ? s.spread[i] : null, s.count ? s.count[i] : null);
        lines.push(row.map(csvField).join(","));
      }
    }
    return lines.join("\n") + "\n";
  }

  function download(id) {
    const blob = new Blob([csv(id)], { type: "text/csv" });
    const a = document.createElement("a");
    const page = (location.pathname.split("/").pop() || "report").replace(/\.html?$/, "");
    a.href = URL.createObjectURL(blob);
    a.download = page + "-" + id + ".csv";
    document.body.appendChild(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(a.href), 10000);
  }

  // The nearest point of a series with sorted x (binned data, lines) to x, or null.
  function nearest(s, x) {
    let lo = 0, hi = s.x.length - 1;
    if (hi < 0) return null;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (s.x[mid] < x) lo = mid; else hi = mid;
    }
    const i = Math.abs(s.x[lo] - x) <= Math.abs(s.x[hi] - x) ? lo : hi;
    return s.y[i] === null ? null : { x: s.x[i], y: s.y[i] };
  }

  function fmt(v) {
    const a = Math.abs(v);
    return a !== 0 && (a < 1e-3 || a >= 1e5) ? v.toExponential(3) : (+v.toPrecision(4)).toString();
  }

  function readout(id, u) {
    const el = document.querySelector('[data-readout="' + id + '"]');
    if (!el) return;
    const left = u.cursor.left;
    if (left === undefined || left < 0) { el.textContent = ""; return; }
    const spec = charts[id].spec;
    const x = u.posToVal(left, "x");
    const parts = [spec.x.label.split(",")[0] + " = " + fmt(x) + " " + spec.x.unit];
    spec.series.forEach((s, k) => {
      if (s.mark === "points" || !s.legend || !u.series[charts[id].map[k][0]].show) return;
      const p = nearest(s, x);
      if (p) parts.push(s.label.split(":")[0] + ": " + fmt(p.y) + " " + spec.y.unit);
    });
    el.textContent = parts.join(" · ");
  }

  // Shows or hides spec series k of a plot (its band edges too), and any series after it
  // that has no legend entry of its own (the second floor line).
  function setShown(id, k, show) {
    const c = charts[id];
    for (let j = k; j < c.spec.series.length && (j === k || !c.spec.series[j].legend); j++) {
      for (const i of c.map[j]) c.u.setSeries(i, { show: show });
    }
    const item = document.querySelector('[data-legend="' + id + '"] [data-series="' + k + '"]');
    if (item) item.classList.toggle("off", !show);
  }

  function legend(id, u, spec, map) {
    const box = document.querySelector('[data-legend="' + id + '"]');
    if (!box) return;
    spec.series.forEach((s, k) => {
      if (!s.legend) return;
      const item = document.createElement("button");
      item.type = "button";
      item.className = "legend-item" + (s.hidden ? " off" : "");
      const mark = document.createElement("span");
      mark.className = "mark " + s.mark + (s.dashed ? " dashed" : "");
      mark.style.setProperty("--c", s.color);
      mark.style.setProperty("--band", withAlpha(s.color, 0.2));
      item.appendChild(mark);
      item.appendChild(document.createTextNode(s.label));
      item.title = "show or hide";
      item.dataset.series = k;
      item.addEventListener("click", () => setShown(id, k, !u.series[map[k][0]].show));
      box.appendChild(item);
    });
  }

  // Wheel zooms about the pointer; shift-drag pans; double-click resets.
  function interactions(id, u) {
    u.over.addEventListener("wheel", e => {
      e.preventDefault();
      const rect = u.over.getBoundingClientRect();
      const x = u.posToVal(e.clientX - rect.left, "x");
      const f = e.deltaY < 0 ? 0.75 : 1 / 0.75;
      const { min, max } = u.scales.x;
      setX(id, x - (x - min) * f, x + (max - x) * f);
    }, { passive: false });
    u.root.addEventListener("mousedown", e => {
      if (!e.shiftKey || e.button !== 0 || !u.over.contains(e.target)) return;
      e.stopPropagation();  // capture phase, on an ancestor: uPlot's own drag never sees it
      e.preventDefault();
      const x0 = e.clientX;
      const { min, max } = u.scales.x;
      const perPx = (max - min) / u.over.getBoundingClientRect().width;
      const move = ev => { const dx = (ev.clientX - x0) * perPx; setX(id, min - dx, max - dx); };
      const up = () => { document.removeEventListener("mousemove", move); document.removeEventListener("mouseup", up); };
      document.addEventListener("mousemove", move);
      document.addEventListener("mouseup", up);
    }, true);
    u.over.addEventListener("dblclick", () => reset(id));
  }

  function draw(spec) {
    const el = document.querySelector('[data-plot="' + spec.id + '"]');
    if (!el) return;
    const log = spec.y.log;
    const tables = [];
    const series = [{ label: axisTitle(spec.x) }];
    const bands = [];
    const map = [];  // spec series k -> its uPlot series indices
    for (const s of spec.series) {
      const first = series.length;
      const y = s.y.map(v => drawable(v, log));
      if (s.mark === "band") {
        const hi = s.y.map((v, i) => drawable(v === null || s.spread[i] === null ? null : v + s.spread[i], log));
        const lo = s.y.map((v, i) => drawable(v === null || s.spread[i] === null ? null : v - s.spread[i], log));
        tables.push([s.x, y, hi, lo]);
        series.push(seriesOptions(s, "points", s.label));
        const edge = { label: s.label + " (±1 σ)", stroke: withAlpha(s.color, 0), width: 1, show: !s.hidden,
                       spanGaps: false, points: { show: false } };
        series.push(edge, Object.assign({}, edge));
        bands.push({ series: [first + 1, first + 2], fill: withAlpha(s.color, 0.18) });
        map.push([first, first + 1, first + 2]);
      } else {
        tables.push([s.x, y]);
        series.push(seriesOptions(s, s.mark, s.label));
        map.push([first]);
      }
    }
    const full = fullRange(spec);
    const opts = {
      width: Math.max(el.clientWidth, 300),
      height: spec.height,
      series: series,
      bands: bands,
      legend: { show: false },
      cursor: { drag: { x: true, y: false, setScale: true }, bind: { dblclick: () => null } },
      scales: {
        // While the chart is built: the plot's full range (the angle's 0-360 deg, not the data's
        // extent); afterwards whatever zoom, pan or reset asks for.
        x: { time: false, range: (u, min, max) => (charts[spec.id] ? [min, max] : full) },
        y: log ? {
          distr: 3,
          log: 10,
          range: (u, min, max) => uPlot.rangeLog(Math.max(min, spec.y.lo === null ? min : spec.y.lo), max, 10, true),
        } : { auto: true },
      },
      axes: [
        { label: axisTitle(spec.x), splits: splitsFor(spec.x.step), labelSize: 24 },
        Object.assign({ label: axisTitle(spec.y), labelSize: 28, size: 64 }, log ? { values: decadeLabels } : {}),
      ],
      hooks: {
        setScale: [(u, key) => follow(u, key)],
        setCursor: [u => readout(spec.id, u)],
      },
    };
    const u = new uPlot(opts, uPlot.join(tables), el);
    charts[spec.id] = { u: u, spec: spec, full: full, map: map };
    if (spec.group) (groups[spec.group] = groups[spec.group] || []).push(spec.id);
    legend(spec.id, u, spec, map);
    interactions(spec.id, u);
  }

  for (const spec of data.plots) {
    for (const s of spec.series) if (s.legend === undefined) s.legend = true;
    draw(spec);
  }
  for (const id of Object.keys(charts)) reset(id);

  document.addEventListener("click", e => {
    const b = e.target.closest("button[data-csv], button[data-reset]");
    if (!b) return;
    if (b.dataset.csv) download(b.dataset.csv);
    else reset(b.dataset.reset);
  });
  let resizing = null;
  window.addEventListener("resize", () => {
    clearTimeout(resizing);
    resizing = setTimeout(() => {
      for (const id of Object.keys(charts)) {
        const el = document.querySelector('[data-plot="' + id + '"]');
        charts[id].u.setSize({ width: Math.max(el.clientWidth, 300), height: charts[id].spec.height });
      }
    }, 100);
  });

  window.resolverReport = {
    ready: true,
    plots: data.plots,
    chart: id => charts[id].u,
    xRange: id => [charts[id].u.scales.x.min, charts[id].u.scales.x.max],
    setX: setX,
    reset: reset,
    setShown: setShown,
    shown: (id, k) => charts[id].u.series[charts[id].map[k][0]].show,
    csv: csv,
    download: download,
  };
})();
