// roastlab's page: fetch JSON from the local server, draw with Plotly (served from its own wheel).
"use strict";

const sid = sessionStorage.getItem("roastlab-session") || crypto.randomUUID();
sessionStorage.setItem("roastlab-session", sid);
const $ = (id) => document.getElementById(id);
const state = { open: null, changed: null, table: null, busy: false, pending: false, lastDrawMs: null, tInput: null };

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
const temp = (v) => (v === null || v === undefined ? null : F() ? v * 9 / 5 + 32 : v);
const dtemp = (v) => (v === null || v === undefined ? null : F() ? v * 9 / 5 : v);
const unit = () => (F() ? "°F" : "°C");
function mmss(s) {
  if (s === null || s === undefined || !isFinite(s)) return "-";
  const n = Math.round(Math.abs(s));
  return `${s < 0 ? "-" : ""}${Math.floor(n / 60)}:${String(n % 60).padStart(2, "0")}`;
}
const minutes = (ts) => ts.map((t) => t / 60);
function mmssTicks(x) {  // the roaster's time axis: a tick a minute, written m:ss
  const last = Math.ceil(Math.max(...x));
  const vals = Array.from({ length: last + 1 }, (_, i) => i);
  return { tickvals: vals, ticktext: vals.map((m) => `${m}:00`) };
}

function eventShapes(events) {
  const shapes = [], notes = [];
  let i = 0;
  for (const [name, t] of Object.entries(events || {})) {
    shapes.push({ type: "line", xref: "x", yref: "paper", x0: t / 60, x1: t / 60, y0: 0.42, y1: 1,
                  line: { color: "#999", width: 1, dash: "dot" } });
    notes.push({ xref: "x", yref: "paper", x: t / 60, y: 1 - 0.04 * (i++ % 3), text: `${name} ${mmss(t)}`,
                 showarrow: false, xanchor: "left", font: { size: 10, color: "#555" } });
  }
  return { shapes, notes };
}

function draw() {
  const o = state.open;
  if (!o) return;
  const c = o.curves, ch = state.changed || o.curves;
  const x = minutes(c.time_s);
  const T = (a) => (a ? a.map(temp) : null);
  const traces = [];
  if (c.BT_measured) traces.push({ x, y: T(c.BT_measured), name: "BT measured", mode: "markers", marker: { size: 3, color: "#333" } });
  if (c.beans_measured) traces.push({ x, y: T(c.beans_measured), name: "beans measured (IR)", mode: "markers", marker: { size: 2, color: "#a0785a" } });
  traces.push({ x, y: T(c.BT_model), name: "BT model, as run", line: { color: "#1f77b4", width: 2 } });
  traces.push({ x, y: T(ch.BT_model), name: "BT model, changed", line: { color: "#ff7f0e", width: 2 }, uid: "bt-changed" });
  traces.push({ x, y: T(c.beans_model), name: "beans model, as run", line: { color: "#1f77b4", width: 1, dash: "dash" } });
  traces.push({ x, y: T(ch.beans_model), name: "beans model, changed", line: { color: "#ff7f0e", width: 1, dash: "dash" } });
  traces.push({ x, y: T(ch.drum_model), name: "drum model (ET), changed", line: { color: "#d62728", width: 1 } });
  if (c.RoR_measured) traces.push({ x, y: c.RoR_measured.map(dtemp), name: "RoR measured", yaxis: "y2", line: { color: "#555", width: 1 } });
  traces.push({ x, y: ch.RoR_model.map(dtemp), name: "RoR model, changed", yaxis: "y2", line: { color: "#ff7f0e", width: 1 } });
  if (ch.heater) traces.push({ x, y: ch.heater, name: "heater", yaxis: "y3", line: { shape: "hv", color: "#d62728" } });
  if (ch.fan) traces.push({ x, y: ch.fan, name: "fan", yaxis: "y3", line: { shape: "hv", color: "#2ca02c" } });
  const ev = eventShapes(o.events);
  const rorAfter = (ch.RoR_model || []).filter((v, i) => v !== null && c.time_s[i] > 90).map(dtemp);
  const rorTop = rorAfter.length ? Math.max(...rorAfter) * 1.2 + 2 : 30;
  const t0 = performance.now();
  Plotly.react("plot", traces, {
    margin: { t: 30, r: 60, l: 60, b: 40 }, legend: { orientation: "h", y: -0.12, font: { size: 10 } },
    xaxis: { title: { text: "time after CHARGE [m:ss]" }, domain: [0, 1], anchor: "y3", ...mmssTicks(x) },
    yaxis: { title: { text: `temperature [${unit()}]` }, domain: [0.42, 1] },
    yaxis2: { title: { text: `RoR [${unit()}/min]` }, overlaying: "y", side: "right", range: [dtemp(-2), rorTop], showgrid: false },
    yaxis3: { title: { text: "setting" }, domain: [0, 0.32] },
    shapes: ev.shapes, annotations: ev.notes, uirevision: "keep",
  }).then(() => {
    state.lastDrawMs = performance.now() - t0;
    if (state.tInput !== null) {  // from the input change to this curve on screen
      document.body.dataset.latency = String(performance.now() - state.tInput);
      state.tInput = null;
    }
  });
}

