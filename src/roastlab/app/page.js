// roastlab's page: fetch JSON from the local server, draw with Plotly (served from its own wheel).
"use strict";

const sid = sessionStorage.getItem("roastlab-session") || crypto.randomUUID();
sessionStorage.setItem("roastlab-session", sid);
const $ = (id) => document.getElementById(id);
const state = { open: null, changed: null, changedBand: null, table: null, busy: false, pending: false, lastDrawMs: null, tInput: null,
                program: {}, touchStep: null, transfer: null, opening: 0 };  // program: setting -> [{from_s, until_s, value, logged}], the steps the roaster can drag
// opening: the number of the latest Open; an earlier one's answer that arrives after it is dropped

async function api(path, body) {
  const opts = { method: body === undefined ? "GET" : "POST", headers: { "X-Session": sid } };
  if (body !== undefined) {
    opts.headers["Content-Type"] = "application/json";
    opts.body = JSON.stringify(body);
  }
  const r = await fetch(path, opts);
  const data = await r.json();
  if (!r.ok || data.error) throw new Error(data.error || `HTTP ${r.status}`);
  return data;
}

function say(text) { $("message").textContent = text || ""; }
const F = () => $("units").value === "F";
// A degC value in the page's unit and back: a level (a temperature) converts with Fahrenheit's offset,
// a difference or a rate (RoR, an offset) without.
const shown = (c, kind, f = F()) => (!f ? c : kind === "level" ? c * 9 / 5 + 32 : c * 9 / 5);
const celsius = (v, kind, f = F()) => (!f ? v : kind === "level" ? (v - 32) * 5 / 9 : v * 5 / 9);
const temp = (v) => (v === null || v === undefined ? null : shown(v, "level"));
const dtemp = (v) => (v === null || v === undefined ? null : shown(v, "delta"));
const unit = (f = F()) => (f ? "°F" : "°C");
// The what-if's temperature fields show the page's unit; the server is asked in degC.
const TEMP_FIELDS = { Tm0_C: "level", Tm0_C_range: "level", Tb0_C: "level", tgi: "delta" };
const round1 = (v) => Math.round(v * 10) / 10;
function fieldC(id) {  // a temperature field's value in degC, or "" when empty
  const v = $(id).value.trim();
  return v === "" ? "" : celsius(Number(v), TEMP_FIELDS[id]);
}
function setFieldC(id, c) { $(id).value = c === null || c === undefined || c === "" ? "" : round1(shown(c, TEMP_FIELDS[id])); }
function unitLabels() { for (const e of document.querySelectorAll(".tunit")) e.textContent = unit(); }
const narrow = () => $("plot").clientWidth < 900;  // the figure's legend wraps into more rows
const phone = () => $("plot").clientWidth < 600;
// A touch screen's finger (a tablet, a phone): a swipe over a figure scrolls the page, as everywhere
// else on it, rather than zooming the curves (Plotly's default drag, which there trapped the page:
// the curves fill most of the screen). The modebar's zoom and pan buttons still turn dragging on.
const fingerDrag = () => (window.matchMedia("(pointer: coarse)").matches ? false : "zoom");
function mmss(s) {
  if (s === null || s === undefined || !isFinite(s)) return "-";
  const n = Math.round(Math.abs(s));
  return `${s < 0 ? "-" : ""}${Math.floor(n / 60)}:${String(n % 60).padStart(2, "0")}`;
}
const minutes = (ts) => ts.map((t) => t / 60);
// The figures' left and right margins (their axes' titles and ticks), and the pixels a minute of a
// figure's time axis takes: its box less those margins.
const SIDE_PX = 60;
const pxPerMinute = (id, x) => Math.max(1, $(id).clientWidth - 2 * SIDE_PX) / Math.max(1e-9, Math.max(...x) - Math.min(0, ...x));
function mmssTicks(x, pxMin) {  // the roaster's time axis written m:ss: a tick a minute, or every 2 or 5 on a phone
  const last = Math.ceil(Math.max(...x));
  const every = [1, 2, 5, 10].find((k) => k * pxMin >= 40) || 10;  // "10:00" takes about 35 px
  const vals = Array.from({ length: Math.floor(last / every) + 1 }, (_, i) => i * every);
  return { tickvals: vals, ticktext: vals.map((m) => `${m}:00`) };
}

const PHASE_COLORS = { drying: "rgba(255, 214, 102, 0.18)", Maillard: "rgba(214, 140, 69, 0.16)", development: "rgba(140, 80, 40, 0.16)" };

