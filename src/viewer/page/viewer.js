// ocular viewer: sends the settings on every change and shows the frames that come back
// (a preview, then the full frame). The server keeps only a client's latest request, so this
// page may send as often as the user moves a control.
"use strict";

const $ = (id) => document.getElementById(id);
const SIZES = [[320, 180], [640, 360], [960, 540], [1280, 720], [1920, 1080]];

// What the page has and shows; tests and the latency tool read it.
const state = {
  ws: null,
  seq: 0,
  catalog: null,
  focus: { mode: "scene" },
  shown: { seq: 0, stage: "" },
  summaries: [null, null],
  // the request each side's last full frame answered
  fullSeq: [0, 0],
  commands: ["", ""],
  latency: {},
  errors: 0,
  urls: [null, null],
  pendingSend: false,
  inputAt: null,
};
window.ocularViewer = state;

function option(select, value, text) {
  const o = document.createElement("option");
  o.value = value;
  o.textContent = text ?? value;
  select.appendChild(o);
}

// One eye's controls: which eye, and what corrects it.
function eyeBlock(root, side) {
  const p = `eye-${side}`;
  root.insertAdjacentHTML("beforeend", `
    ${side === 1 ? "<h2>Second eye</h2>" : ""}
    <label>Eye <select id="${p}-kind">
      <option value="preset">preset</option>
      <option value="file">eye file</option>
      <option value="rx">prescription</option>
    </select></label>
    <label class="k-preset">Preset <select id="${p}-preset"></select></label>
    <label class="k-file">File <select id="${p}-file"></select></label>
    <label class="k-rx">Rx <input id="${p}-rx" type="text" placeholder="-2.00 -0.75 x 90" spellcheck="false" autocomplete="off"></label>
    <label class="k-rx">Measured at pupil (mm) <input id="${p}-rx-pupil" type="number" min="1" max="9" step="0.5" value="5"></label>
    <label>Correction <select id="${p}-corr">
      <option value="none">none</option>
      <option value="glasses">glasses</option>
      <option value="contact">contact lens</option>
      <option value="iol">intraocular lens</option>
    </select></label>
    <label class="c-lens">Lens Rx <input id="${p}-corr-rx" type="text" placeholder="-2.00 -0.75 x 90" spellcheck="false" autocomplete="off"></label>
    <label class="c-glasses">Vertex (mm) <input id="${p}-vertex" type="number" min="0" max="16" step="0.5" value="12"></label>
    <label class="c-iol">IOL power (D) <input id="${p}-iol" type="text" value="auto" spellcheck="false"></label>
    <div id="${p}-error" class="eye-error" role="alert"></div>`);
  const kind = $(`${p}-kind`), corr = $(`${p}-corr`);
  const show = () => {
    for (const k of ["preset", "file", "rx"]) {
      root.querySelectorAll(`.k-${k}`).forEach((e) => (e.hidden = kind.value !== k));
    }
    root.querySelectorAll(".c-lens").forEach((e) => (e.hidden = !["glasses", "contact"].includes(corr.value)));
    root.querySelectorAll(".c-glasses").forEach((e) => (e.hidden = corr.value !== "glasses"));
    root.querySelectorAll(".c-iol").forEach((e) => (e.hidden = corr.value !== "iol"));
  };
  kind.addEventListener("change", () => { show(); changed(); });
  corr.addEventListener("change", () => { show(); changed(); });
  // Typed fields are sent when finished (Enter or leaving the field), not per keystroke.
  for (const id of [`${p}-rx`, `${p}-rx-pupil`, `${p}-corr-rx`, `${p}-vertex`, `${p}-iol`]) {
    $(id).addEventListener("change", changed);
  }
  $(`${p}-preset`).addEventListener("change", changed);
  $(`${p}-file`).addEventListener("change", changed);
  show();
}

