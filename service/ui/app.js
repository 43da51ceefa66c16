// stochcable's page: calls the /v1 API as any client does (no extra work for the
// analyses), draws with the vendored uPlot.  No build step, no dependency but uPlot.
"use strict";

const $ = (id) => document.getElementById(id);
const state = { key: sessionStorage.getItem("stochcable-key") || "", keys: false,
  doc: null, sceneText: "", job: null, timer: null, poll: 0, plots: [], readerNotes: [] };
const COLORS = ["#0b5fa5", "#d95f02", "#1b9e77", "#7570b3", "#e7298a", "#66a61e", "#a6761d"];
const VIRIDIS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
const YEAR_S = 365.25 * 86400;

// ------------------------------------------------------------------ helpers

function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === "class") e.className = v; else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c == null ? "" : c);
  return e;
}

function fmt(v) {
  if (v == null || !Number.isFinite(v)) return "–";
  const a = Math.abs(v);
  if (a !== 0 && (a < 1e-3 || a >= 1e7)) return v.toExponential(3);
  return v.toLocaleString("en-US", { maximumSignificantDigits: 4 });
}

function tick(v) {
  const a = Math.abs(v);
  return a !== 0 && (a < 1e-3 || a >= 1e5) ? v.toExponential(1) : fmt(v);
}

function headers(extra) {
  const h = Object.assign({}, extra || {});
  if (state.key) h.Authorization = "Bearer " + state.key;
  return h;
}

async function errorText(resp) {
  let body = "";
  try { body = await resp.text(); } catch (e) { /* no body */ }
  let lines = [];
  try {
    const detail = JSON.parse(body).detail;
    if (Array.isArray(detail)) {
      // an item with the line of a file (a MoorDyn file) names it in its message
      lines = detail.map((d) => (d.line == null && (d.loc || []).join(".") ? d.loc.join(".") + ": " : "") + d.msg);
    } else if (detail) lines = [String(detail)];
  } catch (e) { if (body) lines = [body.slice(0, 2000)]; }
  if (resp.status === 401) {
    lines.push("Give an API key above.");
    showKeyForm();
  }
  return `${resp.status} ${resp.statusText}\n` + lines.join("\n");
}

async function api(method, path, { body, accept, raw } = {}) {
  const init = { method, headers: headers({ Accept: accept || "application/json" }) };
  if (body !== undefined) {
    init.body = typeof body === "string" ? body : JSON.stringify(body);
    init.headers["Content-Type"] = "application/json";
  }
  const resp = await fetch(path, init);
  if (!resp.ok) throw new Error(await errorText(resp));
  if (raw) return resp;
  return resp.status === 204 ? null : resp.json();
}

function showError(box, err) {
  box.textContent = err ? String(err.message || err) : "";
  box.hidden = !err;
}