// Artisan's phase bands: drying, Maillard, development (from the log's marks), each named with its
// length where its band is wide enough for the words (about 6 px a letter at 10 px), else its length
// alone, else nothing: on a phone the names ran into each other.
function phaseShapes(phases, pxMin) {
  const shapes = [], notes = [];
  for (const p of phases || []) {
    shapes.push({ type: "rect", xref: "x", yref: "paper", x0: p.from_s / 60, x1: p.to_s / 60, y0: 0.42, y1: 1,
                  fillcolor: PHASE_COLORS[p.name] || "rgba(0,0,0,0.05)", line: { width: 0 }, layer: "below" });
    const width = (p.to_s - p.from_s) / 60 * pxMin, length = mmss(p.to_s - p.from_s);
    const text = [`${p.name} ${length}`, length].find((words) => 6 * words.length + 6 <= width);
    if (text) notes.push({ xref: "x", yref: "paper", x: (p.from_s + p.to_s) / 120, y: 0.43, text,
                           showarrow: false, font: { size: 10, color: "#7a5a3a" } });
  }
  return { shapes, notes };
}

// The program the roaster can drag: each held setting as steps (segments between changes), drawn as
// thick editable lines on the settings axis; a dragged step is snapped to the machine's levels.
function stepsOf(t, values) {
  const out = [];
  if (!values) return out;
  let start = 0;
  for (let i = 1; i <= values.length; i++) {
    if (i === values.length || values[i] !== values[start]) {
      const until = i < values.length ? t[i] : t[t.length - 1] + 1;
      out.push({ from_s: t[start], until_s: until, value: values[start], logged: values[start], logged_from: t[start] });
      start = i;
    }
  }
  return out.length > 60 ? [] : out;  // a setting logged as a continuous curve is not a program to drag
}

const STEP_COLORS = { heater: "#d62728", fan: "#2ca02c" };
// Heater and fan in different units (a burner in kPa, the fan in %) each get their own scale: the fan's
// on the right of the settings panel (yaxis4), where on one scale a kPa lay flat along 0-100 %.
function twoScales() {
  const a = (state.open && state.open.actuators) || {};
  return Boolean(a.heater && a.fan && a.heater.unit !== a.fan.unit);
}
const settingAxis = (name) => (name === "fan" && twoScales() ? "y4" : "y3");
function programShapes() {
  const shapes = [];
  for (const [name, steps] of Object.entries(state.program)) {
    steps.forEach((st, k) => shapes.push({ type: "line", xref: "x", yref: settingAxis(name), x0: st.from_s / 60, x1: st.until_s / 60,
      y0: st.value, y1: st.value, editable: true, name: `${name}:${k}`,
      line: { color: STEP_COLORS[name], width: st.value !== st.logged ? 7 : 5 }, opacity: st.value !== st.logged ? 0.9 : 0.45 }));
  }
  return shapes;
}

function snap(name, v) {
  const a = (state.open.actuators || {})[name];
  if (!a) return v;
  v = Math.min(a.high, Math.max(a.low, v));
  return a.step ? a.low + Math.round((v - a.low) / a.step) * a.step : Math.round(v * 10) / 10;
}

// A step moved along time starts at ``minutes`` (on a 5-s grid, not before CHARGE) and keeps its length.
function startAt(st, minutes) {
  const len = st.until_s - st.from_s;
  st.from_s = Math.max(0, Math.round(minutes * 60 / 5) * 5);
  st.until_s = st.from_s + len;
}

function onRelayout(ev) {  // a program step was dragged: its new level (and start, if moved along time)
  const moved = {};
  for (const [key, v] of Object.entries(ev || {})) {
    const m = key.match(/^shapes\[(\d+)\]\.(x0|x1|y0|y1)$/);
    if (m) (moved[m[1]] = moved[m[1]] || {})[m[2]] = v;
  }
  const shapes = ($("plot").layout || {}).shapes || [];
  let changed = false;
  for (const [i, m] of Object.entries(moved)) {
    const sh = shapes[Number(i)];
    if (!sh || !sh.name || !sh.editable) continue;
    const [name, k] = sh.name.split(":");
    const st = state.program[name][Number(k)];
    const y = m.y0 !== undefined && m.y1 !== undefined ? (m.y0 + m.y1) / 2 : (m.y0 ?? m.y1);
    if (y !== undefined) st.value = snap(name, y);
    if (m.x0 !== undefined && m.x1 !== undefined) startAt(st, m.x0);  // moved along time
    changed = true;
  }
  if (changed) { state.tInput = performance.now(); whatif(); }
}