function eyeSettings(side) {
  const p = `eye-${side}`;
  const kind = $(`${p}-kind`).value;
  let eye;
  if (kind === "preset") eye = { kind, name: $(`${p}-preset`).value };
  else if (kind === "file") eye = { kind, name: $(`${p}-file`).value };
  else eye = { kind, rx: $(`${p}-rx`).value, pupil_mm: Number($(`${p}-rx-pupil`).value) };
  const c = $(`${p}-corr`).value;
  let correction = { kind: "none" };
  if (c === "glasses") correction = { kind: c, rx: $(`${p}-corr-rx`).value, vertex_mm: Number($(`${p}-vertex`).value) };
  if (c === "contact") correction = { kind: c, rx: $(`${p}-corr-rx`).value };
  if (c === "iol") correction = { kind: c, power: $(`${p}-iol`).value };
  return { eye, correction };
}

function settings() {
  const [w, h] = $("size").value.split("x").map(Number);
  const mode = $("pupil-mode").value;
  const pupil = mode === "mm" ? { mode, mm: Number($("pupil-mm").value) }
    : mode === "luminance" ? { mode, cdm2: Number($("pupil-lum").value) } : { mode };
  const s = {
    scene: $("scene").value,
    size: [w, h],
    a: eyeSettings(0),
    focus: state.focus,
    pupil,
    age: Number($("age").value),
    quality: $("quality").value,
    layers: Number($("layers").value),
    off_axis: $("off-axis").checked,
  };
  if ($("compare").value !== "off") s.b = eyeSettings(1);
  if ($("compare").value === "binocular") {
    // one pair: both eyes converge on the focus and share one accommodation
    s.binocular = true;
    s.ipd_mm = Number($("ipd").value);
  }
  return s;
}

// Coalesces changes to one message per animation frame.
function changed() {
  if (state.pendingSend) return;
  // latency is measured from the user's action, not from the message
  state.inputAt = performance.now();
  state.pendingSend = true;
  requestAnimationFrame(() => {
    state.pendingSend = false;
    send();
  });
}

// A field the server cannot do without, still empty: say so beside it instead of sending.
function missing() {
  const sides = $("compare").value === "off" ? [0] : [0, 1];
  for (const side of sides) {
    const p = `eye-${side}`;
    if ($(`${p}-kind`).value === "rx" && !$(`${p}-rx`).value.trim()) {
      return [side, "Type the prescription, \"S C x A\" (e.g. -2.00 -0.75 x 90), and press Enter."];
    }
    if (["glasses", "contact"].includes($(`${p}-corr`).value) && !$(`${p}-corr-rx`).value.trim()) {
      return [side, "Type the lens prescription, \"S C x A\", and press Enter."];
    }
  }
  return null;
}

function send() {
  if (!state.ws || state.ws.readyState !== WebSocket.OPEN) return;
  const hint = missing();
  if (hint) {
    $(`eye-${hint[0]}-error`).textContent = hint[1];
    return;
  }
  const seq = ++state.seq;
  state.latency[seq] = { sent: state.inputAt ?? performance.now() };
  state.inputAt = null;
  state.ws.send(JSON.stringify({ type: "render", seq, settings: settings() }));
  $("stage").classList.add("loading");
  setStatus("rendering…");
}

function setStatus(text, bad = false) {
  const s = $("status");
  s.textContent = text;
  s.classList.toggle("bad", bad);
}

function showError(message) {
  state.errors += 1;
  const e = $("error");
  e.textContent = message;
  e.hidden = false;
  // Put an eye's error beside that eye's controls as well.
  const side = message.startsWith("second eye:") ? 1 : 0;
  if (/--(rx|eye|correct|vertex-mm|iol-d)\b/.test(message)) {
    $(`eye-${side}-error`).textContent = message;
    const rx = /^(second eye: )?--rx/.test(message) ? $(`eye-${side}-rx`)
      : /--correct/.test(message) ? $(`eye-${side}-corr-rx`) : null;
    if (rx) rx.setAttribute("aria-invalid", "true");
  }
  $("stage").classList.remove("loading");
  setStatus("error", true);
}

