// The viewer end to end in a real browser: load the page, wait for the first frame, click
// the near sphere to focus on it, type a bad prescription and then a good one, export, and
// save a screenshot. Run by ci/test.sh; `node tests/viewer/e2e.mjs [--screenshot FILE]`.
import { mkdirSync, readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { browser, check, clickPixel, meanAbsDiff, pixels, regionDiff, repo, startServer, waitFrame } from "./harness.mjs";

const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? process.argv[i + 1] : fallback;
};
const screenshot = arg("--screenshot", join(repo, "target/viewer/viewer.png"));

const server = await startServer();
const { context, close } = await browser();
const consoleErrors = [];
try {
  const page = await context.newPage();
  page.on("console", (m) => { if (m.type() === "error") consoleErrors.push(m.text()); });
  page.on("pageerror", (e) => consoleErrors.push(String(e)));
  await page.goto(server.url);

  // First frame: primitives through the myopic eye at 640×360, focused where the scene says.
  await waitFrame(page, 1, "full");
  const first = await page.evaluate(() => window.ocularViewer.summaries[0]);
  check(first.width === 640 && first.height === 360, `first frame is 640x360 (${first.width}x${first.height})`);
  check(Math.abs(first.focus_d - 1 / 7.5) < 1e-6, `first frame focuses at the scene's 7.5 m (${first.focus_d.toFixed(4)} D)`);
  const summaryText = await page.locator("#summary-0").innerText();
  check(/Far point/.test(summaryText) && /Pupil/.test(summaryText), "the summary shows the far point and the pupil");
  check(first.focus.limit === "far_point" && first.far_point_d > 5,
    `the -6 D myope cannot focus at 7.5 m: it stays at its far point (${first.far_point_d.toFixed(2)} D)`);

  // The healthy eye, which can focus where it looks.
  const seqHealthy = (await page.evaluate(() => window.ocularViewer.seq)) + 1;
  await page.selectOption("#eye-0-preset", "healthy");
  await waitFrame(page, seqHealthy, "full");
  const far = await page.evaluate(() => window.ocularViewer.summaries[0]);
  check(far.focus.actual_d < 0.5, `the healthy eye focuses far, near 7.5 m (at ${far.focus.actual_d.toFixed(3)} D: ${far.focus.limit})`);
  const before = await pixels(page);

  // Click the red sphere (0.2 m away, lower left): the focus moves to it.
  const seqBefore = await page.evaluate(() => window.ocularViewer.seq);
  await clickPixel(page, 242, 219, 640, 360);
  await waitFrame(page, seqBefore + 1, "full");
  const near = await page.evaluate(() => window.ocularViewer.summaries[0]);
  const at = (near.focus_from.match(/--focus-at (\d+),(\d+)/) || []).slice(1).map(Number);
  check(at.length === 2 && Math.abs(at[0] - 242) <= 2 && Math.abs(at[1] - 219) <= 2,
    `the focus came from the click (${near.focus_from})`);
  check(near.focus_d > 4.0 && near.focus_d < 6.0 && near.focus.limit === "reached",
    `the focus moved to the sphere, about 5 D, and the eye reached it (${near.focus_d.toFixed(3)} D)`);
  const after = await pixels(page);
  // The sphere's rim sharpens and the far letter blurs (a window around each).
  const sphere = regionDiff(before, after, 640, [190, 170, 300, 270]);
  const letter = regionDiff(before, after, 640, [305, 160, 335, 190]);
  const elsewhere = meanAbsDiff(before, after);
  check(sphere > 0.8 && letter > 3, `the image changed: mean |Δ| ${sphere.toFixed(1)} around the sphere, ${letter.toFixed(1)} around the letter, of 255 (${elsewhere.toFixed(2)} over the frame)`);
  const focusText = await page.locator('#summary-0 dd[data-field="Focus"]').innerText();
  check(/0\.\d+ m/.test(focusText), `the summary's focus reads ${focusText}`);

  // A bad prescription: the CLI's message beside the eye, and the server keeps serving.
  await page.selectOption("#eye-0-kind", "rx");
  await page.fill("#eye-0-rx", "-2.00 -0.75 x 200");
  await page.press("#eye-0-rx", "Enter");
  await page.waitForFunction(() => /x 200/.test(document.getElementById("eye-0-error").textContent), null, { timeout: 30000 });
  const error = await page.locator("#eye-0-error").innerText();
  check(/^--rx "-2.00 -0.75 x 200": .*axis 200/.test(error), `a bad prescription is refused inline: ${error}`);
  check((await page.locator("#eye-0-rx").getAttribute("aria-invalid")) === "true", "the prescription field is marked invalid");

  // A good one: an eye is estimated, the frame comes back and the error goes.
  const seqGood = (await page.evaluate(() => window.ocularViewer.seq)) + 1;
  await page.fill("#eye-0-rx", "-2.00 -0.75 x 90");
  await page.press("#eye-0-rx", "Enter");
  await waitFrame(page, seqGood, "full");
  check((await page.locator("#eye-0-error").innerText()) === "", "the error is cleared by the good prescription");
  check(await page.locator("#error").isHidden(), "the page's error line is hidden again");
  const command = await page.locator("#command").innerText();
  check(/ocular eye estimate --rx '-2.00 -0.75 x 90' --pupil-mm 5 -o eye-rx.toml && ocular render/.test(command),
    `the command line reproduces it: ${command}`);

  // Compare with a split: both eyes come back.
  const seqCompare = (await page.evaluate(() => window.ocularViewer.seq)) + 1;
  await page.selectOption("#compare", "split");
  await page.waitForFunction((s) => window.ocularViewer.fullSeq[1] >= s, seqCompare, { timeout: 120000 });
  // The second eye (healthy by default) in contact lenses of -1.75 D.
  const seqLens = (await page.evaluate(() => window.ocularViewer.seq)) + 1;
  await page.selectOption("#eye-1-corr", "contact");
  await page.fill("#eye-1-corr-rx", "-1.75");
  await page.press("#eye-1-corr-rx", "Enter");
  await waitFrame(page, seqLens, "full");
  await page.waitForFunction((s) => window.ocularViewer.fullSeq[1] >= s, seqLens, { timeout: 60000 });
  const b = await page.evaluate(() => window.ocularViewer.summaries[1]);
  check(/-1\.75/.test(b.correction ?? "") && /contact/.test(b.correction), `the second eye wears its lenses (${b.correction})`);
  const a = await page.evaluate(() => window.ocularViewer.summaries[0]);
  check(a.correction == null, "the first eye stays uncorrected");

  // Export both frames as EXR: two files with the EXR magic number.
  const downloads = [];
  page.on("download", (d) => downloads.push(d));
  await page.click("#export-exr");
  await page.waitForFunction(() => /exported .*-b\.exr/.test(document.getElementById("status").textContent), null, { timeout: 30000 });
  await new Promise((r) => setTimeout(r, 500));
  const names = downloads.map((d) => d.suggestedFilename()).sort();
  check(names.join(",") === "ocular-primitives-a.exr,ocular-primitives-b.exr", `both frames exported (${names.join(", ")})`);
  for (const d of downloads) {
    const magic = readFileSync(await d.path()).subarray(0, 4);
    check(magic.equals(Buffer.from([0x76, 0x2f, 0x31, 0x01])), `${d.suggestedFilename()} is an OpenEXR file`);
  }

  // Two eyes: a lens on one eye only is refused (the CLI gives the right eye the left's kind of
  // lens); a plano lens on the other makes the pair, and both frames come back as left, right.
  await page.selectOption("#compare", "binocular");
  await page.waitForFunction(() => /plano/.test(document.body.innerText), null, { timeout: 30000 });
  check(true, "a lens on one eye of a pair is refused with the remedy");
  const seqPair = (await page.evaluate(() => window.ocularViewer.seq)) + 1;
  await page.selectOption("#eye-0-corr", "contact");
  await page.fill("#eye-0-corr-rx", "0");
  await page.press("#eye-0-corr-rx", "Enter");
  await page.waitForFunction((s) => window.ocularViewer.fullSeq[1] >= s, seqPair, { timeout: 120000 });
  const heading = await page.locator("#summary-1 h3").innerText();
  check(heading === "Right", `the second frame is the right eye's (${heading})`);
  const pairCommand = await page.locator("#command").innerText();
  check(/--binocular .*--correct-right -1\.75/.test(pairCommand) && pairCommand.split("\n").length === 1,
    `one command renders the pair: ${pairCommand}`);

  mkdirSync(dirname(screenshot), { recursive: true });
  await page.evaluate(() => { document.getElementById("controls").scrollTop = 0; });
  await page.screenshot({ path: screenshot });
  console.log(`screenshot: ${screenshot}`);
  check(consoleErrors.length === 0, `no errors in the page's console (${consoleErrors.join("; ")})`);
} finally {
  await close();
  server.stop();
}