// A finger on a tablet: Plotly drags an editable shape only from the 5-7 px line itself, which a
// fingertip misses (4 px off already did). A touch within FINGER_PX of a step takes it instead, and
// the page does not scroll meanwhile; a touch anywhere else scrolls and pans as before. The finger's
// first LOCK_PX of travel says which way it moves the step, as the mouse does either: up and down
// its level (snapped to the machine's steps), sideways its start (and end) along time. The prediction
// follows as it moves.
const FINGER_PX = 24, LOCK_PX = 8;
function stepNear(touch) {
  const gd = $("plot"), fl = gd._fullLayout;
  if (!state.open || !fl || !fl.xaxis) return null;
  const r = gd.getBoundingClientRect(), xa = fl.xaxis, px = touch.clientX - r.left - xa._offset;
  let best = null;
  for (const [name, steps] of Object.entries(state.program)) {
    const axis = "yaxis" + settingAxis(name).slice(1), ya = fl[axis];
    if (!ya) continue;
    const py = touch.clientY - r.top - ya._offset;
    steps.forEach((st, k) => {
      const inside = px >= xa.l2p(st.from_s / 60) - 4 && px <= xa.l2p(st.until_s / 60) + 4;
      const d = Math.abs(py - ya.l2p(st.value));
      if (inside && d <= FINGER_PX && (!best || d < best.d)) {
        best = { name, k, axis, d, x0: touch.clientX, y0: touch.clientY, level: st.value, start: st.from_s / 60, way: null };
      }
    });
  }
  return best;
}
function onStepTouch(ev) {
  if (ev.type === "touchstart") state.touchStep = ev.touches.length === 1 ? stepNear(ev.touches[0]) : null;
  const hit = state.touchStep;
  if (!hit) return;  // not on a step: the page's and Plotly's own handling
  ev.preventDefault();  // no scroll, no pan, no emulated click
  ev.stopPropagation();
  if (ev.type === "touchend" || ev.type === "touchcancel") { state.touchStep = null; return; }
  if (ev.type !== "touchmove") return;
  const fl = $("plot")._fullLayout, st = state.program[hit.name][hit.k], touch = ev.touches[0];
  const dx = touch.clientX - hit.x0, dy = touch.clientY - hit.y0;
  if (!hit.way) {
    if (Math.hypot(dx, dy) < LOCK_PX) return;
    hit.way = Math.abs(dx) > Math.abs(dy) ? "time" : "level";
  }
  const was = [st.value, st.from_s];
  if (hit.way === "level") {  // by as much as the finger moved, on the step's own scale
    st.value = snap(hit.name, hit.level + fl[hit.axis].p2l(touch.clientY) - fl[hit.axis].p2l(hit.y0));
  } else {
    startAt(st, hit.start + fl.xaxis.p2l(touch.clientX) - fl.xaxis.p2l(hit.x0));
  }
  if (st.value !== was[0] || st.from_s !== was[1]) {
    if (state.tInput === null) state.tInput = performance.now();
    whatif();
  }
}

function programBody() {  // the dragged steps as "set" changes (applied in order, as the what-if does)
  const out = [];
  for (const [name, steps] of Object.entries(state.program)) {
    for (const st of steps) {
      if (st.value !== st.logged || st.from_s !== st.logged_from) out.push({ setting: name, value: st.value, from_s: st.from_s, until_s: st.until_s });
    }
  }
  return out;
}

// The log's marks (CHARGE, DRY, FCs, DROP) as dotted lines, named in time order in three staggered
// rows a line of 10-px text apart: in pixels, as a share of the figure's height they ran into each
// other on a phone, where the legend takes half of it.
function eventShapes(events) {
  const shapes = [], notes = [];
  const marks = Object.entries(events || {}).sort((a, b) => a[1] - b[1]);
  marks.forEach(([name, t], i) => {
    shapes.push({ type: "line", xref: "x", yref: "paper", x0: t / 60, x1: t / 60, y0: 0.42, y1: 1,
                  line: { color: "#999", width: 1, dash: "dot" } });
    notes.push({ xref: "x", yref: "paper", x: t / 60, y: 1, yanchor: "top", yshift: -13 * (i % 3), text: `${name} ${mmss(t)}`,
                 showarrow: false, xanchor: "left", font: { size: 10, color: "#555" } });
  });
  return { shapes, notes };
}