function clearErrors() {
  $("error").hidden = true;
  $("error").textContent = "";
  for (const side of [0, 1]) {
    const e = $(`eye-${side}-error`);
    if (e) e.textContent = "";
  }
  document.querySelectorAll("[aria-invalid]").forEach((e) => e.removeAttribute("aria-invalid"));
}

// A negative vergence (a hyperopic eye's far point, or its focus in a pair when it exerts too
// little for infinity) lies beyond infinity.
const fmtD = (d) => (d > 0 ? `${(1 / d).toFixed(3)} m (${d.toFixed(2)} D)` : d < -1e-9 ? `beyond infinity (${d.toFixed(2)} D)` : "infinity (0 D)");

function summaryHtml(s, header) {
  const esc = (t) => String(t).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" }[c]));
  const f = s.focus;
  let focus = fmtD(f.actual_d);
  if (f.limit === "far_point" || f.limit === "FarPoint") focus += ` — its far point (asked ${fmtD(f.requested_d)})`;
  if (f.limit === "near_point" || f.limit === "NearPoint") focus += ` — its near point (asked ${fmtD(f.requested_d)})`;
  const rows = [
    ["Focus", focus],
    ["Asked by", s.focus_from],
    ["Far point", fmtD(s.far_point_d)],
    ["Pupil", `${s.pupil_mm.toFixed(2)} mm, ${s.pupil_from}`],
    ["Accommodation", s.accommodation_max_d == null ? "unlimited" : `${s.accommodation_max_d.toFixed(2)} D (${s.accommodation_source})`],
    ["Correction", s.correction ?? (s.iol_d != null ? `IOL ${s.iol_d.toFixed(2)} D` : "none")],
    ["Frame", `${s.width}×${s.height}, ${s.method}, ${s.quality}`],
    ["Render", `${(s.seconds_render * 1000).toFixed(1)} ms`],
    ["Kernels", s.kernels_reused ? "reused" : `${s.seconds_kernels.toFixed(2)} s (${s.psfs_computed} PSFs computed)`],
    ["Request → frame", `${(header.seconds_total * 1000).toFixed(0)} ms (${header.stage})`],
  ];
  const dl = rows.map(([k, v]) => `<dt>${esc(k)}</dt><dd data-field="${esc(k)}">${esc(v)}</dd>`).join("");
  const warn = (s.warnings || []).map((w) => `<p class="warn">${esc(w)}</p>`).join("");
  return `<dl>${dl}</dl>${warn}`;
}

// "A"/"B" when comparing two eyes, "Left"/"Right" for a binocular pair.
function sideName(side) {
  const pair = $("compare").value === "binocular";
  return pair ? (side === 0 ? "Left" : "Right") : (side === 0 ? "A" : "B");
}

function caption(side) {
  if ($("compare").value === "off") return "";
  const p = `eye-${side}`;
  const kind = $(`${p}-kind`).value;
  const eye = kind === "preset" ? $(`${p}-preset`).value : kind === "file" ? $(`${p}-file`).value : `Rx ${$(`${p}-rx`).value}`;
  const c = $(`${p}-corr`).value;
  const corr = c === "none" ? "uncorrected" : c === "iol" ? `IOL ${$(`${p}-iol`).value}` : `${c} ${$(`${p}-corr-rx`).value}`;
  return `${sideName(side)}: ${eye}, ${corr}`;
}