function drawTable() {
  const t = state.table;
  if (!t) return;
  const kinds = { time: (v) => mmss(v), temp: (v) => (v === null ? "-" : temp(v).toFixed(1)), pct: (v) => (v === null ? "-" : v.toFixed(1)) };
  const delta = { time: (d) => (d < 0 ? "-" : "+") + mmss(Math.abs(d)), temp: (d) => (dtemp(d) >= 0 ? "+" : "") + dtemp(d).toFixed(1), pct: (d) => (d >= 0 ? "+" : "") + d.toFixed(1) };
  const unitOf = { time: "m:ss", temp: unit(), pct: "%" };
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
  $("warnings").textContent = (t.warnings || []).map((w) => "note: " + w).join("\n");
}

function changes() {
  const v = (id) => $(id).value.trim();
  const body = { heater: v("heater"), fan: v("fan"), tgi: v("tgi") };
  const o = state.open;
  if (o && v("Tm0_C") !== "" && Number(v("Tm0_C")) !== o.Tm0_C) body.Tm0_C = Number(v("Tm0_C"));
  if (o && v("batch_kg") !== "" && Number(v("batch_kg")) !== o.batch_kg) body.batch_kg = Number(v("batch_kg"));
  if (v("X0") !== "" && o && Number(v("X0")) !== o.X0) body.X0 = Number(v("X0"));
  return body;
}

async function whatif() {
  if (!state.open) return;
  if (state.busy) { state.pending = true; return; }
  state.busy = true;
  try {
    const t0 = performance.now();
    const r = await api("/api/whatif", changes());
    state.changed = r.curves;
    state.table = r.table;
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

async function openLog() {
  say("opening ...");
  try {
    const r = await api("/api/open", { log: $("log").value, model: $("model").value });
    state.open = r;
    state.changed = null;
    state.table = r.table;
    $("Tm0_C").value = r.Tm0_C ?? "";
    $("Tm0_C_range").value = r.Tm0_C ?? 200;
    $("X0").value = r.X0 ?? "";
    $("batch_kg").value = r.batch_kg ?? "";
    $("batch_kg_range").min = (r.batch_kg || 1) * 0.5;
    $("batch_kg_range").max = (r.batch_kg || 1) * 1.6;
    $("batch_kg_range").value = r.batch_kg || 1;
    $("tr_batch_kg").value = r.batch_kg ?? "";
    for (const id of ["heater", "fan"]) $(id).value = "";
    $("tgi").value = 0;
    $("notes").textContent = (r.notes || []).join("\n");
    draw();
    drawTable();
    say("");
    document.body.dataset.opened = r.log;
  } catch (e) {
    say(e.message);
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
}
let pickModel = null;

async function runFit() {
  const logs = Array.from($("fit_logs").selectedOptions).map((o) => o.value);
  say("");
  try {
    await api("/api/fit", { logs, name: $("fit_name").value });
    const poll = async () => {
      const st = await api("/api/fit-status");
      $("fit_progress").max = st.total || 1;
      $("fit_progress").value = st.done || 0;
      $("fit_text").textContent = st.text || "";
      if (st.running) { setTimeout(poll, 300); return; }
      if (st.error) { say(st.error); return; }
      $("fit-report").textContent = st.report;
      $("fit_text").textContent = `held out: FIT ${st.held_out.FIT.toFixed(1)} %, MAE ${st.held_out.MAE.toFixed(2)} °C`;
      pickModel = st.model;
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

async function runTransfer() {
  say("running the transfer ...");
  try {
    const r = await api("/api/transfer", { batch_kg: $("tr_batch_kg").value, plant_to: $("tr_plant").value.trim(), tm0_free: $("tr_tm0_free").checked });
    $("transfer-summary").textContent = r.summary;
    $("downloads").innerHTML = r.downloads.map((u) => `<a href="${u}" download>${u.split("/").pop()}</a>`).join("");
    const x = minutes(r.time_s);
    Plotly.react("transfer-plot", [
      { x, y: r.target.map(temp), name: "target BT", line: { color: "#333", width: 2 } },
      { x, y: r.predicted.map(temp), name: "predicted BT with the program", line: { color: "#1f77b4" } },
      { x, y: r.program, name: `program: ${r.decide} [${r.unit}]`, yaxis: "y2", line: { shape: "hv", color: "#d62728" } },
    ], {
      margin: { t: 20, r: 60, l: 60, b: 40 }, legend: { orientation: "h", y: -0.2 },
      xaxis: { title: { text: "time after CHARGE [m:ss]" }, ...mmssTicks(x) }, yaxis: { title: { text: `BT [${unit()}]` } },
      yaxis2: { title: { text: `${r.decide} [${r.unit}]` }, overlaying: "y", side: "right", showgrid: false },
    });
    say("");
    document.body.dataset.transfer = "done";
  } catch (e) {
    say(e.message);
  }
}

function link(numberId, rangeId) {
  const go = () => { if (state.tInput === null) state.tInput = performance.now(); whatif(); };
  $(rangeId).addEventListener("input", () => { $(numberId).value = $(rangeId).value; go(); });
  $(numberId).addEventListener("input", () => { $(rangeId).value = $(numberId).value; go(); });
}

window.addEventListener("DOMContentLoaded", async () => {
  $("open").addEventListener("click", openLog);
  $("upload").addEventListener("change", upload);
  $("units").addEventListener("change", () => { draw(); drawTable(); });
  $("reset").addEventListener("click", openLog);
  $("run-transfer").addEventListener("click", runTransfer);
  $("run-fit").addEventListener("click", runFit);
  link("Tm0_C", "Tm0_C_range");
  link("batch_kg", "batch_kg_range");
  for (const id of ["X0", "heater", "fan", "tgi"]) $(id).addEventListener("change", whatif);
  try {
    await refreshFiles();
    if ($("log").value && $("model").value) await openLog();
  } catch (e) {
    say(e.message);
  }
});