function draw() {
  const o = state.open;
  if (!o) return;
  const c = o.curves, ch = state.changed || o.curves;
  const x = minutes(c.time_s);
  const xc = minutes(ch.time_s || c.time_s);  // the changed roast's own times: it may drop elsewhere
  const xAll = xc.length && xc[xc.length - 1] > x[x.length - 1] ? xc : x;  // the axis spans the longer
  const T = (a) => (a ? a.map(temp) : null);
  const traces = [];
  if (c.BT_measured) traces.push({ x, y: T(c.BT_measured), name: "BT measured", mode: "markers", marker: { size: 3, color: "#333" } });
  if (c.beans_measured) {  // a curve of readings, or the first-crack mark read as the beans (the server names it)
    const few = c.beans_measured_few;
    traces.push({ x, y: T(c.beans_measured), name: F() ? c.beans_measured_label_F : c.beans_measured_label, mode: "markers",
      marker: few ? { size: 9, symbol: "diamond-open", color: "#a0785a", line: { width: 2 } } : { size: 2, color: "#a0785a" } });
  }
  if (c.ET_measured) traces.push({ x, y: T(c.ET_measured), name: "ET measured", mode: "markers", marker: { size: 2, color: "#9467bd" } });
  const b = o.band || {};
  if (b.lower) {  // the as-run band: parameters and roast-to-roast spread (roastlab.evaluate.bands)
    traces.push({ x, y: T(b.lower), name: "band", line: { width: 0 }, hoverinfo: "skip", showlegend: false });
    traces.push({ x, y: T(b.upper), name: `${Math.round(b.level * 100)} % band, as run`, fill: "tonexty",
                  fillcolor: "rgba(31, 119, 180, 0.15)", line: { width: 0 }, hoverinfo: "skip" });
  }
  const cb = state.changed && state.changedBand;
  if (cb && cb.lower) {  // the changed curve's band, asked for once a change has settled (bandSoon)
    traces.push({ x: xc, y: T(cb.lower), name: "band changed", line: { width: 0 }, hoverinfo: "skip", showlegend: false });
    traces.push({ x: xc, y: T(cb.upper), name: `${Math.round(cb.level * 100)} % band, changed`, fill: "tonexty",
                  fillcolor: "rgba(255, 127, 14, 0.15)", line: { width: 0 }, hoverinfo: "skip" });
  }
  traces.push({ x, y: T(c.BT_model), name: "BT model, as run", line: { color: "#1f77b4", width: 2 } });
  traces.push({ x: xc, y: T(ch.BT_model), name: "BT model, changed", line: { color: "#ff7f0e", width: 2 }, uid: "bt-changed" });
  traces.push({ x, y: T(c.beans_model), name: "beans model, as run", line: { color: "#1f77b4", width: 1, dash: "dash" } });
  traces.push({ x: xc, y: T(ch.beans_model), name: "beans model, changed", line: { color: "#ff7f0e", width: 1, dash: "dash" } });
  traces.push({ x: xc, y: T(ch.ET_model), name: `ET model: ${o.ET_model_is}, changed`, line: { color: "#9467bd", width: 1 } });
  if (c.RoR_measured) traces.push({ x, y: c.RoR_measured.map(dtemp), name: "RoR measured", yaxis: "y2", line: { color: "#555", width: 1 } });
  traces.push({ x: xc, y: ch.RoR_model.map(dtemp), name: "RoR model, changed", yaxis: "y2", line: { color: "#ff7f0e", width: 1 } });
  if (ch.heater) traces.push({ x: xc, y: ch.heater, name: `heater [${unitName("heater")}]`, yaxis: "y3", line: { shape: "hv", color: "#d62728" } });
  if (ch.fan) traces.push({ x: xc, y: ch.fan, name: `fan [${unitName("fan")}]`, yaxis: settingAxis("fan"), line: { shape: "hv", color: "#2ca02c" } });
  const pxMin = pxPerMinute("plot", xAll);
  const dropS = state.changed && state.table && state.table.drop_s;  // the changed roast's own DROP
  const marks = dropS == null ? o.events : Object.fromEntries(
    Object.entries(o.events || {}).filter(([, t]) => t <= c.time_s[c.time_s.length - 1] + 5).concat([["DROP changed", dropS]]));
  const ev = eventShapes(marks), ph = phaseShapes(o.phases, pxMin);
  const rorAfter = (ch.RoR_model || []).filter((v, i) => v !== null && (ch.time_s || c.time_s)[i] > 90).map(dtemp);
  const rorTop = rorAfter.length ? Math.max(...rorAfter) * 1.2 + 2 : 30;
  const t0 = performance.now();
  Plotly.react("plot", traces, {
    // a narrow screen (a tablet beside the roaster) wraps the legend into more rows: below the time axis's title
    margin: { t: 30, r: SIDE_PX, l: SIDE_PX, b: 40 }, legend: { orientation: "h", y: narrow() ? -0.2 : -0.12, font: { size: 10 } },
    xaxis: { title: { text: "time after CHARGE [m:ss]" }, domain: [0, 1], anchor: "y3", ...mmssTicks(xAll, pxMin) },
    yaxis: { title: { text: `temperature [${unit()}]` }, domain: [0.42, 1] },
    yaxis2: { title: { text: `RoR [${unit()}/min]` }, overlaying: "y", side: "right", range: [dtemp(-2), rorTop], showgrid: false,
              tickmode: "auto", nticks: 6, tickformat: ".0f" },
    // "(drag a step)" on a phone would run past its short axis into the temperature's title
    yaxis3: { title: { text: (twoScales() ? `heater [${unitName("heater")}]` : "setting") + (phone() ? "" : " (drag a step)") },
              domain: [0, 0.32] },
    ...(twoScales() ? { yaxis4: { title: { text: `fan [${unitName("fan")}]`, font: { color: STEP_COLORS.fan } },
                                  overlaying: "y3", side: "right", showgrid: false, tickmode: "auto", nticks: 5 } } : {}),
    shapes: [...ph.shapes, ...ev.shapes, ...programShapes()], annotations: [...ph.notes, ...ev.notes], uirevision: "keep",
    dragmode: fingerDrag(),
  }, { displaylogo: false, responsive: true }).then(() => {
    if (!state.hooked) { $("plot").on("plotly_relayout", onRelayout); state.hooked = true; }
    state.lastDrawMs = performance.now() - t0;
    if (state.tInput !== null) {  // from the input change to this curve on screen
      document.body.dataset.latency = String(performance.now() - state.tInput);
      state.tInput = null;
    }
  });
}