async function onFrame(header, png) {
  if (header.seq < state.shown.seq) return; // an older request's frame
  const side = header.side;
  const img = $(`img-${side}`);
  const url = URL.createObjectURL(new Blob([png], { type: "image/png" }));
  img.src = url;
  try { await img.decode(); } catch (_) { /* shown anyway */ }
  if (state.urls[side]) URL.revokeObjectURL(state.urls[side]);
  state.urls[side] = url;
  img.dataset.width = header.summary.width;
  img.dataset.height = header.summary.height;
  state.shown = { seq: header.seq, stage: header.stage };
  state.summaries[side] = header.summary;
  if (header.stage === "full") state.fullSeq[side] = header.seq;
  state.commands[side] = header.command;
  $(`summary-${side}`).innerHTML = (header.sides > 1 ? `<h3>${sideName(side)}</h3>` : "") + summaryHtml(header.summary, header);
  img.parentElement.querySelector("figcaption").textContent = caption(side);
  // a binocular pair's two sides share one command
  const second = header.sides > 1 && state.commands[1] && state.commands[1] !== state.commands[0];
  $("command").textContent = state.commands[0] + (second ? `\n${state.commands[1]}` : "");
  requestAnimationFrame(() => {
    const l = state.latency[header.seq];
    if (l && side === header.sides - 1) l[header.stage] = performance.now() - l.sent;
    const stage = $("stage");
    stage.dataset.seq = header.seq;
    stage.dataset.stage = header.stage;
    if (header.stage === "full" && side === header.sides - 1 && header.seq === state.seq) {
      stage.classList.remove("loading");
      setStatus("ready");
    } else if (header.stage === "preview") {
      setStatus("preview; full frame coming…");
    }
  });
  if (header.seq >= lastErrorSeq) clearErrors();
}

let lastErrorSeq = 0;

function onExport(header, bytes) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([bytes], { type: header.format === "png" ? "image/png" : "image/x-exr" }));
  a.download = header.filename;
  document.body.appendChild(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
  setStatus(`exported ${header.filename}`);
}

function onMessage(ev) {
  if (typeof ev.data === "string") {
    const m = JSON.parse(ev.data);
    if (m.type === "hello") {
      $("device").textContent = m.device;
      send();
    } else if (m.type === "error") {
      if (m.seq === 0 || m.seq >= state.shown.seq) {
        lastErrorSeq = m.seq + 1;
        showError(m.message);
      }
    }
    return;
  }
  const view = new DataView(ev.data);
  const n = view.getUint32(0);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(ev.data, 4, n)));
  const payload = new Uint8Array(ev.data, 4 + n);
  if (header.type === "frame") onFrame(header, payload);
  else if (header.type === "export") onExport(header, payload);
}

function connect() {
  const ws = new WebSocket(`ws://${location.host}/ws`);
  ws.binaryType = "arraybuffer";
  ws.onmessage = onMessage;
  ws.onopen = () => setStatus("connected");
  ws.onclose = () => {
    setStatus("disconnected; retrying…", true);
    setTimeout(connect, 1500);
  };
  state.ws = ws;
}

function layout() {
  const mode = $("compare").value;
  const stage = $("stage");
  stage.classList.toggle("single", mode === "off");
  stage.classList.toggle("split", mode === "split");
  stage.querySelector('.pane[data-side="1"]').hidden = mode === "off";
  $("eye-b").hidden = mode === "off";
  $("summary-1").hidden = mode === "off";
  $("split").hidden = mode !== "split";
  $("ipd-row").hidden = mode !== "binocular";
  splitAt();
}

function splitAt() {
  const pane = $("stage").querySelector('.pane[data-side="1"]');
  const split = $("compare").value === "split";
  pane.style.clipPath = split ? `inset(0 0 0 ${$("split").value}%)` : "";
  $("split-line").hidden = !split;
  $("split-line").style.left = `${$("split").value}%`;
}

function focusClick(ev) {
  const img = ev.currentTarget;
  const w = Number(img.dataset.width), h = Number(img.dataset.height);
  if (!w || !h) return;
  const [fw, fh] = $("size").value.split("x").map(Number);
  const r = img.getBoundingClientRect();
  const x = Math.min(fw - 1, Math.max(0, Math.floor(((ev.clientX - r.left) / r.width) * fw)));
  const y = Math.min(fh - 1, Math.max(0, Math.floor(((ev.clientY - r.top) / r.height) * fh)));
  state.focus = { mode: "at", x, y };
  $("focus-d-value").textContent = `at ${x},${y}`;
  changed();
}

