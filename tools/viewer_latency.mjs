// Latency of the live viewer, as a person sees it: from a click on the image (focus there) to
// the preview on screen and to the full frame on screen, in Debian's chromium.
//
//   node tools/viewer_latency.mjs [--size 640x360] [--eye myopia] [--quality balanced] [--clicks 8] [--json]
//
// Primitives through the eye, with a warm cache: the two click targets (the sphere and the
// cube) are each rendered once before timing, so the kernels of both eye states are on the
// device; the timed clicks alternate between them. Times are from the click event to the
// frame decoded and drawn (the next animation frame). Needs `npm ci` in tests/viewer.
import { join } from "node:path";

const here = new URL("../tests/viewer/", import.meta.url).pathname;
const { browser, clickPixel, startServer, waitFrame } = await import(join(here, "harness.mjs"));

const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? process.argv[i + 1] : fallback;
};
const [w, h] = arg("--size", "640x360").split("x").map(Number);
const eye = arg("--eye", "myopia");
const quality = arg("--quality", "balanced");
const clicks = Number(arg("--clicks", "8"));
const json = process.argv.includes("--json");

// Sphere (0.2 m) and cube (0.5 m) of the primitives scene, in pixels of a w×h frame.
const targets = [[242 / 640, 219 / 360], [382 / 640, 170 / 360]].map(([x, y]) => [Math.round(x * w), Math.round(y * h)]);

const server = await startServer();
const { context, close } = await browser();
const median = (a) => { const s = [...a].sort((x, y) => x - y); return s[Math.floor(s.length / 2)]; };
try {
  const page = await context.newPage();
  await page.goto(server.url);
  await waitFrame(page, 1, "full", 300000);
  const seq0 = await page.evaluate(() => window.ocularViewer.seq);
  await page.selectOption("#size", `${w}x${h}`);
  await page.selectOption("#eye-0-preset", eye);
  await page.selectOption("#quality", quality);
  await waitFrame(page, seq0 + 1, "full", 300000);
  const click = async (t) => {
    const seq = (await page.evaluate(() => window.ocularViewer.seq)) + 1;
    await clickPixel(page, t[0], t[1], w, h);
    await waitFrame(page, seq, "full", 300000);
    return page.evaluate((s) => ({ ...window.ocularViewer.latency[s], summary: window.ocularViewer.summaries[0] }), seq);
  };
  // Warm: each target's kernels (preview and full) prepared once.
  for (const t of targets) await click(t);
  for (const t of targets) await click(t);
  const preview = [], full = [], render = [];
  for (let i = 0; i < clicks; i++) {
    const l = await click(targets[i % 2]);
    preview.push(l.preview);
    full.push(l.full);
    render.push(l.summary.seconds_render * 1000);
    if (!l.summary.kernels_reused) console.error(`note: click ${i} prepared kernels (cache not warm)`);
  }
  const device = await page.evaluate(() => document.getElementById("device").textContent);
  const result = {
    size: `${w}x${h}`, eye, quality, scene: "primitives", clicks, device,
    preview_ms: { median: median(preview), max: Math.max(...preview) },
    full_ms: { median: median(full), max: Math.max(...full) },
    full_render_ms_median: median(render),
  };
  if (json) console.log(JSON.stringify(result, null, 2));
  else {
    console.log(`${result.scene} through ${eye} at ${result.size}, ${quality}, on ${device}, ${clicks} clicks, warm cache:`);
    console.log(`  click -> preview on screen: median ${result.preview_ms.median.toFixed(0)} ms, max ${result.preview_ms.max.toFixed(0)} ms`);
    console.log(`  click -> full frame on screen: median ${result.full_ms.median.toFixed(0)} ms, max ${result.full_ms.max.toFixed(0)} ms`);
    console.log(`  (the full frame's own render: median ${result.full_render_ms_median.toFixed(0)} ms)`);
  }
} finally {
  await close();
  server.stop();
}
