// Load on the live viewer: N clients (default 20) each change their settings every 0.1–0.5 s
// for D seconds (default 60) against one `ocular serve`, at 320×180. Then every client waits
// for the full frame of its last change. Reports frames, errors, the server's resident memory
// over time (peak, and first vs second half) and whether it stayed up.
//
//   node tools/viewer_load.mjs [--clients 20] [--seconds 60] [--size 320x180] [--json]
//
// Needs `npm ci` in tests/viewer (for the harness) and Node's WebSocket (Node 22+, or 20 with
// --experimental-websocket: the script restarts itself with it).
import { spawnSync } from "node:child_process";
import { readFileSync } from "node:fs";
import { join } from "node:path";

if (typeof WebSocket === "undefined") {
  const r = spawnSync(process.execPath, ["--experimental-websocket", ...process.argv.slice(1)], { stdio: "inherit" });
  process.exit(r.status ?? 1);
}

const here = new URL("../tests/viewer/", import.meta.url).pathname;
const { startServer } = await import(join(here, "harness.mjs"));

const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? process.argv[i + 1] : fallback;
};
const nClients = Number(arg("--clients", "20"));
const seconds = Number(arg("--seconds", "60"));
const [w, h] = arg("--size", "320x180").split("x").map(Number);
const json = process.argv.includes("--json");

// Deterministic noise (xorshift), so that every run asks the same.
let seed = 0x9e3779b9;
const rand = () => { seed ^= seed << 13; seed >>>= 0; seed ^= seed >>> 17; seed ^= seed << 5; seed >>>= 0; return seed / 4294967296; };
const pick = (a) => a[Math.floor(rand() * a.length)];

const scenes = ["primitives", "chart", "colonnade"];
const presets = ["myopia", "healthy", "astigmatism", "keratoconus"];
function settings() {
  const s = {
    scene: pick(scenes), size: [w, h],
    a: { eye: { kind: "preset", name: pick(presets) } },
    // a slider's steps: 0.25 D over 0–4 D
    focus: rand() < 0.3 ? { mode: "scene" } : { mode: "d", d: Math.round(rand() * 16) / 4 },
    pupil: rand() < 0.5 ? { mode: "auto" } : { mode: "mm", mm: 2 + Math.round(rand() * 8) / 2 },
    age: pick([25, 45, 65]),
    quality: pick(["balanced", "fast"]),
  };
  if (rand() < 0.2) s.a.correction = { kind: "glasses", rx: pick(["-1", "-2 -0.5 x 90", "+1.5"]) };
  return s;
}

const server = await startServer();
const rssKib = () => {
  try { return Number(readFileSync(`/proc/${server.pid}/status`, "utf8").match(/VmRSS:\s+(\d+)/)[1]); }
  catch (_) { return NaN; }
};
const samples = [];
const t0 = performance.now();
const sampler = setInterval(() => samples.push([(performance.now() - t0) / 1000, rssKib()]), 500);

function client(i) {
  return new Promise((resolve) => {
    const c = { i, seq: 0, lastFull: 0, lastAnswered: 0, frames: 0, previews: 0, errors: [], closed: false };
    const ws = new WebSocket(`${server.url.replace("http", "ws")}ws`);
    ws.binaryType = "arraybuffer";
    let timer;
    const send = () => {
      c.seq += 1;
      ws.send(JSON.stringify({ type: "render", seq: c.seq, settings: settings() }));
    };
    ws.onmessage = (ev) => {
      if (typeof ev.data === "string") {
        const m = JSON.parse(ev.data);
        if (m.type === "hello") {
          send();
          const loop = () => {
            if (performance.now() - t0 > seconds * 1000) return;
            send();
            timer = setTimeout(loop, 100 + rand() * 400);
          };
          timer = setTimeout(loop, 100 + rand() * 400);
        } else if (m.type === "error") {
          c.errors.push(m.message);
          if (m.seq === c.seq) c.lastAnswered = m.seq;
          if (performance.now() - t0 > seconds * 1000 && c.lastAnswered === c.seq) { clearTimeout(timer); ws.close(); }
        }
        return;
      }
      const n = new DataView(ev.data).getUint32(0);
      const header = JSON.parse(new TextDecoder().decode(new Uint8Array(ev.data, 4, n)));
      if (header.stage === "full") { c.frames += 1; c.lastFull = header.seq; c.lastAnswered = header.seq; } else c.previews += 1;
      if (performance.now() - t0 > seconds * 1000 && c.lastAnswered === c.seq) { clearTimeout(timer); ws.close(); }
    };
    ws.onclose = () => { c.closed = true; resolve(c); };
    ws.onerror = () => {};
  });
}

const deadline = (seconds + 600) * 1000;
const results = await Promise.race([
  Promise.all(Array.from({ length: nClients }, (_, i) => client(i))),
  new Promise((r) => setTimeout(() => r(null), deadline)),
]);
clearInterval(sampler);
const alive = server.proc.exitCode === null;
const stats = alive ? await (await fetch(`${server.url}api/stats`)).json() : null;
server.stop();

const rss = samples.map((s) => s[1]).filter(Number.isFinite);
const during = samples.filter((s) => s[0] <= seconds);
const half = (a, b) => Math.max(...during.filter((s) => s[0] > a && s[0] <= b).map((s) => s[1]));
const report = {
  clients: nClients, seconds, size: `${w}x${h}`,
  server_alive: alive,
  // every client's last change answered: by its full frame (or by the error it earned)
  all_got_latest: !!results && results.every((c) => c.lastAnswered === c.seq),
  last_answered_by_frame: results ? results.filter((c) => c.lastFull === c.seq).length : null,
  requests: results ? results.reduce((n, c) => n + c.seq, 0) : null,
  full_frames: results ? results.reduce((n, c) => n + c.frames, 0) : null,
  previews: results ? results.reduce((n, c) => n + c.previews, 0) : null,
  errors: results ? results.reduce((n, c) => n + c.errors.length, 0) : null,
  error_examples: results ? [...new Set(results.flatMap((c) => c.errors))].slice(0, 3) : null,
  drain_s: (performance.now() - t0) / 1000 - seconds,
  rss_mib: {
    start: rss[0] / 1024, peak: Math.max(...rss) / 1024, end: rss[rss.length - 1] / 1024,
    peak_first_half: half(0, seconds / 2) / 1024, peak_second_half: half(seconds / 2, seconds) / 1024,
  },
  server_stats: stats,
};
if (json) console.log(JSON.stringify(report, null, 2));
else {
  console.log(`${nClients} clients × ${seconds} s at ${report.size}: server ${alive ? "up" : "DOWN"}; every client got its latest frame: ${report.all_got_latest}`);
  console.log(`  ${report.requests} requests, ${report.previews} previews, ${report.full_frames} full frames, ${report.errors} errors; drained ${report.drain_s.toFixed(1)} s after the last change`);
  const m = report.rss_mib;
  console.log(`  resident memory: start ${m.start.toFixed(0)} MiB, peak ${m.peak.toFixed(0)} MiB (first half ${m.peak_first_half.toFixed(0)}, second half ${m.peak_second_half.toFixed(0)}), end ${m.end.toFixed(0)} MiB`);
}
process.exitCode = alive && report.all_got_latest ? 0 : 1;
