// Shared by the viewer's browser test and its measurements: start `ocular serve` on a free
// port, open Debian's chromium through playwright-core, and wait for frames in the page.
import { spawn } from "node:child_process";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join, resolve, dirname } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

export const repo = resolve(dirname(fileURLToPath(import.meta.url)), "../..");
export const bin = process.env.OCULAR_BIN || join(repo, "target/release/ocular");

export function fail(message) {
  console.error(`FAIL: ${message}`);
  process.exitCode = 1;
  throw new Error(message);
}

export function check(ok, message) {
  if (!ok) fail(message);
  console.log(`ok: ${message}`);
}

// Starts the server; resolves to { url, proc, pid, stop() } once it prints its address.
export function startServer(args = [], { cache } = {}) {
  const cacheDir = cache ?? mkdtempSync(join(tmpdir(), "ocular-viewer-cache-"));
  const proc = spawn(bin, ["serve", "--port", "0", "--cache", cacheDir, ...args], {
    stdio: ["ignore", "pipe", "pipe"],
  });
  let stderr = "";
  proc.stderr.on("data", (d) => { stderr += d; });
  return new Promise((ok, no) => {
    let out = "";
    const timer = setTimeout(() => no(new Error(`server did not start in 60 s: ${stderr}`)), 60000);
    proc.stdout.on("data", (d) => {
      out += d;
      const m = out.match(/on (http:\/\/127\.0\.0\.1:\d+\/)/);
      if (m) {
        clearTimeout(timer);
        ok({
          url: m[1],
          proc,
          pid: proc.pid,
          stderr: () => stderr,
          stop() {
            proc.kill("SIGTERM");
            if (!cache) rmSync(cacheDir, { recursive: true, force: true });
          },
        });
      }
    });
    proc.on("exit", (code) => no(new Error(`server exited (${code}): ${stderr}`)));
  });
}

export async function browser() {
  const profile = mkdtempSync(join(tmpdir(), "ocular-viewer-profile-"));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update"],
    viewport: { width: 1400, height: 860 },
    acceptDownloads: true,
  });
  const close = async () => {
    await context.close();
    rmSync(profile, { recursive: true, force: true });
  };
  return { context, close };
}

// Waits until the page shows stage `stage` ("preview" or "full") of a request at least `seq`.
export async function waitFrame(page, seq, stage = "full", timeout = 120000) {
  await page.waitForFunction(
    ([s, st]) => {
      const v = window.ocularViewer;
      const el = document.getElementById("stage");
      return v && Number(el.dataset.seq) >= s && (st === "preview" || el.dataset.stage === "full");
    },
    [seq, stage],
    { timeout },
  );
}

// Reads the shown frame's pixels (RGBA bytes) as a plain array.
export async function pixels(page, side = 0) {
  return page.evaluate((s) => {
    const img = document.getElementById(`img-${s}`);
    const c = document.createElement("canvas");
    c.width = img.naturalWidth;
    c.height = img.naturalHeight;
    const g = c.getContext("2d");
    g.drawImage(img, 0, 0);
    return Array.from(g.getImageData(0, 0, c.width, c.height).data);
  }, side);
}

export function meanAbsDiff(a, b) {
  if (a.length !== b.length) return Infinity;
  let s = 0;
  for (let i = 0; i < a.length; i++) s += Math.abs(a[i] - b[i]);
  return s / a.length;
}

// Mean |a - b| over the RGB of pixels [x0, x1) × [y0, y1) of a `width`-pixel-wide frame.
export function regionDiff(a, b, width, [x0, y0, x1, y1]) {
  let s = 0, n = 0;
  for (let y = y0; y < y1; y++) {
    for (let x = x0; x < x1; x++) {
      for (let c = 0; c < 3; c++) {
        const i = (y * width + x) * 4 + c;
        s += Math.abs(a[i] - b[i]);
        n++;
      }
    }
  }
  return s / n;
}

// Clicks the frame at pixel (x, y) of a `w`×`h` frame.
export async function clickPixel(page, x, y, w, h, side = 0) {
  const box = await page.locator(`#img-${side}`).boundingBox();
  await page.mouse.click(box.x + ((x + 0.5) / w) * box.width, box.y + ((y + 0.5) / h) * box.height);
}