function pupilControls() {
  const mode = $("pupil-mode").value;
  document.querySelectorAll(".pupil-mm").forEach((e) => (e.hidden = mode !== "mm"));
  document.querySelectorAll(".pupil-lum").forEach((e) => (e.hidden = mode !== "luminance"));
}

async function start() {
  const catalog = await (await fetch("/api/catalog")).json();
  state.catalog = catalog;
  for (const s of catalog.scenes) option($("scene"), s);
  $("scene").value = catalog.scenes.includes("primitives") ? "primitives" : catalog.scenes[0];
  for (const [w, h] of SIZES) if (w * h <= catalog.max_pixels) option($("size"), `${w}x${h}`, `${w}×${h}`);
  $("size").value = "640x360";
  for (let k = 1; k <= catalog.max_layers; k++) option($("layers"), String(k));
  eyeBlock($("eye-a"), 0);
  eyeBlock($("eye-b"), 1);
  for (const side of [0, 1]) {
    for (const p of catalog.eye_presets) option($(`eye-${side}-preset`), p);
    for (const f of catalog.eye_files) option($(`eye-${side}-file`), f);
    if (!catalog.eye_files.length) $(`eye-${side}-kind`).querySelector('option[value="file"]').disabled = true;
  }
  $("eye-0-preset").value = "myopia";
  // The comparison starts as "this eye | a healthy one".
  $("eye-1-preset").value = catalog.eye_presets.includes("healthy") ? "healthy" : catalog.eye_presets[0];
  for (const id of ["scene", "size", "quality", "layers", "off-axis", "pupil-lum"]) $(id).addEventListener("change", changed);
  $("focus-d").addEventListener("input", () => {
    const d = Number($("focus-d").value);
    state.focus = { mode: "d", d };
    $("focus-d-value").textContent = `${d.toFixed(2)} D`;
    changed();
  });
  $("focus-scene").addEventListener("click", () => {
    state.focus = { mode: "scene" };
    $("focus-d-value").textContent = "scene";
    changed();
  });
  $("pupil-mode").addEventListener("change", () => { pupilControls(); changed(); });
  $("pupil-mm").addEventListener("input", () => {
    $("pupil-mm-value").textContent = `${Number($("pupil-mm").value).toFixed(1)} mm`;
    changed();
  });
  $("age").addEventListener("input", () => { $("age-value").textContent = $("age").value; changed(); });
  $("compare").addEventListener("change", () => { layout(); changed(); });
  $("ipd").addEventListener("change", changed);
  $("split").addEventListener("input", splitAt);
  $("img-0").addEventListener("click", focusClick);
  $("img-1").addEventListener("click", focusClick);
  $("scene").addEventListener("change", () => { state.focus = { mode: "scene" }; $("focus-d-value").textContent = "scene"; });
  $("export-png").addEventListener("click", () => exportFrame("png"));
  $("export-exr").addEventListener("click", () => exportFrame("exr"));
  $("copy-command").addEventListener("click", async () => {
    try { await navigator.clipboard.writeText($("command").textContent); setStatus("command copied"); }
    catch (_) { setStatus("select the command below to copy it"); }
  });
  pupilControls();
  layout();
  connect();
}

// The shown frame (both, when comparing) as files.
function exportFrame(format) {
  if (!state.ws || state.ws.readyState !== WebSocket.OPEN) return;
  const sides = $("compare").value === "off" ? [0] : [0, 1];
  for (const side of sides) state.ws.send(JSON.stringify({ type: "export", format, side }));
}

start().catch((e) => { setStatus(`cannot start: ${e}`, true); });
