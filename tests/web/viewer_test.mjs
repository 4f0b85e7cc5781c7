// Drives the viewer page in Debian's chromium (headless, playwright-core from the npm cache):
//   node viewer_test.mjs --url URL --playwright DIR/node_modules/playwright-core
//        [--frames N] [--people K] [--cameras C] [--screenshot FILE] [--timeline] [--duration S]
// Checks: the page loads without script errors, at least N frames arrive over the WebSocket, the
// people count shown (#people) is K and matches the frames received, the 3D canvas is not blank
// (pixels read back: not background, and each person's colour present), and with --timeline that
// pause and seek reach the server; --cameras C: the page draws C cameras (a rig's, in its world). --duration S then samples the page's frames/s for S seconds.
// Prints one JSON line with what it measured; exit code 0 when every check passed, 1 otherwise.

import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { pathToFileURL } from "node:url";

const args = {};
for (let i = 2; i < process.argv.length; ++i) {
  const key = process.argv[i].replace(/^--/, "");
  const next = process.argv[i + 1];
  if (next === undefined || next.startsWith("--")) args[key] = true;
  else { args[key] = next; ++i; }
}
const minFrames = Number(args.frames ?? 30);
const expectedPeople = args.people === undefined ? null : Number(args.people);
const expectedCameras = args.cameras === undefined ? null : Number(args.cameras);
const duration = Number(args.duration ?? 0);
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); return ok; };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const { chromium } = await import(pathToFileURL(join(args.playwright, "index.mjs")).href);
const profile = mkdtempSync(join(tmpdir(), "mocap-chromium-"));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: args.chromium ?? "/usr/bin/chromium",
  headless: true,
  viewport: { width: 1280, height: 720 },
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
const result = { url: args.url };
try {
  const page = context.pages()[0] ?? (await context.newPage());
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
  // Every frame the page receives, seen at the protocol level (not through the page's code).
  const frames = [];
  page.on("websocket", (ws) => ws.on("framereceived", (f) => {
    try {
      const m = JSON.parse(typeof f.payload === "string" ? f.payload : f.payload.toString());
      if (m.type === "frame") frames.push(m);
    } catch { errors.push("a WebSocket message that is not JSON"); }
  }));
  await page.goto(args.url, { waitUntil: "load", timeout: 20000 });
  const start = Date.now();
  while (frames.length < minFrames && Date.now() - start < 20000) await sleep(50);
  result.frames_received = frames.length;
  check(frames.length >= minFrames, `only ${frames.length} frames arrived (wanted ${minFrames})`);
  await sleep(1500);  // the fps counter needs a full second
  const shown = await page.evaluate(() => ({
    people: Number(document.getElementById("people").textContent),
    fps: Number(document.getElementById("fps").textContent),
    status: document.getElementById("status").textContent,
    drawn: window.viewerStats?.drawn ?? 0,
    cameras: window.viewerStats?.cameras ?? 0,
  }));
  result.cameras_shown = shown.cameras;
  if (expectedCameras !== null) check(shown.cameras === expectedCameras,
                                      `${shown.cameras} cameras drawn, expected ${expectedCameras}`);
  Object.assign(result, { people_shown: shown.people, fps_shown: shown.fps, status: shown.status });
  const last = frames[frames.length - 1];
  result.people_in_stream = last ? last.people.length : null;
  check(shown.status === "connected", `status is '${shown.status}'`);
  check(shown.drawn > 0, "the page drew no frame");
  if (last) check(shown.people === last.people.length,
                  `#people shows ${shown.people}, the last frame has ${last.people.length}`);
  if (expectedPeople !== null) check(shown.people === expectedPeople,
                                     `#people shows ${shown.people}, expected ${expectedPeople}`);
  // The 3D canvas read back: pixels that are not the background, and pixels of each person's colour.
  const ids = last ? last.people.map((p) => p.id) : [];
  const pixels = await page.evaluate((ids) => {
    const gl = document.getElementById("canvas3d");
    const c = document.createElement("canvas");
    c.width = gl.width; c.height = gl.height;
    const ctx = c.getContext("2d");
    ctx.drawImage(gl, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    const colours = ids.map((id) => window.viewerColour(id));
    const perId = ids.map(() => 0);
    let notBackground = 0;
    for (let i = 0; i < d.length; i += 4) {
      const [r, g, b] = [d[i], d[i + 1], d[i + 2]];
      if (Math.abs(r - 0x15) + Math.abs(g - 0x18) + Math.abs(b - 0x1d) > 30) ++notBackground;
      colours.forEach(([cr, cg, cb], k) => {
        if (Math.abs(r - cr) + Math.abs(g - cg) + Math.abs(b - cb) < 40) ++perId[k];
      });
    }
    return { width: c.width, height: c.height, notBackground, perId };
  }, ids);
  result.canvas = pixels;
  const total = pixels.width * pixels.height;
  check(total > 0 && pixels.notBackground > total * 0.005,
        `the 3D canvas is blank (${pixels.notBackground} of ${total} pixels drawn)`);
  pixels.perId.forEach((n, k) => check(n >= 30, `person ${ids[k]}'s colour covers only ${n} pixels`));
  if (args.timeline) {
    check(last && last.playback, "a recording's frames carry no playback state");
    await page.click("#play");  // pause
    let t = Date.now();
    while (!(frames.at(-1).playback && !frames.at(-1).playback.playing) && Date.now() - t < 5000) await sleep(50);
    check(!frames.at(-1).playback.playing, "pause did not reach the server");
    const target = Math.floor(frames.at(-1).playback.count / 2);
    await page.evaluate((v) => {
      const s = document.getElementById("scrub");
      s.value = String(v);
      s.dispatchEvent(new Event("input"));
    }, target);
    t = Date.now();
    while (frames.at(-1).playback.index !== target && Date.now() - t < 5000) await sleep(50);
    result.seek = { wanted: target, got: frames.at(-1).playback.index };
    check(frames.at(-1).playback.index === target, `seek to ${target} gave ${frames.at(-1).playback.index}`);
    await page.click("#play");  // play again
  }
  if (args.screenshot) await page.screenshot({ path: args.screenshot });
  if (duration > 0) {
    // The page's own counters (its last full second), read once a second; medians reported.
    const samples = [], renderSamples = [];
    const received0 = frames.length, t0 = Date.now();
    for (let s = 0; s < duration; ++s) {
      await sleep(1000);
      const st = await page.evaluate(() => ({ fps: window.viewerStats.fps.at(-1), render: window.viewerStats.renderFps.at(-1) }));
      samples.push(st.fps);
      renderSamples.push(st.render);
    }
    const median = (a) => { const s = [...a].sort((x, y) => x - y); return s[Math.floor(s.length / 2)]; };
    result.fps_samples = samples.map((x) => Math.round(x * 10) / 10);
    result.fps_median = median(samples);
    result.render_fps_median = median(renderSamples);
    result.received_per_second = (frames.length - received0) / ((Date.now() - t0) / 1000);
  }
  result.page_errors = errors;
  check(errors.length === 0, "page errors: " + errors.join("; "));
} catch (e) {
  failures.push(String(e));
} finally {
  await context.close();
  rmSync(profile, { recursive: true, force: true });
}
result.failures = failures;
console.log(JSON.stringify(result));
process.exit(failures.length === 0 ? 0 : 1);