function save(blob, name) {
  const a = el("a", { href: URL.createObjectURL(blob), download: name });
  document.body.append(a); a.click(); a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

function table(node, head, rows) {
  node.replaceChildren(
    el("thead", {}, el("tr", {}, ...head.map((h) => el("th", { scope: "col" }, h)))),
    el("tbody", {}, ...rows.map((r) => el("tr", {}, ...r.map((c) => (c instanceof Node ? c : el("td", {}, c))))))
  );
}

function numCell(v, name) {
  const td = el("td", { "data-value": String(v) }, fmt(v));
  if (name) td.dataset.name = name;
  return td;
}

// ------------------------------------------------------------------ plots (uPlot)

function facetPlot(node, series, xlabel, ylabel, extra) {
  const xs = series.flatMap((s) => s.x), ys = series.flatMap((s) => s.y);
  const pad = (lo, hi) => { const d = (hi - lo) || Math.abs(hi) || 1; return [lo - 0.04 * d, hi + 0.04 * d]; };
  const xr = (extra && extra.xrange) || pad(Math.min(...xs), Math.max(...xs));
  const yr = (extra && extra.yrange) || pad(Math.min(...ys), Math.max(...ys));
  const opts = {
    mode: 2, width: 560, height: 320,
    legend: { live: false, show: !(extra && extra.noLegend) }, cursor: { drag: { x: false, y: false } },
    scales: { x: { time: false, range: xr }, y: { range: yr } },
    axes: [{ label: xlabel, values: (u, vals) => vals.map(tick) },
      { label: ylabel, size: 80, values: (u, vals) => vals.map(tick) }],
    series: [{}, ...series.map((s, i) => ({
      label: s.label, stroke: s.color || COLORS[i % COLORS.length], width: s.marker ? 0 : 1.5,
      fill: s.marker ? s.color : undefined,
      facets: [{ scale: "x", auto: false }, { scale: "y", auto: false }],
      paths: s.marker ? uPlot.paths.points() : (s.draw || uPlot.paths.linear()),
      points: s.marker ? { show: true, size: 10, fill: s.color, stroke: s.color, width: 1 } : { show: false },
    }))],
    hooks: (extra && extra.hooks) || {},
  };
  node.replaceChildren();
  const u = new uPlot(opts, [null, ...series.map((s) => [s.x, s.y])], node);
  state.plots.push(u);
  return u;
}

function interp(s, values, at) {
  for (let i = 1; i < s.length; i++) {
    if (at <= s[i]) {
      const t = (at - s[i - 1]) / (s[i] - s[i - 1] || 1);
      return values[i - 1] + t * (values[i] - values[i - 1]);
    }
  }
  return values[values.length - 1];
}

const VIEWS = { xz: [0, 2], yz: [1, 2], xy: [0, 1] };  // node coordinates drawn

function drawProfile(doc, scene, units) {
  const view = $("profile-view").value || "xz";
  const [i0, i1] = VIEWS[view];
  const series = [];
  let i = 0;
  for (const [name, st] of Object.entries(doc.statics.lines)) {
    const a = st.nodes.map((n) => n[i0]), b = st.nodes.map((n) => n[i1]);
    series.push({ label: name, x: a, y: b, color: COLORS[i++ % COLORS.length] });
    if (st.touchdown != null && st.s) {
      series.push({ label: `${name} touchdown`, x: [interp(st.s, a, st.touchdown)],
        y: [interp(st.s, b, st.touchdown)], marker: true, color: "#a51b0b" });
    }
  }
  const allx = series.flatMap((s) => s.x);
  const depth = scene && scene.environment && scene.environment.depth;
  if (depth != null && view !== "xy") {
    const span = [Math.min(...allx), Math.max(...allx)];
    series.unshift({ label: "seabed", x: span, y: [-depth, -depth], color: "#8b6b3d" });
    series.unshift({ label: "still water", x: span, y: [0, 0], color: "#7fb3d5" });
  }
  for (const [name, body] of Object.entries(doc.statics.bodies || {})) {
    series.push({ label: `body ${name}`, x: [body.position[i0]], y: [body.position[i1]], marker: true,
      color: "#333" });
  }
  const old = state.plots.indexOf(state.profile);
  if (old >= 0) { state.profile.destroy(); state.plots.splice(old, 1); }
  const L = units.length;
  state.profile = facetPlot($("profile-plot"), series, `${"xyz"[i0]} [${L}]`, `${"xyz"[i1]} [${L}]`);
}

function drawSpectra(doc, units) {
  const series = [];
  let i = 0;
  for (const [name, line] of Object.entries(doc.lines)) {
    const sp = line.spectra;
    if (!sp) continue;
    for (const end of ["end_a", "end_b"]) {
      if (!sp[end]) continue;
      series.push({ label: `${name} ${end}`, x: sp.omega, y: sp[end].tension, color: COLORS[i++ % COLORS.length] });
    }
  }
  if (!series.length) { $("spectra-plot").textContent = "No spectra in the result."; return; }
  const ymax = Math.max(...series.flatMap((s) => s.y));
  facetPlot($("spectra-plot"), series, "ω [rad/s]", `S_T [${units.force}²·s/rad]`,
    { yrange: [0, 1.05 * ymax || 1] });
}

// ------------------------------------------------------------------ analysis

function sceneInput() { return $("scene-text").value; }

// a MoorDyn input file, recognised as stochcable.io.moordyn_file.is_moordyn_text does
function isMoorDyn(text) {
  const lines = text.split(/\r?\n/);
  const first = (lines.find((l) => l.trim()) || "").trim();
  if (!first || first.startsWith("{")) return false;
  if (first.includes("---") && /moordyn/i.test(first)) return true;
  return lines.some((l) => l.includes("---") && /LINE TYPES|LINE DICTIONARY/i.test(l));
}

const DOFS = ["surge", "sway", "heave", "roll", "pitch", "yaw"];

// what a scene read from a MoorDyn file lacks: the vessels' motion (a zero RAO) and a sea
function sceneNotes(scene) {
  const notes = [];
  const moved = ((scene && scene.bodies) || []).filter((b) => b && b.prescribed);
  for (const b of moved) {
    const tables = DOFS.map((k) => b.prescribed[k]).filter(Boolean);
    if (tables.every((t) => [t.re, t.im].flat(2).every((v) => v === 0))) {
      notes.push(`bodies[${b.name}].prescribed is a zero motion RAO: the body does not move, ` +
        "and the lines answer to the waves on them alone. Give the vessel's RAO (per unit wave " +
        `amplitude over omega) in bodies[${b.name}].prescribed.`);
    }
  }
  if (moved.length && !scene.sea) {
    notes.push('The scene has no sea: add one (e.g. "sea": {"spectrum": {"type": "jonswap", ' +
      '"hs": 2, "tp": 8}, "heading": 0}) before Run analysis.');
  }
  return notes;
}

function showNotes() {
  let scene = null;
  try { scene = JSON.parse(sceneInput()); } catch (e) { /* not JSON (yet) */ }
  const notes = [...state.readerNotes, ...sceneNotes(scene)];
  $("scene-notes").replaceChildren(...notes.map((n) => el("li", { class: "warn" }, n)));
  $("scene-notes").hidden = !notes.length;
}

// a MoorDyn file -> its scene document in the editor (POST /v1/scenes/moordyn), with the
// reader's warnings (its X-Stochcable-Warnings header); a bad file: the 422 beside the input
async function convertMoorDyn(text) {
  $("run-status").textContent = "Reading the MoorDyn file…";
  const resp = await fetch("/v1/scenes/moordyn", { method: "POST", body: text,
    headers: headers({ "Content-Type": "text/plain", Accept: "application/json" }) });
  if (!resp.ok) {
    $("run-status").textContent = "Not read.";
    const item = await resp.clone().json().then((b) => b.detail[0], () => null);
    if (item && item.line) selectLine(text, item.line);
    throw new Error(await errorText(resp));
  }
  const scene = await resp.json();
  let notes = [];
  try { notes = JSON.parse(resp.headers.get("X-Stochcable-Warnings") || "[]"); } catch (e) { /* none */ }
  state.readerNotes = notes.map((n) => `MoorDyn file: ${n}`);
  $("scene-text").value = JSON.stringify(scene, null, 1);
  showNotes();
  $("run-status").textContent = "MoorDyn file read into a scene document.";
  return scene;
}

// select line `n` (1-based) of the editor, scrolled into view: where the file is wrong
function selectLine(text, n) {
  const lines = text.split("\n");
  const start = lines.slice(0, n - 1).reduce((a, l) => a + l.length + 1, 0);
  const area = $("scene-text");
  area.setSelectionRange(start, start + (lines[n - 1] || "").length);
  const lh = parseFloat(getComputedStyle(area).lineHeight) || 16;
  area.scrollTop = Math.max(0, (n - 3) * lh);
}

// the editor's text changed (typed, pasted, a file): convert a MoorDyn file
async function sceneChanged() {
  const text = sceneInput();
  if (!isMoorDyn(text)) { showNotes(); return; }
  showError($("scene-error"), null);
  try { await convertMoorDyn(text); } catch (e) { showError($("scene-error"), e); }
}

function clearNotes() { state.readerNotes = []; showNotes(); }

async function loadExamples() {
  const list = await api("GET", "/v1/examples");
  const sel = $("example-select");
  sel.replaceChildren(el("option", { value: "" }, "— choose an example —"),
    ...list.map((e) => el("option", { value: e.name, title: e.title }, e.name)));
}

// Each choice of an example asks for its scene; arrowing through a closed select asks
// for every example passed, and the answers may come back in any order: only the
// latest choice's answer is shown.
let exampleTicket = 0;

async function loadExample() {
  const name = $("example-select").value;
  if (!name) return;
  const ticket = ++exampleTicket;
  try {
    const scene = await api("GET", `/v1/examples/${encodeURIComponent(name)}`);
    if (ticket !== exampleTicket) return;  // a later choice superseded this one
    $("scene-text").value = JSON.stringify(scene, null, 1);
    showError($("scene-error"), null);
    clearNotes();
  } catch (e) { if (ticket === exampleTicket) showError($("scene-error"), e); }
}

function readFileInto(input, target, then) {
  const f = input.files && input.files[0];
  if (!f) return;
  f.text().then((t) => { $(target).value = t; if (then) then(); });
}

async function runAnalysis() {
  let text = sceneInput();
  const btn = $("run");
  btn.disabled = true;
  showError($("scene-error"), null);
  const t0 = performance.now();
  try {
    if (isMoorDyn(text)) {
      await convertMoorDyn(text);
      text = sceneInput();
    }
    $("run-status").textContent = "Running…";
    const doc = await api("POST", "/v1/analyses?timeseries=none", { body: text });
    state.doc = doc; state.sceneText = text;
    let scene = null;
    try { scene = JSON.parse(text); } catch (e) { /* the server accepted it */ }
    state.scene = scene;
    showResult(doc, scene);
    $("run-status").textContent = `Done in ${((performance.now() - t0) / 1000).toFixed(1)} s.`;
    $("result-title").focus();
  } catch (e) {
    $("run-status").textContent = "Failed.";
    showError($("scene-error"), e);
  } finally { btn.disabled = false; }
}

function showResult(doc, scene) {
  const units = doc.units || { force: "N", length: "m", time: "s" };
  state.plots.forEach((p) => p.destroy()); state.plots = [];
  $("result").hidden = false;
  $("result-title").textContent = (scene && scene.title) || "Result";
  const lin = doc.linearization || {};
  $("result-meta").replaceChildren(
    el("span", { class: lin.converged ? "ok" : "warn" },
      lin.converged ? "Drag linearization converged" : "Drag linearization NOT converged"),
    ` (${lin.iterations} iterations) · ${Object.keys(doc.lines).length} line(s) · ` +
    `${(doc.warnings || []).length} warning(s) · ${fmt(doc.timing.total_s)} s · units ${units.system || ""}`);
  const F = units.force, T = units.time;
  const rows = [];
  for (const [name, line] of Object.entries(doc.lines)) {
    for (const end of ["end_a", "end_b"]) {
      const t = line[end] && line[end].tension;
      if (!t) continue;
      rows.push([el("td", {}, name), el("td", { class: "text" }, end), numCell(t.mean),
        numCell(t.std, `${name}.${end}.std`), numCell(t.tz), numCell(t.mpm_3h)]);
    }
  }
  table($("stats-table"), ["line", "end", `mean [${F}]`, `σ [${F}]`, `Tz [${T}]`, `MPM 3 h [${F}]`], rows);
  drawProfile(doc, scene, units);
  drawSpectra(doc, units);
  // the service does not know a zero RAO is a placeholder: the page says so
  const warnings = [...(doc.warnings || []), ...sceneNotes(scene).map((n) => `page: ${n}`)];
  $("warnings-list").replaceChildren(...(warnings.length
    ? warnings.map((w) => el("li", { class: "warn" }, w)) : [el("li", { class: "ok" }, "None.")]));
  const fid = doc.fidelity;
  $("fidelity").hidden = !fid;
  if (fid) {
    $("fidelity-meta").textContent = `Target error ${fmt(fid.target_error)}; ω ${fmt(fid.omega.min)}–` +
      `${fmt(fid.omega.max)} rad/s, ${fid.omega.count} frequencies; solver ${fid.solver}.`;
    table($("fidelity-table"), ["setting", "value", "reason", "error [-]"],
      (fid.choices || []).map((c) => [c.setting, el("td", { class: "text" }, JSON.stringify(c.value)),
        el("td", { class: "text" }, c.reason), numCell(c.error)]));
  }
}

// the force label of the scene's unit system, read off g as stochcable.scene.units.unit_labels
function forceUnit(g) {
  if (Math.abs(g / 9.80665 - 1) <= 0.01) return "N";
  if (Math.abs(g / (9.80665 / 0.3048) - 1) <= 0.01) return "lbf";
  return "force unit";
}

function statsCsv(doc) {
  const u = doc.units || { force: "N", time: "s" };
  const out = [`line,end,mean [${u.force}],std [${u.force}],tz [${u.time}],mpm_3h [${u.force}]`];
  for (const [name, line] of Object.entries(doc.lines)) {
    for (const end of ["end_a", "end_b"]) {
      const t = line[end] && line[end].tension;
      if (t) out.push([name, end, t.mean, t.std, t.tz, t.mpm_3h].join(","));
    }
  }
  return out.join("\n") + "\n";
}

async function downloadNetcdf() {
  const btn = $("dl-netcdf");
  btn.disabled = true;
  try {
    const resp = await api("POST", "/v1/analyses?timeseries=none",
      { body: state.sceneText, accept: "application/x-netcdf", raw: true });
    save(await resp.blob(), "result.nc");
  } catch (e) { showError($("scene-error"), e); } finally { btn.disabled = false; }
}

// ------------------------------------------------------------------ batches

function parseScatter(text) {
  const lines = text.split(/\r?\n/).filter((l) => l.trim() && !l.trim().startsWith("#"));
  if (lines.length < 2) throw new Error("Scatter CSV: a header row and at least one sea state are needed.");
  const head = lines[0].split(",").map((h) => h.trim().toLowerCase());
  return lines.slice(1).map((l, i) => {
    const cells = l.split(",");
    const row = {};
    head.forEach((h, j) => {
      const v = (cells[j] || "").trim();
      if (v === "") return;
      const n = Number(v);
      if (!Number.isFinite(n)) throw new Error(`Scatter CSV row ${i + 2}: ${h} = ${JSON.stringify(v)} is not a number.`);
      row[h] = n;
    });
    return row;
  });
}

async function submitBatch() {
  const box = $("batch-error");
  showError(box, null);
  let body;
  try {
    const sceneText = sceneInput();
    let scene;
    try { scene = JSON.parse(sceneText); } catch (e) { throw new Error("Scene: not valid JSON (" + e.message + ")."); }
    body = { scene, scatter: { rows: parseScatter($("scatter-text").value) } };
    state.batchForce = forceUnit((scene.environment && scene.environment.g) || 9.80665);
    const heads = $("batch-headings").value.trim();
    if (heads) body.headings = heads.split(",").map((h) => Number(h.trim()));
    const curve = $("batch-curve").value.trim();
    if (curve) {
      const fat = { curve, method: $("batch-method").value };
      const fields = { nominal_diameter: "batch-diameter", nominal_area: "batch-area", mbs: "batch-mbs",
        mean_load_ratio: "batch-mlr", design_factor: "batch-dff" };
      for (const [k, id] of Object.entries(fields)) {
        if ($(id).value.trim() !== "") fat[k] = Number($(id).value);
      }
      body.fatigue = fat;
    }
  } catch (e) { showError(box, e); return; }
  $("batch-submit").disabled = true;
  try {
    const job = await api("POST", "/v1/batches", { body });
    $("batch-status").textContent = `Submitted ${job.id}.`;
    openJob(job.id);
    refreshJobs();
  } catch (e) { showError(box, e); } finally { $("batch-submit").disabled = false; }
}

async function refreshJobs() {
  try {
    const list = await api("GET", "/v1/batches");
    table($("jobs-table"), ["job", "status", "submitted (UTC)", "cases", "progress", ""],
      list.batches.map((j) => [
        el("td", { class: "text" }, j.id), el("td", { class: "text" }, j.status),
        el("td", { class: "text" }, j.created.replace("T", " ").slice(0, 19)),
        numCell(j.progress.total), el("td", {}, `${Math.round(100 * j.progress.fraction)} %`),
        el("td", {}, el("button", { type: "button", onclick: () => openJob(j.id),
          "aria-label": `Open job ${j.id}` }, "Open"), " ",
        el("button", { type: "button", onclick: () => cancelJob(j.id, j.status),
          "aria-label": `${finished(j.status) ? "Delete" : "Cancel"} job ${j.id}` },
        finished(j.status) ? "Delete" : "Cancel")),
      ]));
  } catch (e) { showError($("batch-error"), e); }
}

const finished = (s) => s === "done" || s === "failed" || s === "cancelled";

// Cancel (of a job last seen queued or running) never deletes: a job that finished before
// the cancel arrived is left as it finished and the page says the cancel came too late.
// Delete (of a finished job) removes it with its results.
async function cancelJob(id, status) {
  const del = finished(status), open = state.job === id;
  if (open) stopPolling();
  try {
    const j = await api("DELETE", `/v1/batches/${id}${del ? "" : "?cancel_only=true"}`);
    if (open && state.job === id) {
      if (del) { $("job").hidden = true; state.job = null; }
      else {
        const late = finished(j.status) && j.status !== "cancelled";
        await showJob(j, late ? "the cancel came too late: the batch had already finished" : "");
      }
    }
    refreshJobs();
  } catch (e) {
    showError($("batch-error"), e);
    if (open && state.job === id) pollJob();
  }
}

// a poll answered after a newer one was started, or after a cancel, is dropped
function stopPolling() { if (state.timer) clearTimeout(state.timer); state.timer = null; state.poll++; }

function openJob(id) {
  stopPolling();
  state.job = id;
  $("job").hidden = false;
  $("job-results").hidden = true;
  $("job-cancel").disabled = true;  // until the job's status tells Cancel from Delete
  $("job-title").textContent = `Job ${id}`;
  pollJob().then(() => $("job-title").focus());
}

async function pollJob() {
  const id = state.job, poll = state.poll;
  if (!id) return;
  let j;
  try { j = await api("GET", `/v1/batches/${id}`); } catch (e) { showError($("batch-error"), e); return; }
  if (state.job === id && state.poll === poll) await showJob(j);
}

async function showJob(j, note = "") {
  const id = j.id, p = j.progress;
  $("job-progress").value = p.fraction;
  const eta = p.eta_seconds != null ? `, about ${Math.round(p.eta_seconds)} s left` : "";
  $("job-progress-text").textContent = `${j.status}: ${p.done} of ${p.total} cases` +
    (p.not_ok ? ` (${p.not_ok} not ok)` : "") + (finished(j.status) ? "" : eta) + (j.error ? ` — ${j.error}` : "") +
    (note ? ` — ${note}` : "");
  $("job-cancel").textContent = finished(j.status) ? "Delete" : "Cancel";
  $("job-cancel").onclick = () => cancelJob(id, j.status);
  $("job-cancel").disabled = false;
  $("job-warnings").replaceChildren(...(j.warnings || []).map((w) => el("li", { class: "warn" }, w)),
    ...(j.problems || []).map((c) => el("li", { class: "warn" }, `case ${c.index}: ${c.status} — ${c.reason}`)));
  for (const b of ["job-csv", "job-netcdf", "job-json"]) $(b).hidden = j.status !== "done";
  if (j.status === "done") { await showJobResults(id); refreshJobs(); return; }
  if (finished(j.status)) { refreshJobs(); return; }
  state.timer = setTimeout(pollJob, 1000);
}

async function showJobResults(id) {
  const res = await api("GET", `/v1/batches/${id}/results`);
  $("job-results").hidden = false;
  // the governing line end: the largest annual damage
  let best = null;
  const totals = [];
  for (const [ln, t] of Object.entries(res.totals)) {
    for (const [end, d] of Object.entries(t.annual_damage || {})) {
      totals.push(`${ln} ${end}: annual damage ${fmt(d)} /year, fatigue life ${fmt((t.fatigue_life_years || {})[end])} years`);
      if (d != null && (!best || d > best.d)) best = { ln, end, d };
    }
  }
  $("job-totals").textContent = totals.join("; ") || "No damage totals.";
  const cases = res.cases, F = state.batchForce || "N";
  const ln0 = best ? best.ln : Object.keys(cases[0].lines)[0], end0 = best ? best.end : "end_b";
  drawHeatmap(cases, ln0, end0);
  const rows = cases.map((c, i) => {
    const r = c.lines[ln0][end0];
    return [numCell(i), numCell(c.hs), numCell(c.tp), numCell(c.heading), numCell(c.probability),
      el("td", { class: "text" }, c.status), numCell(r.tension.std), numCell(r.tension.mpm_3h),
      numCell(r.damage_rate)];
  });
  table($("cases-table"), ["case", "Hs [m]", "Tp [s]", "heading [deg]", "probability [-]", "status",
    `σ ${ln0} ${end0} [${F}]`, `MPM 3 h ${ln0} ${end0} [${F}]`, "damage rate [1/s]"], rows);
}

function viridis(t) {
  t = Math.max(0, Math.min(1, t)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(t)), f = t - i;
  const c = VIRIDIS[i].map((a, k) => Math.round(a + f * (VIRIDIS[i + 1][k] - a)));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

function step(values) {
  const u = [...new Set(values)].sort((a, b) => a - b);
  let d = Infinity;
  for (let i = 1; i < u.length; i++) d = Math.min(d, u[i] - u[i - 1]);
  return Number.isFinite(d) ? d : 1;
}

function drawHeatmap(cases, ln, end) {
  // annual damage contributed by each (Hs, Tp) cell, summed over headings
  const cells = new Map();
  for (const c of cases) {
    const r = c.lines[ln][end].damage_rate;
    if (r == null) continue;
    const k = `${c.hs}|${c.tp}`;
    cells.set(k, (cells.get(k) || 0) + c.probability * r * YEAR_S);
  }
  const pts = [...cells].map(([k, v]) => { const [h, t] = k.split("|").map(Number); return { h, t, v }; });
  const pos = pts.filter((p) => p.v > 0).map((p) => Math.log10(p.v));
  const lo = pos.length ? Math.min(...pos) : 0, hi = pos.length ? Math.max(...pos) : 1;
  // cell sizes: the Hs class step, and the Tp step within each Hs row (a diagram in Tz
  // classes has its Tp off any common grid: each row's Tp = Tz × a factor of its Hs)
  const dh = step(pts.map((p) => p.h)), dtAll = step(pts.map((p) => p.t));
  const rowStep = new Map();
  for (const h of new Set(pts.map((p) => p.h))) {
    const row = pts.filter((p) => p.h === h).map((p) => p.t);
    rowStep.set(h, row.length > 1 ? step(row) : dtAll);
  }
  for (const p of pts) p.w = rowStep.get(p.h);
  const ts = pts.map((p) => p.t), hs = pts.map((p) => p.h);
  const xr = [Math.min(...pts.map((p) => p.t - p.w / 2)), Math.max(...pts.map((p) => p.t + p.w / 2))];
  const yr = [Math.min(0, Math.min(...hs) - dh / 2), Math.max(...hs) + dh / 2];
  const drawCells = (u) => {
    const ctx = u.ctx;
    ctx.save();
    for (const p of pts) {
      const x0 = u.valToPos(p.t - p.w / 2, "x", true), x1 = u.valToPos(p.t + p.w / 2, "x", true);
      const y0 = u.valToPos(p.h + dh / 2, "y", true), y1 = u.valToPos(p.h - dh / 2, "y", true);
      ctx.fillStyle = p.v > 0 ? viridis((Math.log10(p.v) - lo) / ((hi - lo) || 1)) : "#ddd";
      ctx.fillRect(x0, y0, x1 - x0, y1 - y0);
    }
    ctx.restore();
  };
  $("heatmap-caption").textContent = `Annual fatigue damage per sea state, ${ln} ${end} (summed over headings)`;
  facetPlot($("heatmap-plot"), [{ label: "sea states", x: ts, y: hs, draw: () => null }],
    "Tp [s]", "Hs [m]", { xrange: xr, yrange: yr, noLegend: true, hooks: { draw: [drawCells] } });
  const bar = el("span", { class: "bar", style: `background: linear-gradient(to right, ${[0, 0.25, 0.5, 0.75, 1].map(viridis).join(",")})` });
  $("heatmap-legend").replaceChildren(el("span", {}, `${fmt(10 ** lo)} /year`), bar, el("span", {}, `${fmt(10 ** hi)} /year`));
}

async function jobDownload(kind) {
  const id = state.job;
  const accept = { csv: "text/csv", netcdf: "application/x-netcdf", json: "application/json" }[kind];
  const ext = { csv: "csv", netcdf: "nc", json: "json" }[kind];
  try {
    const resp = await api("GET", `/v1/batches/${id}/results`, { accept, raw: true });
    save(await resp.blob(), `batch-${id}.${ext}`);
  } catch (e) { showError($("batch-error"), e); }
}

// ------------------------------------------------------------------ keys and start

function showKeyForm() { $("key-form").hidden = false; }

async function start() {
  try {
    const cfg = await (await fetch("/ui/config.json")).json();
    state.keys = cfg.keys;
  } catch (e) { /* an older service: assume no keys */ }
  if (state.keys && !state.key) { showKeyForm(); $("key-input").focus(); return; }
  await afterKey();
}

async function afterKey() {
  try {
    await loadExamples();
    $("key-status").textContent = state.keys ? "Key accepted." : "";
    if (state.keys) $("key-form").hidden = true;
  } catch (e) {
    $("key-status").textContent = String(e.message || e);
    return;
  }
  refreshJobs();
}

function bind() {
  $("key-form").addEventListener("submit", (ev) => {
    ev.preventDefault();
    state.key = $("key-input").value.trim();
    sessionStorage.setItem("stochcable-key", state.key);
    afterKey();
  });
  $("example-load").addEventListener("click", loadExample);
  $("example-select").addEventListener("change", loadExample);
  $("scene-file").addEventListener("change", () => {
    clearNotes();
    readFileInto($("scene-file"), "scene-text", sceneChanged);
  });
  let typed = null;
  $("scene-text").addEventListener("input", () => {
    clearTimeout(typed);
    typed = setTimeout(sceneChanged, 400);
  });
  $("scatter-file").addEventListener("change", () => readFileInto($("scatter-file"), "scatter-text"));
  $("scatter-example").addEventListener("click", async () => {
    $("scatter-text").value = await (await fetch("/ui/scatter.csv")).text();
  });
  $("run").addEventListener("click", runAnalysis);
  $("dl-json").addEventListener("click", () => save(new Blob([JSON.stringify(state.doc)], { type: "application/json" }), "result.json"));
  $("dl-csv").addEventListener("click", () => save(new Blob([statsCsv(state.doc)], { type: "text/csv" }), "statistics.csv"));
  $("dl-netcdf").addEventListener("click", downloadNetcdf);
  $("profile-view").addEventListener("change", () => {
    if (state.doc) drawProfile(state.doc, state.scene, state.doc.units || { length: "m" });
  });
  $("batch-submit").addEventListener("click", submitBatch);
  $("jobs-refresh").addEventListener("click", refreshJobs);
  for (const k of ["csv", "netcdf", "json"]) $(`job-${k}`).addEventListener("click", () => jobDownload(k));
}

document.addEventListener("DOMContentLoaded", () => { bind(); start(); });