// A setting's unit as the page shows it (a level shown in tens, as Artisan's Aillio setup logs it: "steps ×10").
const shownUnit = (u) => ({ level: "steps", tens: "steps ×10", percent: "%", reading: "as logged" }[u] || u);
function unitName(name) {
  const a = (state.open && state.open.actuators || {})[name];
  return a ? shownUnit(a.unit) : "as logged";
}

function drawTable() {
  const t = state.table;
  if (!t) return;
  // auc: an area of temperature differences (degC min), whole degree-minutes as Artisan shows it
  const kinds = { time: (v) => mmss(v), temp: (v) => (v === null ? "-" : temp(v).toFixed(1)), pct: (v) => (v === null ? "-" : v.toFixed(1)),
    auc: (v) => (v === null ? "-" : dtemp(v).toFixed(0)) };
  const delta = { time: (d) => (d < 0 ? "-" : "+") + mmss(Math.abs(d)), temp: (d) => (dtemp(d) >= 0 ? "+" : "") + dtemp(d).toFixed(1), pct: (d) => (d >= 0 ? "+" : "") + d.toFixed(1),
    auc: (d) => (dtemp(d) >= 0 ? "+" : "") + dtemp(d).toFixed(0) };
  const unitOf = { time: "m:ss", temp: unit(), pct: "%", auc: `${unit()}·min` };
  let html = "<tr><th></th><th>measured</th><th>as run</th><th>changed</th><th>change</th><th>model error</th></tr>";
  let group = null;
  for (const r of t.rows) {
    if (r.reading !== group) {
      group = r.reading;
      html += `<tr class="group"><td colspan="6">${group === "beans" ? "beans (judged; model bean temperature)" : "probe BT (what the roaster sees)"}</td></tr>`;
    }
    const f = kinds[r.kind], d = delta[r.kind];
    const ch = r.as_run !== null && r.changed !== null ? d(r.changed - r.as_run) : "-";
    const er = r.as_run !== null && r.measured !== null ? d(r.as_run - r.measured) : "-";
    html += `<tr data-key="${r.reading}-${r.key}"><td>${r.what} [${unitOf[r.kind]}]</td><td>${f(r.measured)}</td>` +
            `<td>${f(r.as_run)}</td><td class="changed">${f(r.changed)}</td><td>${ch}</td><td>${er}</td></tr>`;
  }
  $("table").innerHTML = html;
  const m = state.open && state.open.metrics, b = state.open && state.open.band;
  // named: after a fit the model list selects the new model, which the open log shows only once opened again
  const which = state.open ? `${state.open.model} ` : "";
  $("figures").textContent = (m ? `model ${which}as run against this log${m.fitted_on ? " (it was fitted on this roast: not held out)" : ""}: FIT ${m.FIT_pct.toFixed(1)} %, MAE ${dtemp(m.MAE_C).toFixed(2)} ${unit()}` : "") +
    (b && b.lower ? `; ${Math.round(b.level * 100)} % band median width ${dtemp(b.median_width_C).toFixed(1)} ${unit()}` : b && b.why ? `; ${b.why}` : "") +
    (state.changed && state.changedBand ? `; changed: ${dtemp(state.changedBand.median_width_C).toFixed(1)} ${unit()}` : "");
  const bandNotes = [b && b.note, state.changed && state.changedBand && state.changedBand.note];
  const notes = (t.warnings_by_unit || {})[$("units").value] || t.warnings || [];  // in the table's unit
  $("warnings").textContent = [...notes, ...new Set(bandNotes.filter(Boolean))].map((w) => "note: " + w).join("\n");
}

