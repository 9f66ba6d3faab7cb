// resolver-model fleet page (tools/model/fleet_page.cpp): what its strip plots add to the
// report page's script (report_page.js, which draws every plot and runs before this one).
//
// A series of the page's data may carry, per point:
//   err           a standard error: drawn as an error bar y +- err
//   names         the unit's id: the readout names the unit under the pointer
//   label_points  true: each point's name is written beside it (the outlier units)
// Both are drawn on uPlot's canvas after each redraw (zoom, resize, legend), and only
// while their series is shown. The value axis labels small values (1e-6 rad) in exponent
// form, and the units axis labels whole rows only.
//
// window.resolverFleet (the tests may drive it): ready; unitAt(id, x) -> the name of the
// unit at x in plot id, or null.
(function () {
  "use strict";

  const api = window.resolverReport;
  if (!api || typeof uPlot === "undefined") return;

  function fmt(v) {
    const a = Math.abs(v);
    return a !== 0 && (a < 1e-3 || a >= 1e5) ? v.toExponential(3) : (+v.toPrecision(4)).toString();
  }

  // The spec series k of a plot that names its points and has error bars (the units), or the first naming one.
  function unitSeries(spec) {
    return spec.series.find(s => s.names && s.err) || spec.series.find(s => s.names) || null;
  }

  // A tick label of a value axis: a parameter may be 1e-6 rad, where uPlot's own labels all read 0.
  function valueTick(v, incr) {
    if (Math.abs(v) < Math.abs(incr) * 1e-6) return "0";
    const a = Math.abs(v);
    return a < 1e-3 || a >= 1e5 ? v.toExponential(2).replace(/\.?0+e/, "e") : String(+v.toPrecision(4));
  }

  // A tick label of the units axis: whole rows only.
  function rowTick(v) {
    return Math.abs(v - Math.round(v)) < 1e-9 ? String(Math.round(v)) : "";
  }

  // Index of the point of s nearest x, within half a unit; -1 if none.
  function nearestPoint(s, x) {
    let best = -1;
    for (let i = 0; i < s.x.length; i++) {
      if (s.y[i] === null) continue;
      if (best < 0 || Math.abs(s.x[i] - x) < Math.abs(s.x[best] - x)) best = i;
    }
    return best >= 0 && Math.abs(s.x[best] - x) <= 0.5 ? best : -1;
  }

  function decorate(u, spec) {
    const ctx = u.ctx;
    const px = uPlot.pxRatio || window.devicePixelRatio || 1;
    const { left, top, width, height } = u.bbox;
    ctx.save();
    ctx.beginPath();
    ctx.rect(left, top, width, height);
    ctx.clip();
    spec.series.forEach((s, k) => {
      if (!api.shown(spec.id, k)) return;
      if (s.err) {
        ctx.strokeStyle = s.color;
        ctx.lineWidth = px;
        ctx.beginPath();
        for (let i = 0; i < s.x.length; i++) {
          const y = s.y[i], e = s.err[i];
          if (y === null || e === null || !(e > 0)) continue;
          const x = u.valToPos(s.x[i], "x", true);
          const lo = u.valToPos(y - e, "y", true), hi = u.valToPos(y + e, "y", true);
          ctx.moveTo(x, lo); ctx.lineTo(x, hi);
          ctx.moveTo(x - 3 * px, lo); ctx.lineTo(x + 3 * px, lo);
          ctx.moveTo(x - 3 * px, hi); ctx.lineTo(x + 3 * px, hi);
        }
        ctx.stroke();
      }
      if (s.label_points && s.names) {
        ctx.fillStyle = s.color;
        ctx.strokeStyle = "#ffffff";  // a halo: the label stays readable over points and grid
        ctx.lineWidth = 3 * px;
        ctx.font = 12 * px + "px system-ui, 'DejaVu Sans', sans-serif";
        ctx.textBaseline = "middle";
        for (let i = 0; i < s.x.length; i++) {
          if (s.y[i] === null) continue;
          const x = u.valToPos(s.x[i], "x", true), y = u.valToPos(s.y[i], "y", true);
          const right = x > left + width * 0.8;  // near the right edge: the label goes on the left
          ctx.textAlign = right ? "right" : "left";
          ctx.strokeText(s.names[i], right ? x - 8 * px : x + 8 * px, y);
          ctx.fillText(s.names[i], right ? x - 8 * px : x + 8 * px, y);
        }
      }
    });
    ctx.restore();
  }

  // The readout names the unit under the pointer, with its value and standard error.
  function readout(u, spec) {
    const el = document.querySelector('[data-readout="' + spec.id + '"]');
    const s = unitSeries(spec);
    if (!el || !s || u.cursor.left === undefined || u.cursor.left < 0) return;
    const i = nearestPoint(s, u.posToVal(u.cursor.left, "x"));
    if (i < 0) return;
    const err = s.err && s.err[i] !== null ? " ± " + fmt(s.err[i]) : "";
    el.textContent = "unit " + s.names[i] + ": " + spec.y.label + " = " + fmt(s.y[i]) + err + " " + spec.y.unit;
  }

  for (const spec of api.plots) {
    if (!spec.series.some(s => s.names || s.err)) continue;
    let u;
    try { u = api.chart(spec.id); } catch (e) { continue; }  // not drawn (no element)
    (u.hooks.draw = u.hooks.draw || []).push(u => decorate(u, spec));
    (u.hooks.setCursor = u.hooks.setCursor || []).push(u => readout(u, spec));
    u.axes[0].values = (u, splits) => splits.map(rowTick);
    u.axes[1].values = (u, splits, axis, space, incr) => splits.map(v => valueTick(v, incr));
    u.redraw(true, true);
  }

  window.resolverFleet = {
    ready: true,
    unitAt: (id, x) => {
      const spec = api.plots.find(p => p.id === id);
      const s = spec && unitSeries(spec);
      const i = s ? nearestPoint(s, x) : -1;
      return i < 0 ? null : s.names[i];
    },
  };
})();
