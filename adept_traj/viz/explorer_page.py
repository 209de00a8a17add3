"""The HTML and JavaScript of the front explorer (:mod:`adept_traj.viz.explorer`).

:data:`PAGE_TEMPLATE` has three place-holders: ``@@TITLE@@``, ``@@PLOTLY@@`` (Plotly's
library) and ``@@DATA@@`` (:func:`~adept_traj.viz.explorer.explorer_data` as JSON). The
script's functions mirror the library's, each named in a comment: the B-spline
(:mod:`adept_traj.problem.bspline`), the fixed-step grid and the file formats
(:mod:`adept_traj.export`), the best trade-off (:func:`adept_traj.analysis.best_tradeoff`).
"""

from __future__ import annotations

__all__ = ["PAGE_TEMPLATE"]

PAGE_TEMPLATE = r"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>@@TITLE@@</title>
<style>
body { font-family: sans-serif; margin: 8px; color: #222; }
h1 { font-size: 18px; margin: 4px 0; }
.row { display: flex; gap: 8px; flex-wrap: wrap; }
.panel { border: 1px solid #ccc; border-radius: 4px; padding: 6px; }
#weights label { display: inline-block; width: 150px; font-size: 13px; }
#weights input[type=range] { width: 160px; vertical-align: middle; }
#certificate { font-size: 13px; width: 420px; white-space: pre-wrap; }
#controls { font-size: 13px; margin: 4px 0; }
.note { font-size: 12px; color: #555; }
</style>
<script>@@PLOTLY@@</script>
</head><body>
<h1 id="title"></h1>
<div class="note" id="summary"></div>
<div class="panel"><div id="parcoords" style="width:100%;height:330px"></div>
<div class="note">Drag along an axis to brush (filter) the members; click a brushed range to
clear it. <span id="selected-count"></span></div></div>
<div class="row">
 <div class="panel"><div>x <select id="scatter-x"></select> y <select id="scatter-y"></select>
  <span class="note">click a point to play that member</span></div>
  <div id="scatter" style="width:560px;height:420px"></div></div>
 <div class="panel" id="weights"><b>Weights of f<sub>c</sub></b> (as adept_traj.analysis.best_tradeoff)<br>
  <div id="sliders"></div>
  <div>best trade-off for these weights: <b id="best-weighted"></b></div>
  <div class="note" id="best-stored"></div>
  <div>member <input id="member-input" type="number" min="0" style="width:70px">
   <button id="member-show">show</button></div>
 </div>
</div>
<div class="row">
 <div class="panel"><div id="controls">
  <button id="play">pause</button>
  <input id="scrub" type="range" min="0" max="1000" value="0" style="width:300px">
  <span id="time">t = 0.000 s</span> · <span id="shown-member"></span></div>
  <div id="view3d" style="width:640px;height:520px"></div></div>
 <div class="panel"><div id="joints" style="width:520px;height:420px"></div>
  <div>download at dt <input id="dt" value="0.001" style="width:60px"> s:
   <button id="download-csv">CSV</button> <button id="download-ros-json">ROS JSON</button>
   <button id="download-ros-yaml">ROS YAML</button>
   <span class="note" id="download-note"></span></div>
  <div id="certificate" class="panel"></div></div>
</div>
<script id="explorer-data" type="application/json">@@DATA@@</script>
<script>
"use strict";
const D = JSON.parse(document.getElementById("explorer-data").textContent);
const N = D.F.length, NQ = D.joint_names.length;
function f64(b64) { const s = atob(b64), u = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) u[i] = s.charCodeAt(i); return new Float64Array(u.buffer); }
function f32(b64) { const s = atob(b64), u = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) u[i] = s.charCodeAt(i); return new Float32Array(u.buffer); }
const X = f64(D.spline.x), NVAR = D.spline.n_var;
const PTS = f32(D.view.points), NP = D.view.n_points;
const OFFS = []; { let o = 0; for (const c of D.view.counts) { OFFS.push(o); o += c; } }
for (const ob of D.obstacles) ob.P = f32(ob.poses);

// ---------------------------------------------------------------- B-spline (problem.bspline)
const M = [[-1, 3, -3, 1], [3, -6, 3, 0], [-3, 0, 3, 0], [1, 4, 1, 0]].map(r => r.map(v => v / 6));
function controlPoints(k) {  // (n_control, nq): 3 x start, free joint-major, 3 x goal
  const x = X.subarray(k * NVAR, (k + 1) * NVAR), nf = (NVAR - 1) / NQ, P = [];
  for (let i = 0; i < 3; i++) P.push(D.spline.start.slice());
  for (let i = 0; i < nf; i++) { const row = []; for (let j = 0; j < NQ; j++) row.push(x[1 + j * nf + i]); P.push(row); }
  for (let i = 0; i < 3; i++) P.push(D.spline.goal.slice());
  return {T: x[0], P: P};
}
function monomials(u, r) {
  if (r === 0) return [u ** 3, u ** 2, u, 1];
  if (r === 1) return [3 * u ** 2, 2 * u, 1, 0];
  if (r === 2) return [6 * u, 2, 0, 0];
  return [6, 0, 0, 0];
}
function sampleSpline(k, times, orders) {  // {q, qd, qdd}: arrays (n) of (nq)
  const {T, P} = controlPoints(k), S = P.length - 3, out = {};
  for (const r of orders) {
    const scale = r === 0 ? 1 : T ** (-r), rows = [];
    for (const t of times) {
      const s = Math.min(Math.max(t / T, 0), 1), seg = Math.min(Math.floor(s * S), S - 1), u = s * S - seg;
      const m = monomials(u, r), b = [0, 0, 0, 0];
      for (let c = 0; c < 4; c++) { let v = 0; for (let a = 0; a < 4; a++) v += m[a] * M[a][c]; b[c] = v * S ** r; }
      const q = [];
      for (let j = 0; j < NQ; j++) { let v = 0; for (let c = 0; c < 4; c++) v += b[c] * (P[seg + c][j] * scale); q.push(v); }
      rows.push(q);
    }
    out[["q", "qd", "qdd"][r]] = rows;
  }
  return {T: T, ...out};
}
// ---------------------------------------------------------------- export (export.fixed_step)
function fixedStepTimes(T, dt) {
  if (!(dt > 0) || dt > T || dt < T / 999999) throw new Error("dt = " + dt + " s must lie in [T/999999, T = " + T + " s]");
  const k = Math.ceil(T / dt - 1e-9), t = [], mult = multiples(dt, k);
  for (let i = 0; i < k; i++) { const v = mult(i); if (v < T - 1e-9 * dt) t.push(v); }
  t.push(T); return t;
}
function multiples(dt, n) {  // results.fixed_step._multiples: (i·m)/10^e, dt's decimal m·10^-e
  const [mant, ex] = String(dt).toLowerCase().split("e"), dot = mant.indexOf(".");
  const m = parseInt(mant.replace(".", ""), 10), e = (ex ? parseInt(ex, 10) : 0) - (dot < 0 ? 0 : mant.length - dot - 1);
  const num = e >= 0 ? m * 10 ** e : m, den = e >= 0 ? 1 : 10 ** -e, exact = 2 ** 53;
  if (den <= exact && num * Math.max(n - 1, 1) <= exact && Number.isSafeInteger(num)) return i => (i * num) / den;
  return i => i * dt;
}
function pyRepr(x) {  // Python's repr of a float (shortest round trip)
  if (x === 0) return Object.is(x, -0) ? "-0.0" : "0.0";
  if (!isFinite(x)) return isNaN(x) ? "nan" : (x > 0 ? "inf" : "-inf");
  let [mant, ex] = x.toExponential().split("e"); const exp = parseInt(ex, 10);
  const neg = mant[0] === "-"; if (neg) mant = mant.slice(1);
  const dg = mant.replace(".", ""); let out;
  if (exp < -4 || exp >= 16) out = dg[0] + (dg.length > 1 ? "." + dg.slice(1) : "") + "e" + (exp < 0 ? "-" : "+") + String(Math.abs(exp)).padStart(2, "0");
  else if (exp >= 0) out = dg.length <= exp + 1 ? dg + "0".repeat(exp + 1 - dg.length) + ".0" : dg.slice(0, exp + 1) + "." + dg.slice(exp + 1);
  else out = "0." + "0".repeat(-exp - 1) + dg;
  return (neg ? "-" : "") + out;
}
function fixedStep(k, dt) { const T = X[k * NVAR]; const t = fixedStepTimes(T, dt); return {t: t, ...sampleSpline(k, t, [0, 1, 2])}; }
function csvText(k, dt) {
  const s = fixedStep(k, dt), lines = [D.csv_header.join(",")];  // results.fixed_step.csv_header
  for (let i = 0; i < s.t.length; i++) lines.push([s.t[i], ...s.q[i], ...s.qd[i], ...s.qdd[i]].map(pyRepr).join(","));
  return lines.join("\n") + "\n";
}
function jsonValue(v) {  // json.dumps of the message's values
  if (typeof v === "number") return Number.isInteger(v) && !v.isFloat ? String(v) : pyRepr(v);
  if (v === null) return "null"; if (typeof v === "boolean") return String(v);
  if (typeof v === "string") return JSON.stringify(v);
  if (Array.isArray(v)) return "[" + v.map(jsonValue).join(", ") + "]";
  if (v.__float !== undefined) return pyRepr(v.__float);
  return "{" + Object.entries(v).map(([a, b]) => JSON.stringify(a) + ": " + jsonValue(b)).join(", ") + "}";
}
function rosMessage(k, dt) {
  const s = fixedStep(k, dt), fl = a => a.map(v => ({__float: v})), cert = D.certified[k];
  const points = s.t.map((t, i) => { const ns = Math.round(t * 1e9);
    return {positions: fl(s.q[i]), velocities: fl(s.qd[i]), accelerations: fl(s.qdd[i]),
            time_from_start: {sec: Math.floor(ns / 1e9), nanosec: ns % 1e9}}; });
  return {certified: cert, member: k, best_tradeoff: k === D.best, dt: {__float: dt},
          warning: cert ? null : "NOT CERTIFIED: member " + k + " was exported with allow_uncertified; do not send it to a robot as is",
          header: {frame_id: ""}, joint_names: D.joint_names, points: points};
}
function rosJsonText(k, dt) {
  const m = rosMessage(k, dt), head = Object.entries(m).filter(([a]) => a !== "points").map(([a, b]) => "  " + JSON.stringify(a) + ": " + jsonValue(b) + ",");
  return ["{", ...head, '  "points": [', m.points.map(p => "    " + jsonValue(p)).join(",\n"), "  ]", "}"].join("\n") + "\n";
}
function rosYamlText(k, dt) {
  const m = rosMessage(k, dt), lines = [];
  for (const [a, b] of Object.entries(m)) if (a !== "header" && a !== "points") lines.push(a + ": " + jsonValue(b));
  lines.push("header:", '  frame_id: ""', "points:"); for (const p of m.points) lines.push("  - " + jsonValue(p));
  return lines.join("\n") + "\n";
}
function download(fmt) {
  const k = state.member, dt = parseFloat(document.getElementById("dt").value), note = document.getElementById("download-note");
  if (!D.certified[k] && !confirm("member " + k + " is NOT certified: download anyway?")) return;
  let text; try { text = {csv: csvText, "ros-json": rosJsonText, "ros-yaml": rosYamlText}[fmt](k, dt); }
  catch (e) { note.textContent = e.message; return; }
  const ext = {csv: ".csv", "ros-json": ".json", "ros-yaml": ".yaml"}[fmt];
  const a = document.createElement("a"); a.href = URL.createObjectURL(new Blob([text], {type: "text/plain"}));
  a.download = "member_" + k + ext; document.body.appendChild(a); a.click(); a.remove();
  note.textContent = "member_" + k + ext + " (" + text.split("\n").length + " lines)";
}
// ---------------------------------------------------------------- best trade-off (analysis.decision)
function minRank(v) { const s = v.slice().sort((a, b) => a - b);
  return v.map(x => { let lo = 0, hi = s.length; while (lo < hi) { const m = (lo + hi) >> 1; if (s[m] < x) lo = m + 1; else hi = m; } return lo + 1; }); }
function bestTradeoff(w) {
  const m = D.objectives.length, lo = [], hi = [];
  for (let i = 0; i < m; i++) { lo.push(Math.min(...D.F.map(r => r[i]))); hi.push(Math.max(...D.F.map(r => r[i]))); }
  const total = w.reduce((a, b) => a + b, 0), wn = w.map(v => v / total);
  const score = D.F.map(r => r.map((z, i) => { const span = hi[i] - lo[i]; if (!(span > 0)) return 1;
    return D.objectives[i].maximised ? (z - lo[i]) / span : (hi[i] - z) / span; }));
  const fc = score.map(n => n.reduce((a, v, i) => a + (1 - v) * wn[i], 0));
  const favg = score.map(n => n.reduce((a, v) => a + v, 0) / m);
  const rs = minRank(fc), ra = minRank(favg.map(v => -v)), sum = rs.map((v, i) => v + ra[i]);
  const order = [...Array(N).keys()].sort((a, b) => sum[a] - sum[b] || fc[a] - fc[b] || a - b);
  const certified = order.filter(k => D.certified[k]);
  return {order: order, index: certified.length ? certified[0] : order[0], fc: fc, favg: favg};
}
// ---------------------------------------------------------------- state and views
const state = {member: D.best, weighted: D.best, t: 0, playing: true, last: null, mask: new Array(N).fill(true)};
const AXES = [...D.objectives.map((o, i) => ({label: o.label, values: D.F.map(r => r[i])})),
  {label: "clearance [m]", values: D.clearance}, {label: "worst limit ratio [-]", values: D.worst_ratio}];
const fill = v => v.map(x => x === null ? NaN : x);
function memberText(k) { return "member " + k + (D.certified[k] ? " (certified)" : " (NOT certified)"); }
function drawParcoords() {
  const dims = AXES.map(a => { const v = fill(a.values).filter(isFinite);
    return {label: a.label.replace(/ \[/, "<br>["), values: fill(a.values).map(x => isFinite(x) ? x : Math.min(...v)),
            range: [Math.min(...v), Math.max(...v)]}; });
  Plotly.newPlot("parcoords", [{type: "parcoords", dimensions: dims,
    line: {color: D.certified.map((c, k) => k === state.weighted ? 2 : (c ? 1 : 0)),
           colorscale: [[0, "#bbbbbb"], [0.5, "#1f77b4"], [1, "#d62728"]], cmin: 0, cmax: 2}}],
    {margin: {l: 60, r: 60, t: 50, b: 20}}, {displayModeBar: false});
  document.getElementById("parcoords").on("plotly_restyle", brushed);
}
function brushed() {
  const dims = document.getElementById("parcoords").data[0].dimensions;
  state.mask = [...Array(N).keys()].map(k => dims.every((d, i) => {
    let cr = d.constraintrange; if (!cr) return true; if (!Array.isArray(cr[0])) cr = [cr];
    return cr.some(([a, b]) => d.values[k] >= a && d.values[k] <= b); }));
  const n = state.mask.filter(Boolean).length;
  document.getElementById("selected-count").textContent = n + " of " + N + " members in the brushed ranges";
  drawScatter();
}
function drawScatter() {
  const xi = +document.getElementById("scatter-x").value, yi = +document.getElementById("scatter-y").value;
  const ax = AXES[xi], ay = AXES[yi], traces = [];
  for (const [name, sel, color, sym] of [["certified", k => D.certified[k], "#1f77b4", "circle"],
                                         ["uncertified", k => !D.certified[k], "#999999", "x"]]) {
    const idx = [...Array(N).keys()].filter(sel);
    traces.push({type: "scatter", mode: "markers", name: name, x: idx.map(k => ax.values[k]), y: idx.map(k => ay.values[k]),
      customdata: idx, text: idx.map(memberText), hoverinfo: "text",
      marker: {color: color, symbol: sym, size: 7, opacity: idx.map(k => state.mask[k] ? 0.9 : 0.12)}});
  }
  for (const [name, k, color, sym] of [["best trade-off (weights)", state.weighted, "#d62728", "star"],
                                       ["shown member", state.member, "#2ca02c", "circle-open"]])
    traces.push({type: "scatter", mode: "markers", name: name, x: [ax.values[k]], y: [ay.values[k]], customdata: [k],
      text: [memberText(k)], hoverinfo: "text", marker: {color: color, symbol: sym, size: 16, line: {width: 2, color: color}}});
  Plotly.react("scatter", traces, {xaxis: {title: ax.label}, yaxis: {title: ay.label}, margin: {l: 70, r: 10, t: 10, b: 50},
    legend: {orientation: "h", y: -0.2}, hovermode: "closest"}, {displayModeBar: false});
}
function drawWeights() {
  const box = document.getElementById("sliders");
  D.objectives.forEach((o, i) => { const d = document.createElement("div");
    d.innerHTML = '<label for="w' + (i + 1) + '">w' + (i + 1) + " " + o.name + '</label><input type="range" id="w' + (i + 1) +
      '" min="0" max="1" step="0.01" value="' + D.weights[i] + '"> <span id="w' + (i + 1) + '-value">' + D.weights[i].toFixed(2) + "</span>";
    box.appendChild(d); d.querySelector("input").addEventListener("input", reweigh); });
  document.getElementById("best-stored").textContent = "the result's best trade-off (paper weights): member " + D.best;
}
function weights() { return D.objectives.map((o, i) => parseFloat(document.getElementById("w" + (i + 1)).value)); }
function reweigh() {
  const w = weights(); D.objectives.forEach((o, i) => document.getElementById("w" + (i + 1) + "-value").textContent = w[i].toFixed(2));
  if (!(w.reduce((a, b) => a + b, 0) > 0)) { document.getElementById("best-weighted").textContent = "(weights must not all be 0)"; return; }
  const b = bestTradeoff(w); state.weighted = b.index;
  document.getElementById("best-weighted").textContent = "member " + b.index + ", f_c = " + b.fc[b.index].toFixed(4);
  document.getElementById("best-weighted").dataset.member = b.index;
  Plotly.restyle("parcoords", {"line.color": [D.certified.map((c, k) => k === b.index ? 2 : (c ? 1 : 0))]});
  drawScatter();
}
// ---------------------------------------------------------------- 3-D view and joint motion
function robotAt(k, t) {  // (NP) points [x, y, z], interpolated on the member's coarse grid
  const c = D.view.counts[k], f = Math.min(t / D.view.dt, c - 1), i = Math.min(Math.floor(f), c - 2), a = f - i, out = [];
  for (let p = 0; p < NP; p++) { const o0 = ((OFFS[k] + i) * NP + p) * 3, o1 = o0 + NP * 3;
    out.push([0, 1, 2].map(d => PTS[o0 + d] * (1 - a) + PTS[o1 + d] * a)); }
  return out;
}
function obstacleAt(ob, t) {  // world vertices at scene time t
  const i = ob.moving ? Math.min(Math.round(t / D.scene_dt), ob.n_poses - 1) : 0, P = ob.P.subarray(i * 12, i * 12 + 12);
  const x = [], y = [], z = [];
  for (const v of ob.vertices) { x.push(P[0] * v[0] + P[1] * v[1] + P[2] * v[2] + P[3]);
    y.push(P[4] * v[0] + P[5] * v[1] + P[6] * v[2] + P[7]); z.push(P[8] * v[0] + P[9] * v[1] + P[10] * v[2] + P[11]); }
  return {x: x, y: y, z: z};
}
function toolPath(k) { const c = D.view.counts[k], x = [], y = [], z = [];
  for (let i = 0; i < c; i++) { const o = ((OFFS[k] + i) * NP + NP - 1) * 3; x.push(PTS[o]); y.push(PTS[o + 1]); z.push(PTS[o + 2]); }
  return {x: x, y: y, z: z}; }
function draw3d() {
  const k = state.member, r = robotAt(k, 0), path = toolPath(k), traces = [];
  traces.push({type: "scatter3d", mode: "lines+markers", name: "robot (joint origins, tool)", x: r.map(p => p[0]), y: r.map(p => p[1]),
    z: r.map(p => p[2]), line: {width: 10, color: "#ff7f0e"}, marker: {size: 4, color: "#333"}});
  traces.push({type: "scatter3d", mode: "lines", name: "tool path", ...path, line: {width: 5, color: "#2ca02c"}});
  traces.push({type: "scatter3d", mode: "markers", name: "start / goal", x: [path.x[0], path.x[path.x.length - 1]],
    y: [path.y[0], path.y[path.y.length - 1]], z: [path.z[0], path.z[path.z.length - 1]], marker: {size: 5, color: ["#1f77b4", "#9467bd"]}});
  D.obstacles.forEach((ob, i) => { const v = obstacleAt(ob, 0);
    traces.push({type: "mesh3d", name: ob.name + (ob.moving ? " (moving)" : ""), showlegend: true, ...v,
      i: ob.faces.map(f => f[0]), j: ob.faces.map(f => f[1]), k: ob.faces.map(f => f[2]), color: ob.color, opacity: ob.moving ? 1 : 0.6, flatshading: true}); });
  if (D.pivots.length) traces.push({type: "scatter3d", mode: "markers", name: "pendulum pivot", x: D.pivots.map(p => p.point[0]),
    y: D.pivots.map(p => p.point[1]), z: D.pivots.map(p => p.point[2]), text: D.pivots.map(p => p.name), marker: {size: 6, color: "#212f3c", symbol: "diamond"}});
  Plotly.react("view3d", traces, {margin: {l: 0, r: 0, t: 0, b: 0}, legend: {x: 0, y: 1},
    scene: {aspectmode: "data", camera: {eye: {x: 1.4, y: -1.4, z: 0.9}}}, uirevision: "keep"}, {displayModeBar: false});
  document.getElementById("shown-member").textContent = "shown: " + memberText(k) + (k === D.best ? ", the best trade-off" : "");
}
function update3d() {
  const k = state.member, t = state.t, r = robotAt(k, t), gd = document.getElementById("view3d");
  const moving = D.obstacles.map((ob, i) => [ob, i + 3]).filter(([ob]) => ob.moving);
  const xs = [r.map(p => p[0])], ys = [r.map(p => p[1])], zs = [r.map(p => p[2])], idx = [0];
  for (const [ob, i] of moving) { const v = obstacleAt(ob, t); xs.push(v.x); ys.push(v.y); zs.push(v.z); idx.push(i); }
  Plotly.restyle(gd, {x: xs, y: ys, z: zs}, idx);
  const T = X[k * NVAR]; document.getElementById("time").textContent = "t = " + t.toFixed(3) + " s of T = " + T.toFixed(3) + " s";
  document.getElementById("scrub").value = Math.round(1000 * t / T);
}
function drawJoints() {
  const k = state.member, T = X[k * NVAR], n = 201, times = [...Array(n).keys()].map(i => T * i / (n - 1));
  const s = sampleSpline(k, times, [0, 1, 2]), L = D.limits, traces = [];
  for (let j = 0; j < NQ; j++) {
    traces.push({x: times, y: s.q.map(q => (q[j] - L.lower[j]) / (L.upper[j] - L.lower[j])), name: D.joint_names[j] + " position", legendgroup: j, line: {color: "C" + j}});
    traces.push({x: times, y: s.qd.map(q => Math.abs(q[j]) / L.velocity[j]), name: D.joint_names[j] + " |velocity|", legendgroup: j, yaxis: "y2", showlegend: false});
    if (L.acceleration[j]) traces.push({x: times, y: s.qdd.map(q => Math.abs(q[j]) / L.acceleration[j]), name: D.joint_names[j] + " |acceleration|", legendgroup: j, yaxis: "y3", showlegend: false});
  }
  const colours = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2"];
  traces.forEach(tr => { tr.type = "scatter"; tr.mode = "lines"; tr.line = {color: colours[tr.legendgroup % 6]}; });
  const lim = (y0, y1, ax) => ({type: "line", xref: "x", yref: ax, x0: 0, x1: T, y0: y0, y1: y1, line: {dash: "dash", color: "red"}});
  Plotly.react("joints", traces, {title: {text: "joint motion of " + memberText(k) + " against the limits", font: {size: 13}},
    margin: {l: 60, r: 10, t: 40, b: 40}, showlegend: true, legend: {orientation: "h", y: -0.15},
    xaxis: {title: "t [s]"}, yaxis: {title: "position / range", domain: [0.68, 1]},
    yaxis2: {title: "|q̇| / VC", domain: [0.35, 0.63]}, yaxis3: {title: "|q̈| / WC", domain: [0, 0.3]},
    shapes: [lim(0, 0, "y"), lim(1, 1, "y"), lim(1, 1, "y2"), lim(1, 1, "y3")]}, {displayModeBar: false});
}
function showCertificate() {
  const k = state.member, c = D.certificates[k], el = document.getElementById("certificate");
  el.dataset.member = k;
  const fmt = (v, d) => v === null ? "-" : v.toFixed(d);
  let text = "Certificate of member " + k + (k === D.best ? " (the result's best trade-off)" : "") + "\n";
  text += "T = " + X[k * NVAR].toFixed(4) + " s; " + D.objectives.map((o, i) => o.name + " = " + D.F[k][i].toPrecision(5) + " " + o.unit).join(", ") + "\n";
  if (c === null) { el.textContent = text + "NOT CERTIFIED: no certificate stored for this member (adept-traj verify)"; return; }
  text += (c.feasible ? "CERTIFIED" : "NOT CERTIFIED") + "; distance guarantee: " + c.guarantee + (c.torque_guarantee ? "; torque: " + c.torque_guarantee : "") + "\n";
  text += "minimum distance " + (c.min_distance_exact ? "" : "≥ ") + fmt(c.min_distance, 4) + " m" + (c.t_min_distance === null ? "" : " at t = " + fmt(c.t_min_distance, 3) + " s") +
    (c.closest_pair ? " between " + c.closest_pair[0] + " and " + c.closest_pair[1] : "") + (c.distance_bound === null ? "" : "; bound at every instant ≥ " + fmt(c.distance_bound, 4) + " m") + "\n";
  text += "worst per limit (position: fraction of the range beyond the nearer limit, ≤ 0 inside; others: ratio to the limit, ≤ 1 within):\n";
  for (const [kind, w] of Object.entries(c.worst)) text += "  " + kind + ": " + fmt(w.value, 3) + " (" + w.joint + (w.t === null ? "" : ", t = " + fmt(w.t, 3) + " s") + ")\n";
  if (c.violations.length) text += "violations: " + c.violations.join("; ") + "\n";
  el.textContent = text;
}
function show(k) {
  if (!(k >= 0 && k < N)) return;
  state.member = k; state.t = 0; state.last = null;
  document.getElementById("member-input").value = k;
  draw3d(); drawJoints(); showCertificate(); drawScatter();
}
function tick(now) {
  if (state.playing) { if (state.last !== null) { const T = X[state.member * NVAR];
      state.t += (now - state.last) / 1000; if (state.t > T) state.t = 0; update3d(); }
    state.last = now; }
  setTimeout(() => requestAnimationFrame(tick), 50);
}
// ---------------------------------------------------------------- start
document.getElementById("title").textContent = "adept_traj front explorer: " + D.title;
document.getElementById("summary").textContent = D.certified.filter(Boolean).length + " of " + N + " members certified; red line / star: the best trade-off for the weights; grey: uncertified";
for (const id of ["scatter-x", "scatter-y"]) { const s = document.getElementById(id);
  AXES.forEach((a, i) => { const o = document.createElement("option"); o.value = i; o.textContent = a.label; s.appendChild(o); });
  s.addEventListener("change", drawScatter); }
document.getElementById("scatter-y").value = 6;
drawParcoords(); drawWeights(); reweigh(); show(D.best); brushed();
document.getElementById("scatter").on("plotly_click", ev => show(ev.points[0].customdata));
document.getElementById("member-show").addEventListener("click", () => show(parseInt(document.getElementById("member-input").value, 10)));
document.getElementById("play").addEventListener("click", () => { state.playing = !state.playing; state.last = null;
  document.getElementById("play").textContent = state.playing ? "pause" : "play"; });
document.getElementById("scrub").addEventListener("input", e => { state.playing = false; document.getElementById("play").textContent = "play";
  state.t = X[state.member * NVAR] * e.target.value / 1000; update3d(); });
for (const f of ["csv", "ros-json", "ros-yaml"]) document.getElementById("download-" + f).addEventListener("click", () => download(f));
requestAnimationFrame(tick);
window.explorerReady = true;
</script></body></html>
"""