function changes() {
  const v = (id) => $(id).value.trim();
  const body = { heater: v("heater"), fan: v("fan"), tgi: v("tgi") === "" ? "" : String(fieldC("tgi")) };
  // DROP elsewhere: a clock (9:30) or a shift (+0:20, -15) is a time, a plain number the BT to drop at
  if (v("drop") !== "") {
    if (/[:+-]/.test(v("drop"))) body.drop_at = v("drop");
    else body.drop_bt = celsius(Number(v("drop")), "level", F());
  }
  const o = state.open;
  // a field shown in degF and read back differs from the log's degC value by its rounding to 0.1 degF
  const moved = (c, was) => c !== "" && Math.abs(c - was) > (F() ? 0.05 : 1e-9);
  if (o && moved(fieldC("Tm0_C"), o.Tm0_C)) body.Tm0_C = fieldC("Tm0_C");
  if (o && v("batch_kg") !== "" && Number(v("batch_kg")) !== o.batch_kg) body.batch_kg = Number(v("batch_kg"));
  if (v("X0") !== "" && o && Number(v("X0")) !== o.X0) body.X0 = Number(v("X0"));
  if (o && moved(fieldC("Tb0_C"), o.Tb0_C)) body.Tb0_C = fieldC("Tb0_C");
  const program = programBody();
  if (program.length) body.program = program;
  return body;
}

// The changed curve's prediction band costs a sensitivity run of the simulation again (a few ms
// on the server): asked for once the changes have stood still for BAND_WAIT_MS, not on every drag step.
const BAND_WAIT_MS = 300;
let bandTimer = null;
function bandSoon(body) {
  clearTimeout(bandTimer);
  if (!state.open || !state.open.band || !state.open.band.lower) return;  // the model carries no band
  const key = JSON.stringify(body);
  bandTimer = setTimeout(async () => {
    try {
      const r = await api("/api/whatif", { ...body, band: true });
      if (JSON.stringify(changes()) !== key) return;  // the roaster moved on meanwhile
      state.changedBand = r.band;
      draw();
      drawTable();
      document.body.dataset.bands = String(Number(document.body.dataset.bands || 0) + 1);
    } catch (e) {
      say(e.message);
    }
  }, BAND_WAIT_MS);
}

async function whatif() {
  if (!state.open) return;
  if (state.busy) { state.pending = true; return; }
  state.busy = true;
  try {
    const t0 = performance.now();
    const body = changes();
    const r = await api("/api/whatif", body);
    $("whatif_downloads").innerHTML = "";  // a background written before these changes is not this roast's
    state.changed = r.curves;
    state.changedBand = null;
    state.table = r.table;
    bandSoon(body);
    draw();
    drawTable();
    say("");
    $("timing").textContent = `server ${r.server_ms} ms, round trip ${(performance.now() - t0).toFixed(0)} ms`;
    document.body.dataset.updates = String(Number(document.body.dataset.updates || 0) + 1);
  } catch (e) {
    say(e.message);
  } finally {
    state.busy = false;
    if (state.pending) { state.pending = false; whatif(); }
  }
}

async function whatifBackground() {
  try {
    const r = await api("/api/whatif-background", changes());
    $("whatif_downloads").innerHTML = [r.download, r.alarms].filter(Boolean)
      .map((u) => `<a href="${u}" download>${u.split("/").pop()}</a>`).join("<br>");
    say("");
    document.body.dataset.background = "done";
  } catch (e) {
    say(e.message);
  }
}

// The fit report (fit-roaster's report.md), rendered by the server with raw HTML in it escaped.
function showReport(html) {
  if (html) $("fit-report").innerHTML = html;
  else $("fit-report").textContent = "(no fit report beside this model: fit-roaster writes model.json with its report.md in one folder; fit a model on your logs here, or with roastlab init + fit-roaster)";
}

// A folder with logs and no model yet: what to do first (the fit writes one, then opens the log with it).
const NO_MODEL = "no model in this folder yet: choose logs of one roaster under \"Fit a model\" (left) and fit one; " +
  "then Open shows a log with it";

// The what-if's temperature fields and their ranges from degC values, in the page's unit.
function setTempFields(valuesC) {
  for (const k of ["Tm0_C", "Tb0_C"]) {  // the ranges first: a slider clamps a value to the range it has
    const r = (state.ranges || {})[k];
    if (r) for (const id of [k, `${k}_range`]) if ($(id)) { $(id).min = round1(shown(r[0], "level")); $(id).max = round1(shown(r[1], "level")); }
  }
  for (const [id, c] of Object.entries(valuesC)) setFieldC(id, c);
}

async function openLog() {
  if (!$("model").value) { say(NO_MODEL); return; }
  say("opening ...");
  $("whatif_downloads").innerHTML = "";
  const ticket = ++state.opening;  // the last Open wins (the page's own first Open may still be on its way)
  try {
    const r = await api("/api/open", { log: $("log").value, model: $("model").value });
    if (ticket !== state.opening) return;
    state.open = r;
    state.changed = null;
    state.program = {};
    for (const name of Object.keys(r.actuators || {})) {
      const steps = stepsOf(r.curves.time_s, r.curves[name]);
      if (steps.length) state.program[name] = steps;
    }
    state.table = r.table;
    if (!state.unitsChosen && r.temp_unit) { $("units").value = r.temp_unit; unitLabels(); }  // the log's own unit
    state.ranges = r.ranges || {};
    setTempFields({ Tm0_C: r.Tm0_C, Tm0_C_range: r.Tm0_C ?? 200, Tb0_C: r.Tb0_C, tgi: 0 });
    $("X0").value = r.X0 ?? "";
    if (state.ranges.X0) { $("X0").min = state.ranges.X0[0]; $("X0").max = state.ranges.X0[1]; }
    const lim = r.transfer_limits;
    $("tr_limits_label").textContent = `${lim.decide} lowest / highest [${shownUnit(lim.unit)}]`;
    $("tr_low").placeholder = lim.low; $("tr_high").placeholder = lim.high;
    $("tr_low").value = ""; $("tr_high").value = "";
    $("batch_kg").value = r.batch_kg ?? "";
    $("batch_kg_range").min = (r.batch_kg || 1) * 0.5;
    $("batch_kg_range").max = (r.batch_kg || 1) * 1.6;
    $("batch_kg_range").value = r.batch_kg || 1;
    $("tr_batch_kg").value = r.batch_kg ?? "";
    for (const id of ["heater", "fan", "drop"]) $(id).value = "";
    $("notes").textContent = (r.notes || []).join("\n");
    showReport(r.report_html);
    draw();
    drawTable();
    say("");
    document.body.dataset.opened = r.log;
  } catch (e) {
    if (ticket === state.opening) say(e.message);
  }
}

async function refreshFiles(selectLog) {
  const f = await api("/api/files");
  const fill = (id, items, pick) => {
    $(id).innerHTML = items.map((p) => `<option value="${p}">${p}</option>`).join("");
    if (pick) $(id).value = pick;
  };
  fill("log", f.logs, selectLog);
  fill("model", f.models, pickModel);
  fill("fit_logs", f.logs);
  $("tr_target").innerHTML = `<option value="">(this log)</option>` +
    f.logs.map((p) => `<option value="${p}">${p}</option>`).join("");
}
let pickModel = null;

async function runFit() {
  const logs = Array.from($("fit_logs").selectedOptions).map((o) => o.value);
  say("");
  try {
    await api("/api/fit", {
      logs, name: $("fit_name").value, every_log: $("fit_every_log").checked, by_size: $("fit_by_size").checked,
      units: $("units").value,  // the report in the page's unit
    });
    const poll = async () => {
      const st = await api("/api/fit-status");
      $("fit_progress").max = st.total || 1;
      $("fit_progress").value = st.done || 0;
      $("fit_text").textContent = st.text || "";
      if (st.running) { setTimeout(poll, 300); return; }
      if (st.error) { say(st.error); return; }
      showReport(st.report_html);
      $("fit_text").textContent = `held out: FIT ${st.held_out.FIT.toFixed(1)} %, MAE ${dtemp(st.held_out.MAE).toFixed(2)} ${unit()}` +
        (st.every_log ? `; each log held out once: FIT ${st.every_log.FIT.toFixed(1)} %` : "") +
        (st.across_sizes ? `; across sizes: ${st.across_sizes}` : "");
      if (st.verdict) say(`not usable: ${st.verdict}`);
      pickModel = st.model;
      $("fit_text").textContent += ` — ${st.model} is selected under "model": Open shows it on a log`;
      await refreshFiles($("log").value);
      document.body.dataset.fitted = st.model;
    };
    poll();
  } catch (e) {
    say(e.message);
  }
}

async function upload(ev) {
  const file = ev.target.files[0];
  if (!file) return;
  say("uploading ...");
  try {
    const q = new URLSearchParams({ name: file.name, model: $("model").value });
    const r = await fetch(`/api/upload?${q}`, { method: "POST", headers: { "X-Session": sid }, body: file });
    const data = await r.json();
    if (!r.ok || data.error) throw new Error(data.error || `HTTP ${r.status}`);
    await refreshFiles(data.path);
    await openLog();
  } catch (e) {
    say(e.message);
  }
}

function drawTransfer() {
  const r = state.transfer;
  if (!r) return;
  const x = minutes(r.time_s), T = (a) => a.map((v) => shown(v, "level", r.F));
  const band = r.band ? [  // where a roast run with the program is expected (transfer --band)
    { x, y: T(r.band.upper), line: { width: 0 }, showlegend: false, hoverinfo: "skip" },
    { x, y: T(r.band.lower), fill: "tonexty", fillcolor: "rgba(31,119,180,0.15)", line: { width: 0 },
      name: `${Math.round(r.band.level * 100)} % band of the predicted BT` },
  ] : [];
  $("transfer-plot").classList.add("drawn");  // shown before drawing: Plotly sizes the figure to its box
  Plotly.react("transfer-plot", [
    ...band,
    { x, y: T(r.target), name: "target BT", line: { color: "#333", width: 2 } },
    { x, y: T(r.predicted), name: "predicted BT with the program", line: { color: "#1f77b4" } },
    { x, y: r.program, name: `program: ${r.decide} [${shownUnit(r.unit)}]`, yaxis: "y2", line: { shape: "hv", color: "#d62728" } },
  ], {
    margin: { t: 20, r: SIDE_PX, l: SIDE_PX, b: 40 }, legend: { orientation: "h", y: narrow() ? -0.3 : -0.2 }, dragmode: fingerDrag(),
    xaxis: { title: { text: "time after CHARGE [m:ss]" }, ...mmssTicks(x, pxPerMinute("transfer-plot", x)) },
    yaxis: { title: { text: `BT [${unit(r.F)}]` } },
    yaxis2: { title: { text: `${r.decide} [${shownUnit(r.unit)}]` }, overlaying: "y", side: "right", showgrid: false,
              range: [r.low - (r.step || (r.high - r.low) / 20), r.high + (r.step || (r.high - r.low) / 20)],
              // on the machine's steps, a tick every step or every few (at most about ten ticks)
              ...(r.step ? { dtick: r.step * Math.max(1, Math.ceil((r.high - r.low) / r.step / 10)), tickformat: "d" } : {}) },
  }, { displaylogo: false, responsive: true });
}

async function runTransfer() {
  say("");
  $("transfer_progress").hidden = false;
  $("transfer_progress").removeAttribute("value");  // indeterminate: the solve reports no steps
  $("transfer-summary").textContent = "running the transfer ...";
  try {
    const r = await api("/api/transfer", { batch_kg: $("tr_batch_kg").value, plant_to: $("tr_plant").value.trim(), tm0_free: $("tr_tm0_free").checked, limit_low: $("tr_low").value, limit_high: $("tr_high").value, target: $("tr_target").value, units: $("units").value });
    $("transfer-summary").textContent = r.summary;
    $("downloads").innerHTML = r.downloads.map((u) => `<a href="${u}" download>${u.split("/").pop()}</a>`).join("");
    state.transfer = { ...r, F: F() };  // drawn again when the window changes, in the unit its summary speaks
    drawTransfer();
    say("");
    document.body.dataset.transfer = "done";
  } catch (e) {
    $("transfer-summary").textContent = "(the transfer failed: see the message above)";
    say(e.message);
  } finally {
    $("transfer_progress").hidden = true;
  }
}

function link(numberId, rangeId) {
  const go = () => { if (state.tInput === null) state.tInput = performance.now(); whatif(); };
  $(rangeId).addEventListener("input", () => { $(numberId).value = $(rangeId).value; go(); });
  $(numberId).addEventListener("input", () => { $(rangeId).value = $(numberId).value; go(); });
}

// A window resized or a tablet turned: Plotly's responsive figures take the new width; what the page
// chose for the old one (the time axis's ticks, the phases' names, the legend's place) is chosen again.
let resizeTimer = null;
window.addEventListener("resize", () => {
  clearTimeout(resizeTimer);
  resizeTimer = setTimeout(() => { draw(); drawTransfer(); }, 150);
});

window.addEventListener("DOMContentLoaded", async () => {
  $("open").addEventListener("click", openLog);
  $("upload").addEventListener("change", upload);
  $("units").addEventListener("change", () => {  // the fields keep what they hold, in the new unit
    state.unitsChosen = true;
    const was = $("units").value === "F" ? "C" : "F";
    const held = Object.fromEntries(Object.entries(TEMP_FIELDS).map(([id, kind]) => {
      const v = $(id).value.trim();
      return [id, v === "" ? "" : celsius(Number(v), kind, was === "F")];
    }));
    setTempFields(held);
    unitLabels();
    draw(); drawTable();
  });
  $("reset").addEventListener("click", openLog);
  $("run-transfer").addEventListener("click", runTransfer);
  $("whatif-background").addEventListener("click", whatifBackground);
  $("run-fit").addEventListener("click", runFit);
  for (const kind of ["touchstart", "touchmove", "touchend", "touchcancel"]) {  // before Plotly's own handlers
    $("plot").addEventListener(kind, onStepTouch, { capture: true, passive: false });
  }
  link("Tm0_C", "Tm0_C_range");
  link("batch_kg", "batch_kg_range");
  const changed = () => { if (state.tInput === null) state.tInput = performance.now(); whatif(); };
  for (const id of ["X0", "Tb0_C", "heater", "fan", "tgi", "drop"]) $(id).addEventListener("change", changed);
  try {
    await refreshFiles();
    if ($("log").value && $("model").value) await openLog();
    else if ($("log").value) say(NO_MODEL);
  } catch (e) {
    say(e.message);
  }
});
