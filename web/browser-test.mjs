// The editor in headless Chromium with WebGPU (SwiftShader): builds nothing, expects web/pkg/ and
// web/pkg-threads/ to exist (web/build.sh), serves the repository on 127.0.0.1 (cross-origin
// isolated, so the page runs the threaded bundle; a second server without the isolation headers
// for the single-threaded one), and checks what a user would see.
//
//   node web/browser-test.mjs            (CHROMIUM=/path/to/chromium to use another binary)
//
// Screenshots land in web/test-results/. Prints "browser: N passed, M failed" and exits non-zero
// on any failure; a missing browser is a failure, never a skip.
import { existsSync } from 'node:fs';
import { mkdir, readFile, stat, writeFile } from 'node:fs/promises';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { startServer } from './server.mjs';
import { summary, validate } from './validate-gltf.mjs';

const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
const resultsDir = fileURLToPath(new URL('./test-results/', import.meta.url));
const pkg = fileURLToPath(new URL('./pkg/knotwork_bg.wasm', import.meta.url));
const pkgThreads = fileURLToPath(new URL('./pkg-threads/knotwork_bg.wasm', import.meta.url));

// Flags that give headless Chromium a WebGPU adapter and a rendered canvas on SwiftShader
// (../shared/notes/toolchain.md): with fewer, compute works but the canvas stays black.
const webgpuFlags = [
  '--no-sandbox', '--disable-gpu-sandbox', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--enable-unsafe-webgpu', '--enable-features=Vulkan', '--use-vulkan=swiftshader',
  '--use-angle=swiftshader',
];

// WebGL2 without WebGPU: no --enable-unsafe-webgpu (and the page's navigator.gpu hidden too);
// ANGLE on SwiftShader needs --enable-unsafe-swiftshader for WebGL.
const webgl2Flags = [
  '--no-sandbox', '--disable-gpu-sandbox', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
];

const results = [];
// While working on one check: KNOTWORK_BROWSER_ONLY=substring runs only the checks whose name
// contains it (the test command never sets it).
const only = process.env.KNOTWORK_BROWSER_ONLY;
async function check(name, body) {
  if (only && !name.includes(only)) return;
  const started = performance.now();
  try {
    await body();
    results.push({ name, ok: true });
    console.log(`ok    ${name} (${((performance.now() - started) / 1000).toFixed(1)} s)`);
  } catch (error) {
    results.push({ name, ok: false });
    console.log(`FAIL  ${name}\n      ${String(error.stack ?? error).split('\n').join('\n      ')}`);
  }
}

function assert(condition, message) {
  if (!condition) throw new Error(message);
}

/** Opens the page, collecting console errors and uncaught exceptions. */
async function openEditor(browser, url, { hideWebGpu = false } = {}) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`page: ${e.message}`));
  if (hideWebGpu) {
    await page.addInitScript(() => { delete Object.getPrototypeOf(navigator).gpu; });
  }
  await page.goto(url);
  return { page, errors };
}

/**
 * The page's status, with undo_steps counted from the last openObjects (opening a project is
 * an undo step of its own, which the checks after it do not count).
 */
const status = (page) => page.evaluate(() => {
  const s = window.knotwork.status();
  return { ...s, undo_steps: s.undo_steps - (window.__base ?? 0) };
});

/**
 * Statistics of a screenshot's pixels in a rectangle, decoded in the page (no image library
 * needed here): how many differ from `background` by more than `tolerance` in any channel.
 */
async function screenshotStats(page, png, rect, background, tolerance) {
  return page.evaluate(async ({ data, rect, background, tolerance }) => {
    const bytes = Uint8Array.from(atob(data), (c) => c.charCodeAt(0));
    const bitmap = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
    const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
    const context = canvas.getContext('2d');
    context.drawImage(bitmap, 0, 0);
    const pixels = context.getImageData(rect.x, rect.y, rect.width, rect.height).data;
    let differing = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      if (Math.abs(pixels[i] - background[0]) > tolerance
        || Math.abs(pixels[i + 1] - background[1]) > tolerance
        || Math.abs(pixels[i + 2] - background[2]) > tolerance) differing += 1;
    }
    return { differing, total: pixels.length / 4, width: bitmap.width, height: bitmap.height };
  }, { data: png.toString('base64'), rect, background, tolerance });
}

/** How many pixels of two screenshots differ by more than `tolerance` in any channel. */
async function screenshotDifference(page, a, b, rect, tolerance) {
  return page.evaluate(async ({ a, b, rect, tolerance }) => {
    const decode = async (data) => {
      const bytes = Uint8Array.from(atob(data), (c) => c.charCodeAt(0));
      const bitmap = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
      const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
      const context = canvas.getContext('2d');
      context.drawImage(bitmap, 0, 0);
      return context.getImageData(rect.x, rect.y, rect.width, rect.height).data;
    };
    const [pa, pb] = [await decode(a), await decode(b)];
    let differing = 0;
    for (let i = 0; i < pa.length; i += 4) {
      if (Math.abs(pa[i] - pb[i]) > tolerance || Math.abs(pa[i + 1] - pb[i + 1]) > tolerance
        || Math.abs(pa[i + 2] - pb[i + 2]) > tolerance) differing += 1;
    }
    return { differing, total: pa.length / 4 };
  }, { a: a.toString('base64'), b: b.toString('base64'), rect, tolerance });
}

/** The page's exportGlb(options) as bytes (through base64: the page returns a Uint8Array). */
async function exportGlbBytes(page, options) {
  const exported = await page.evaluate(async (o) => {
    const glb = await window.knotwork.exportGlb(o);
    let text = '';
    for (let k = 0; k < glb.length; k += 0x8000) text += String.fromCharCode(...glb.subarray(k, k + 0x8000));
    return btoa(text);
  }, options);
  return new Uint8Array(Buffer.from(exported, 'base64'));
}

/** The JSON chunk of a .glb. */
function glbJson(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const length = view.getUint32(12, true);
  return JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + length)));
}

/** The bytes of accessor `index` of a .glb (its elements, tightly packed in its view). */
function glbAccessorBytes(bytes, index) {
  const json = glbJson(bytes);
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const bin = 20 + view.getUint32(12, true) + 8;
  const accessor = json.accessors[index];
  const bufferView = json.bufferViews[accessor.bufferView];
  const width = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[accessor.type];
  const component = { 5121: 1, 5123: 2, 5125: 4, 5126: 4 }[accessor.componentType];
  const start = bin + (bufferView.byteOffset ?? 0) + (accessor.byteOffset ?? 0);
  return bytes.subarray(start, start + accessor.count * width * component);
}

/** The floats of float accessor `index` of a .glb. */
function glbFloats(bytes, index) {
  const raw = glbAccessorBytes(bytes, index);
  const view = new DataView(raw.buffer, raw.byteOffset, raw.byteLength);
  const out = new Float32Array(raw.byteLength / 4);
  for (let k = 0; k < out.length; k += 1) out[k] = view.getFloat32(4 * k, true);
  return out;
}

/** The message `call` (run in the page) throws, or null if it does not throw. */
async function thrownBy(page, call) {
  return page.evaluate((source) => {
    try {
      (0, eval)(source)();
      return null;
    } catch (e) {
      return e.message;
    }
  }, call.toString());
}

/** Has the editor draw `count` more frames, so the canvas shows the latest state. */
// Installs in the page window.__waitFor(test, limit, key): animation frames until test()
// holds or limit ms pass, with the readings of status()[key] (a progress) along the way; and
// window.__stlVolume(bytes): a binary STL's facet count and enclosed volume (the divergence
// theorem over its facets).
async function installPageHelpers(page) {
  await page.evaluate(() => {
    window.__stlVolume = (stl) => {
      const view = new DataView(stl.buffer, stl.byteOffset, stl.byteLength);
      const facets = view.getUint32(80, true);
      let volume = 0;
      for (let k = 0; k < facets; k += 1) {
        const at = 84 + 50 * k + 12;
        const [a, b, c] = [0, 1, 2].map((i) => [0, 1, 2].map((j) => view.getFloat32(at + 12 * i + 4 * j, true)));
        volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
      }
      return { facets, volume };
    };
    window.__waitFor = async (test, limit, key) => {
      const started = performance.now();
      let frames = 0;
      const progress = [];
      while (!test() && performance.now() - started < limit) {
        await new Promise((r) => requestAnimationFrame(r));
        frames += 1;
        const p = window.knotwork.status()[key];
        if (p !== null && p !== undefined) progress.push(p);
      }
      return { ms: performance.now() - started, frames, progress };
    };
  });
}

/** Whether the page gets an animation frame within 2 s. */
async function animationFrameComes(page) {
  return page.evaluate(() => Promise.race([
    new Promise((r) => requestAnimationFrame(() => r(true))),
    new Promise((r) => setTimeout(() => r(false), 2000)),
  ]));
}

/**
 * Waits up to 60 s for the status to report `n` patches; else fails with what tells a lost
 * frame from a wrong result: the frames drawn while waiting, whether the page still gets
 * animation frames, its visibility and focus, what one mouse move over the canvas then brings
 * (frames, patches, undo steps), the console's errors and the status.
 */
async function waitForPatches(page, n, what, errors) {
  const framesBefore = (await status(page)).frames;
  try {
    await page.waitForFunction((k) => window.knotwork.status().patches === k, n, { timeout: 60_000 });
  } catch {
    const s = await status(page);
    const frames = await animationFrameComes(page);
    const pageState = await page.evaluate(() => ({ visibility: document.visibilityState, focus: document.hasFocus() }));
    await page.mouse.move(700, 400);
    await page.waitForTimeout(2000);
    const after = await status(page);
    const moved = { frames: after.frames - s.frames, patches: after.patches, undo_steps: after.undo_steps };
    throw new Error(`${what}: not reached in 60 s; ${s.frames - framesBefore} frames drawn while waiting; animation frames ${frames ? 'come' : 'do not come'}; page ${JSON.stringify(pageState)}; after a mouse move ${JSON.stringify(moved)}; console errors ${JSON.stringify(errors)}; status ${JSON.stringify(s)}`);
  }
}

async function nextFrames(page, count = 2) {
  const frames = (await status(page)).frames;
  await page.evaluate(() => window.knotwork.setContinuous(true));
  await page.waitForFunction((f) => window.knotwork.status().frames >= f, frames + count, { timeout: 30_000 });
  await page.evaluate(() => window.knotwork.setContinuous(false));
}

/** An n x n bicubic B-spline landscape as a project object (uniform clamped knots). */
function landscapeObject(n, segments) {
  const knots = [0, 0, 0, 0];
  for (let k = 1; k <= n - 4; k += 1) knots.push(k / (n - 3));
  knots.push(1, 1, 1, 1);
  const points = [];
  for (let i = 0; i < n; i += 1) {
    const row = [];
    for (let j = 0; j < n; j += 1) {
      const [x, y] = [(10 * i) / n, (10 * j) / n];
      row.push([x, y, 0.6 * Math.sin(x * 0.9) * Math.cos(y * 0.7), 1]);
    }
    points.push(row);
  }
  return { type: 'nurbs_surface', name: `landscape ${n}`, segments, degree: [3, 3], knots: [knots, knots], points };
}

/** Opens `objects` as a project and waits for its first frame. */
// A bilinear plane object named `name` through corners [[p00, p01], [p10, p11]].
function plane(name, corners) {
  return {
    type: 'nurbs_surface', name, segments: 8, degree: [1, 1],
    knots: [[0, 0, 1, 1], [0, 0, 1, 1]],
    points: corners.map((row) => row.map((p) => [...p, 1])),
  };
}

async function openObjects(page, objects) {
  const text = JSON.stringify({ format: 'knotwork', version: 2, objects });
  // Opening is an undo step: wait for it (the object count alone may be the previous
  // document's), and count the checks' undo steps from it.
  const before = await page.evaluate(() => window.knotwork.status().undo_steps);
  await page.evaluate((t) => window.knotwork.openProject('bench.json', t), text);
  await page.waitForFunction(([n, steps]) => {
    const s = window.knotwork.status();
    return s.objects === n && s.undo_steps === steps;
  }, [objects.length, before + 1], { timeout: 120_000 });
  await page.evaluate(() => { window.__base = window.knotwork.status().undo_steps; });
  await nextFrames(page, 1);
}

/** A handle of the selected object inside the viewport with no other handle within `gap` px. */
async function freeHandle(page, gap) {
  const handles = await page.evaluate(() => window.knotwork.handles());
  const inside = handles.map((h, k) => [k, h]).filter(([, h]) => h && h[0] > 450 && h[0] < 1200 && h[1] > 100 && h[1] < 700);
  return inside.find(([k, h]) => inside.every(([j, q]) => j === k || Math.hypot(q[0] - h[0], q[1] - h[1]) > gap)) ?? inside[0];
}

/**
 * Drags from (x, y) with real mouse events in `steps` moves of (dx, dy). Each move after the
 * first (which starts the drag) must bring a new frame: the sorted times from the mouse event
 * to that frame (the drag-to-new-frame latency) are returned.
 */
async function dragWithMouse(page, x, y, steps, dx, dy) {
  await page.mouse.move(x, y);
  await page.mouse.down();
  const times = [];
  for (let k = 1; k <= steps; k += 1) {
    const frames = (await status(page)).frames;
    const t0 = Date.now();
    await page.mouse.move(x + dx * k, y + dy * k);
    if (k > 1) {
      await page.waitForFunction((f) => window.knotwork.status().frames > f, frames, { timeout: 120_000 });
      times.push(Date.now() - t0);
    }
  }
  await page.mouse.up();
  return times.sort((a, b) => a - b);
}

/** The viewport's part of the canvas (right of the panel) that screenshots compare. */
const VIEWPORT = { x: 320, y: 60, width: 940, height: 700 };

/**
 * Frames the model, selects object 0 and drags one of its handles (with no other handle within
 * 10 px) with real mouse events, then waits for the drag's undo step. Returns the handle's
 * index and the canvas before the drag.
 */
async function dragFirstObjectHandle(page) {
  await page.evaluate(() => window.knotwork.frame());
  await page.evaluate(() => window.knotwork.select(0));
  await page.waitForFunction(() => window.knotwork.status().selected === 0, null, { timeout: 30_000 });
  await nextFrames(page);
  const canvas = await page.locator('#knotwork-canvas').boundingBox();
  const before = await page.locator('#knotwork-canvas').screenshot();
  const [index, [hx, hy]] = await freeHandle(page, 10);
  await dragWithMouse(page, canvas.x + hx, canvas.y + hy, 4, 10, -8);
  await page.waitForFunction(() => {
    const t = window.knotwork.status();
    return t.undo_steps - (window.__base ?? 0) === 1 && !t.dragging;
  }, null, { timeout: 60_000 });
  return { index, before };
}

/** Drag-to-new-frame times for a handle of object 0. */
async function dragToFrame(page, canvas) {
  await page.evaluate(() => window.knotwork.select(0));
  await page.waitForFunction(() => window.knotwork.status().selected === 0, null, { timeout: 30_000 });
  await nextFrames(page, 1);
  const [, [hx, hy]] = await freeHandle(page, 10);
  const times = await dragWithMouse(page, canvas.x + hx, canvas.y + hy, 5, 6, -4);
  await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) >= 1, null, { timeout: 60_000 });
  return times;
}

async function main() {
  if (!existsSync(chromiumPath)) {
    console.log(`FAIL  no Chromium at ${chromiumPath}: install it (Debian: apt-get install chromium) or set CHROMIUM`);
    console.log('browser: 0 passed, 1 failed');
    process.exit(1);
  }
  if (!existsSync(pkg) || !existsSync(pkgThreads)) {
    console.log(`FAIL  ${existsSync(pkg) ? pkgThreads : pkg} is missing: build the bundles first with web/build.sh`);
    console.log('browser: 0 passed, 1 failed');
    process.exit(1);
  }
  await mkdir(resultsDir, { recursive: true });
  const server = await startServer(0);
  const url = `http://127.0.0.1:${server.address().port}/index.html`;
  // The same page served without the cross-origin isolation headers: single-threaded.
  const plainServer = await startServer(0, { isolated: false });
  const browser = await chromium.launch({ executablePath: chromiumPath, headless: true, args: webgpuFlags });
  console.log(`Chromium ${browser.version()}, serving ${url}`);

  try {
    await check('the scene is evaluated and drawn with WebGPU', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => {
        const s = window.knotwork.status();
        return s.frames >= 1 || s.error;
      }, null, { timeout: 120_000 });
      let s = await status(page);
      assert(s.error === null, `error: ${s.error}`);
      assert(s.backend === 'webgpu', `backend ${s.backend}`);
      assert(typeof s.adapter === 'string' && s.adapter.length > 0, `adapter ${s.adapter}`);
      // SwiftShader is a software adapter: its device keeps WebGPU's default 128 MiB buffers
      // (a hardware GPU's would ask for what the GPU offers, up to 1 GiB).
      assert(s.software_adapter === true && s.buffer_limit_mib === 128,
        `software ${s.software_adapter}, buffers up to ${s.buffer_limit_mib} MiB`);
      // Teapot, torus, sphere, (2, 5) B-spline, loft, revolution: 32 + 16 + 8 + 16 + 4 + 8 patches.
      assert(s.objects === 6, `objects ${s.objects}`);
      assert(s.patches === 84, `patches ${s.patches}`);
      assert(s.segments.length === 6 && s.segments[0] === 12, `segments ${s.segments}`);
      // Tessellated for the view: the GPU's statistics arrive after the first pass.
      assert(s.tessellation === 'adaptive', `tessellation ${s.tessellation}`);
      assert(s.patches_reevaluated === 84, `the first pass measures everything: ${s.patches_reevaluated}`);
      await page.waitForFunction(() => window.knotwork.status().visible_patches !== null, null, { timeout: 30_000 });
      s = await status(page);
      assert(s.visible_patches >= 1 && s.visible_patches <= 84, `visible ${s.visible_patches}`);
      assert(s.vertices >= 9 * s.visible_patches && s.triangles >= 4 * s.visible_patches,
        `${s.vertices} vertices, ${s.triangles} triangles for ${s.visible_patches} patches`);
      assert(s.adaptive_coarsening === 0, `coarsened ${s.adaptive_coarsening}`);
      console.log(`      adaptive: ${s.visible_patches} of 84 patches visible, ${s.vertices} vertices, ${s.triangles} triangles`);
      // The fixed tessellation: every object's own segments.
      await page.evaluate(() => window.knotwork.setTessellation(false, 0.5));
      await page.waitForFunction(() => window.knotwork.status().tessellation === 'fixed', null, { timeout: 30_000 });
      s = await status(page);
      assert(s.vertices === 32 * 13 * 13 + 52 * 17 * 17, `vertices ${s.vertices} at ${s.segments}`);
      assert(s.triangles === 32 * 12 * 12 * 2 + 52 * 16 * 16 * 2, `triangles ${s.triangles}`);
      await page.evaluate(() => window.knotwork.setTessellation(true, 0.5));
      await page.waitForFunction(() => window.knotwork.status().tessellation === 'adaptive', null, { timeout: 30_000 });

      // Redraw continuously, then wait for frames and measure the frame rate.
      await page.evaluate(() => window.knotwork.setContinuous(true));
      await page.waitForFunction(() => window.knotwork.status().frames > 2, null, { timeout: 60_000 });
      const before = await status(page);
      const t0 = Date.now();
      // At least 3 s, and until a frame has come (SwiftShader draws about one in 3 s here).
      await page.waitForTimeout(3000);
      await page.waitForFunction((f) => window.knotwork.status().frames > f, before.frames, { timeout: 60_000 })
        .catch(() => {});
      const after = await status(page);
      const fps = ((after.frames - before.frames) * 1000) / (Date.now() - t0);
      console.log(`      adapter "${after.adapter}", ${after.vertices} vertices, ${fps.toFixed(1)} frames/s, ` +
        `GPU evaluate ${after.gpu_eval_ms ?? 'n/a'} ms, draw ${after.gpu_render_ms ?? 'n/a'} ms`);
      assert(after.frames > before.frames, 'frames keep coming while redrawing continuously');
      await page.evaluate(() => window.knotwork.setContinuous(false));

      // The canvas shows the teapot: the viewport (right of the 250 px panel) is not blank.
      const png = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/teapot.png`, png);
      const viewport = { x: 320, y: 100, width: 900, height: 600 };
      const stats = await screenshotStats(page, png, viewport, [33, 36, 41], 12);
      console.log(`      ${stats.differing} of ${stats.total} viewport pixels differ from the background`);
      assert(stats.differing > 0.03 * stats.total, `the viewport looks blank (${stats.differing} px differ)`);
      assert(stats.differing < 0.9 * stats.total, `the viewport is not the scene (${stats.differing} px differ)`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('tessellation changes re-run the compute pass; absurd levels are refused', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      await page.evaluate(() => window.knotwork.setTessellation(true, 100));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 30_000 });
      let s = await status(page);
      assert(/tolerance/.test(s.error) && s.tessellation === 'adaptive', `refused: ${JSON.stringify(s)}`);
      await page.evaluate(() => window.knotwork.setTessellation(false, 0.5));
      await page.waitForFunction(() => window.knotwork.status().tessellation === 'fixed', null, { timeout: 30_000 });
      await page.evaluate(() => window.knotwork.setSegments(8));
      await page.waitForFunction(() => window.knotwork.status().segments.every((n) => n === 8), null, { timeout: 30_000 });
      s = await status(page);
      assert(s.vertices === 84 * 9 * 9 && s.error === null, JSON.stringify(s));
      const framesBefore = s.frames;
      await page.evaluate(() => window.knotwork.setSegments(100000));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 30_000 });
      s = await status(page);
      assert(/segments/.test(s.error), `error names the problem: ${s.error}`);
      assert(s.segments.every((n) => n === 8) && s.vertices === 84 * 9 * 9, `the model is unchanged: ${JSON.stringify(s)}`);
      await page.evaluate(() => window.knotwork.setQuality(2));
      await page.waitForFunction(() => window.knotwork.status().segments.every((n) => n === 16), null, { timeout: 30_000 });
      s = await status(page);
      assert(s.vertices === 84 * 17 * 17 && s.frames > framesBefore && s.error === null, JSON.stringify(s));
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('curvature shading comes from the compute pass; an edit re-evaluates only its support', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const viewport = { x: 320, y: 100, width: 900, height: 600 };
      const plain = await page.locator('#knotwork-canvas').screenshot();
      assert(await page.evaluate(() => window.knotwork.setShading('gaussian')), 'gaussian is a mode');
      const rainbow = await thrownBy(page, () => window.knotwork.setShading('rainbow'));
      assert(/setShading: mode must be one of .*got "rainbow"/.test(rainbow ?? ''), `unknown modes are refused: ${rainbow}`);
      await page.waitForFunction(() => window.knotwork.status().shading === 'gaussian', null, { timeout: 30_000 });
      let s = await status(page);
      assert(s.range_auto && s.range && s.range[0] < s.range[1], `automatic range ${JSON.stringify(s.range)}`);
      await page.waitForTimeout(500);
      const gaussian = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/gaussian.png`, gaussian);
      const stats = await screenshotStats(page, gaussian, viewport, [33, 36, 41], 12);
      assert(stats.differing > 0.03 * stats.total, `the curvature view looks blank (${stats.differing} px)`);
      assert(Buffer.compare(plain, gaussian) !== 0, 'the gaussian view differs from the plain one');
      await page.evaluate(() => window.knotwork.setRange(-0.5, 0.5));
      await page.waitForFunction(() => !window.knotwork.status().range_auto, null, { timeout: 30_000 });
      s = await status(page);
      assert(s.range[0] === -0.5 && s.range[1] === 0.5, `manual range ${JSON.stringify(s.range)}`);

      // Control point (4, 4) of the (2, 5) B-spline (object 3, 7 x 9 points): its support covers
      // 8 of the sheet's 16 Bezier patches; with the fixed tessellation nothing else is
      // re-evaluated.
      await page.evaluate(() => window.knotwork.setTessellation(false, 0.5));
      await page.waitForFunction(() => window.knotwork.status().tessellation === 'fixed', null, { timeout: 30_000 });
      await page.evaluate(() => window.knotwork.moveControlPoint(3, 4 * 9 + 4, [1.0, 5.0, 3.0]));
      await page.waitForFunction(() => window.knotwork.status().points_uploaded > 0, null, { timeout: 30_000 });
      await page.waitForFunction(() => window.knotwork.status().patches_reevaluated === 8, null, { timeout: 30_000 });
      s = await status(page);
      assert(s.error === null, `error after the edit: ${s.error}`);
      // A script's drag of the same point takes the mouse's path: each step re-evaluates the
      // same 8 patches, and the end is one undo step.
      const stepsBefore = s.undo_steps;
      await page.evaluate(() => {
        window.knotwork.beginDrag(3, [4 * 9 + 4]);
        window.knotwork.dragBy([0, 0, 0.5]);
      });
      await page.waitForFunction(() => window.knotwork.status().dragging, null, { timeout: 30_000 });
      s = await status(page);
      assert(s.patches_in_drag === 8 && s.error === null, `drag step: ${s.patches_in_drag} patches, ${s.error}`);
      await page.evaluate(() => window.knotwork.endDrag());
      await page.waitForFunction(() => !window.knotwork.status().dragging, null, { timeout: 30_000 });
      s = await status(page);
      assert(s.undo_steps === stepsBefore + 1, `the drag is one undo step (${stepsBefore} -> ${s.undo_steps})`);
      const dragged = (await page.evaluate(() => window.knotwork.project())).objects[3].points[4][4];
      assert(Math.abs(dragged[0] - 1) < 1e-12 && Math.abs(dragged[1] - 5) < 1e-12 && Math.abs(dragged[2] - 3.5) < 1e-12,
        `the dragged point went from (1, 5, 3) by (0, 0, 0.5) to ${JSON.stringify(dragged)}`);
      // A NaN coordinate is refused at the call and changes nothing.
      const nan = await thrownBy(page, () => window.knotwork.moveControlPoint(3, 0, [NaN, 0, 0]));
      assert(/position must be an array of three finite numbers/.test(nan ?? ''), `the error names the problem: ${nan}`);
      const unchanged = (await page.evaluate(() => window.knotwork.project())).objects[3].points[0][0];
      assert(unchanged.every(Number.isFinite), `the point is unchanged: ${JSON.stringify(unchanged)}`);
      console.log(`      range ${JSON.stringify(s.range)}, ${s.patches_reevaluated} patches re-evaluated after the edit`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('every analysis mode draws per pixel, views switch, continuity is measured (triangular patches too)', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      let previous = await page.locator('#knotwork-canvas').screenshot();
      for (const mode of ['zebra', 'isophotes', 'reflection', 'draft', 'mean']) {
        const frames = (await status(page)).frames;
        assert(await page.evaluate((m) => window.knotwork.setShading(m), mode), `${mode} is a mode`);
        await page.waitForFunction((m) => window.knotwork.status().shading === m, mode, { timeout: 30_000 });
        await page.waitForFunction((f) => window.knotwork.status().frames > f, frames, { timeout: 120_000 });
        // The frame after the one that saw the change is on the canvas.
        const shown = (await status(page)).frames;
        await page.evaluate(() => window.knotwork.setContinuous(true));
        await page.waitForFunction((f) => window.knotwork.status().frames > f, shown, { timeout: 120_000 });
        await page.evaluate(() => window.knotwork.setContinuous(false));
        const shot = await page.locator('#knotwork-canvas').screenshot();
        await writeFile(`${resultsDir}/mode-${mode}.png`, shot);
        assert(Buffer.compare(previous, shot) !== 0, `${mode} changes the canvas`);
        previous = shot;
      }
      let refused = null;
      try {
        await page.evaluate(() => window.knotwork.setAnalysis({ zebra_pairs: 0 }));
      } catch (e) {
        refused = String(e);
      }
      assert(refused && /zebra_pairs/.test(refused), `out-of-range settings are refused: ${refused}`);
      await page.evaluate(() => window.knotwork.setShading('zebra'));
      await page.evaluate(() => window.knotwork.setAnalysis({ zebra_pairs: 12, continuity: true }));
      await page.waitForFunction(() => window.knotwork.status().continuity !== null, null, { timeout: 60_000 });
      const c = (await status(page)).continuity;
      assert(c.edges > 40 && c.verdicts.length === c.edges, `continuity ${JSON.stringify(c).slice(0, 200)}`);
      // Neighbouring boundaries of one object (the teapot's rim, its lid's rings) are not edges.
      assert(!c.verdicts.includes('open'), `no open edge in the sample scene: ${JSON.stringify(c.verdicts)}`);
      for (const view of ['top', 'front', 'right', 'perspective']) {
        assert(await page.evaluate((v) => window.knotwork.setView(v), view), `${view} is a view`);
        await page.waitForFunction((v) => window.knotwork.status().view === v, view, { timeout: 30_000 });
        const s = await status(page);
        assert(s.orthographic === (view !== 'perspective'), `${view}: orthographic ${s.orthographic}`);
      }
      const sideways = await thrownBy(page, () => window.knotwork.setView('sideways'));
      assert(/setView: name must be one of .*got "sideways"/.test(sideways ?? ''), `unknown views are refused: ${sideways}`);
      const s = await status(page);
      assert(s.grid_step > 0, `grid step ${s.grid_step}`);
      // Two quadratic triangular patches either side of x = 0, the right one rising at slope
      // 0.4: one shared edge, a crease (G0), measured through the one surface interface.
      const flatTriangle = (u, v, w, f) => {
        const points = [];
        for (let j = 0; j <= 2; j++) {
          for (let i = 0; i <= 2 - j; i++) {
            const k = 2 - i - j;
            const x = (i * u[0] + j * v[0] + k * w[0]) / 2;
            const y = (i * u[1] + j * v[1] + k * w[1]) / 2;
            points.push([x, y, f(x)]);
          }
        }
        return { type: 'triangular_bezier', degree: 2, points };
      };
      await page.evaluate((t) => window.knotwork.openProject('triangles.json', t), JSON.stringify({
        format: 'knotwork', version: 2, objects: [
          flatTriangle([0, 0], [0, 1], [-1, 0], () => 0),
          flatTriangle([0, 1], [0, 0], [1, 0], (x) => 0.4 * x),
        ],
      }));
      await page.waitForFunction(() => window.knotwork.status().objects === 2, null, { timeout: 60_000 });
      await page.waitForFunction(() => window.knotwork.status().continuity?.edges === 1, null, { timeout: 60_000 });
      const t = (await status(page)).continuity;
      assert(t.verdicts[0] === 'G0', `triangles' edge ${JSON.stringify(t)}`);
      console.log(`      ${c.edges} shared edges, ${c.passing} meet G1; grid step ${s.grid_step}; two triangular patches: ${t.verdicts[0]}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('drag a control point with the mouse, undo with Ctrl+Z, reload finds the autosave; New is undone and its work is in Recent after a reload', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const canvas = await page.locator('#knotwork-canvas').boundingBox();
      await page.evaluate(() => window.knotwork.select(3));
      await page.waitForFunction(() => window.knotwork.status().selected === 3, null, { timeout: 30_000 });
      await nextFrames(page);
      // A handle of the (2, 5) B-spline inside the viewport with no other handle within 20 px.
      const handles = await page.evaluate(() => window.knotwork.handles());
      const free = handles.map((h, k) => [k, h]).filter(([, h]) => h && h[0] > 450 && h[0] < 1200 && h[1] > 100 && h[1] < 700)
        .find(([k, h]) => handles.every((q, j) => j === k || !q || Math.hypot(q[0] - h[0], q[1] - h[1]) > 20));
      assert(free, `no free handle on screen: ${JSON.stringify(handles)}`);
      const [index, [hx, hy]] = free;
      const [x, y] = [canvas.x + hx, canvas.y + hy];
      const pointOf = (project) => project.objects[3].points[Math.floor(index / 9)][index % 9];
      const original = pointOf(await page.evaluate(() => window.knotwork.project()));

      // Click selects the point; this is the picture to come back to.
      const clickStart = Date.now();
      await page.mouse.click(x, y);
      await page.waitForFunction((i) => window.knotwork.status().selected_points.join() === String(i), index, { timeout: 30_000 });
      const pickMs = Date.now() - clickStart;
      await nextFrames(page);
      const viewport = VIEWPORT;
      const before = await page.locator('#knotwork-canvas').screenshot();

      // Drag it with real mouse events.
      const dragMs = await dragWithMouse(page, x, y, 8, 8, -6);
      console.log(`      pick (click to selection) ${pickMs} ms; drag-to-new-frame median ${dragMs[dragMs.length >> 1]} ms ` +
        `(of ${dragMs.join(', ')} ms) on SwiftShader`);
      await page.waitForFunction(() => {
        const s = window.knotwork.status();
        return s.undo_steps === 1 && !s.dragging;
      }, null, { timeout: 30_000 });
      let s = await status(page);
      assert(s.error === null, `error after the drag: ${s.error}`);
      const dragged = pointOf(await page.evaluate(() => window.knotwork.project()));
      assert(JSON.stringify(dragged) !== JSON.stringify(original), `the point moved: ${dragged} vs ${original}`);
      await nextFrames(page);
      const moved = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/dragged.png`, moved);
      const change = await screenshotDifference(page, before, moved, viewport, 24);
      console.log(`      point ${index} moved from ${original.slice(0, 3)} to ${dragged.slice(0, 3)}; ${change.differing} px changed`);
      assert(change.differing > 500, `the canvas changed with the drag (${change.differing} px)`);

      // Ctrl+Z: the original pixels come back (within a tolerance).
      await page.keyboard.press('Control+z');
      await page.waitForFunction(() => window.knotwork.status().redo_steps === 1, null, { timeout: 30_000 });
      await nextFrames(page);
      const undone = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/undone.png`, undone);
      const back = await screenshotDifference(page, before, undone, viewport, 24);
      assert(back.differing < 0.002 * back.total, `undo restores the picture (${back.differing} px differ)`);
      assert(JSON.stringify(pointOf(await page.evaluate(() => window.knotwork.project()))) === JSON.stringify(original), 'undo restores the point');

      // Redo, let the autosave write, reload: the edit is still there.
      await page.keyboard.press('Control+Shift+z');
      await page.waitForFunction(() => {
        const s = window.knotwork.status();
        return s.undo_steps === 1 && s.autosaved_revision === s.revision;
      }, null, { timeout: 30_000 });
      await page.reload();
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      s = await status(page);
      assert(/restored/.test(s.notice ?? ''), `notice after reload: ${s.notice}`);
      const reloaded = pointOf(await page.evaluate(() => window.knotwork.project()));
      assert(JSON.stringify(reloaded) === JSON.stringify(dragged), `the autosave kept the edit: ${reloaded} vs ${dragged}`);

      // New throws nothing away: it is an undo step, and the work it replaced is in the
      // Recent list, also after the autosave has written the new document and the page reloads.
      const work = await page.evaluate(() => window.knotwork.project());
      await page.evaluate(() => window.knotwork.newDocument({ empty: true }));
      await page.waitForFunction(() => window.knotwork.status().objects === 0, null, { timeout: 30_000 });
      s = await status(page);
      assert(s.undo_steps === 1 && s.last_edit === 'new empty scene', `new: ${JSON.stringify([s.undo_steps, s.last_edit])}`);
      assert(s.recent.length === 1 && /6 objects/.test(s.recent[0]), `recent: ${JSON.stringify(s.recent)}`);
      await page.keyboard.press('Control+z');
      await page.waitForFunction(() => window.knotwork.status().objects === 6, null, { timeout: 30_000 });
      assert(JSON.stringify(await page.evaluate(() => window.knotwork.project())) === JSON.stringify(work), 'undo brings the work back');
      await page.evaluate(() => window.knotwork.redo());
      await page.waitForFunction(() => {
        const s = window.knotwork.status();
        return s.objects === 0 && s.autosaved_revision === s.revision;
      }, null, { timeout: 30_000 });
      await page.reload();
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      s = await status(page);
      assert(s.objects === 0 && s.recent.length === 1, `after reload: ${JSON.stringify([s.objects, s.recent])}`);
      await page.evaluate(() => window.knotwork.openRecent(0));
      await page.waitForFunction(() => window.knotwork.status().objects === 6, null, { timeout: 30_000 });
      assert(JSON.stringify(await page.evaluate(() => window.knotwork.project())) === JSON.stringify(work), 'Recent opens the work again');
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('a broken project file is refused with its reason; the document stays', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const before = await page.evaluate(() => window.knotwork.project());
      await page.evaluate(() => window.knotwork.openProject('zero.json', JSON.stringify({
        format: 'knotwork', version: 2, objects: [{ type: 'nurbs_surface', degree: [1, 1],
          knots: [[0, 0, 1, 1], [0, 0, 1, 1]], points: [[[0, 0, 0, 1], [0, 1, 0, 0]], [[1, 0, 0, 1], [1, 1, 0, 1]]] }],
      })));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 30_000 });
      const s = await status(page);
      assert(/zero\.json: objects\[0\]\.points\[0\]\[1\]: weight 0/.test(s.error), `error: ${s.error}`);
      assert(JSON.stringify(await page.evaluate(() => window.knotwork.project())) === JSON.stringify(before), 'the document is unchanged');
      assert(s.objects === 6, `objects ${s.objects}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('glTF export from the page passes the Khronos validator and reopens; an OBJ opens as a mesh', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const before = await page.evaluate(() => window.knotwork.project());
      // Timed in the page from the call to the promise's bytes (the editor builds one object
      // per frame, so this includes the frames between): the first call (V8 runs new
      // WebAssembly in its baseline compiler and moves hot functions to the optimizing one
      // after some calls) and the median of calls 6 to 15. The bytes travel to node as base64.
      const exported = await page.evaluate(async () => {
        const times = [];
        let glb;
        for (let k = 0; k < 15; k++) {
          const started = performance.now();
          glb = await window.knotwork.exportGlb({ curvature: true, colors: 'mean' });
          times.push(performance.now() - started);
        }
        const first = times[0];
        const steady = times.slice(5).sort((a, b) => a - b);
        const ms = { first, steady: (steady[4] + steady[5]) / 2 };
        let text = '';
        for (let k = 0; k < glb.length; k += 0x8000) {
          text += String.fromCharCode(...glb.subarray(k, k + 0x8000));
        }
        return { ms, base64: btoa(text) };
      });
      const bytes = new Uint8Array(Buffer.from(exported.base64, 'base64'));
      const exportMs = `${exported.ms.steady.toFixed(1)} ms (median of calls 6–15; the first call ${exported.ms.first.toFixed(0)} ms)`;
      const report = summary('page.glb', await validate(bytes, 'page.glb'));
      assert(report.errors === 0 && report.warnings === 0, `validator: ${JSON.stringify(report)}`);
      await page.evaluate(() => window.knotwork.openFile('cube.obj', new TextEncoder().encode(
        'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n' +
        'f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n')));
      await page.waitForFunction(() => window.knotwork.status().objects === 1, null, { timeout: 30_000 });
      const cube = await status(page);
      assert(cube.patches === 6 && cube.error === null, `cube: ${JSON.stringify(cube)}`);
      await page.evaluate((b) => window.knotwork.openFile('page.glb',
        Uint8Array.from(atob(b), (c) => c.charCodeAt(0))), exported.base64);
      await page.waitForFunction(() => window.knotwork.status().objects === 6, null, { timeout: 30_000 });
      const reopened = await page.evaluate(() => window.knotwork.project());
      assert(JSON.stringify(reopened.objects) === JSON.stringify(before.objects), 'the glb reopens as the same model');
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      const wasmBytes = (await stat(new URL('./pkg/knotwork_bg.wasm', import.meta.url))).size;
      console.log(`  export in the page: ${bytes.length} bytes in ${exportMs}, with curvature and colours ` +
        `(native, without frames: knotwork bench --only export, "as the page's exportGlb does"), ${report.infos} validator infos; wasm bundle ${wasmBytes} bytes`);
      await page.close();
    });

    await check('glTF export in the page with its grids from the GPU: the CPU\'s triangles, positions within f32 precision, valid', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      // SwiftShader is a software adapter, where the export's default is the kernel;
      // `backend: 'gpu'` asks for the compute shaders' grids, read back between frames.
      const timed = async (backend) => {
        const started = Date.now();
        const glb = await exportGlbBytes(page, { tolerance: 0.002, curvature: true, backend });
        return { glb, ms: Date.now() - started };
      };
      const gpu = await timed('gpu');
      const cpu = await timed('cpu');
      const auto = await timed(undefined);
      const report = summary('page-gpu.glb', await validate(gpu.glb, 'page-gpu.glb'));
      assert(report.errors === 0 && report.warnings === 0, `validator: ${JSON.stringify(report)}`);
      assert(Buffer.compare(Buffer.from(auto.glb), Buffer.from(cpu.glb)) === 0, 'on a software adapter the default is the kernel');
      assert(Buffer.compare(Buffer.from(gpu.glb), Buffer.from(cpu.glb)) !== 0, 'the GPU\'s grids are not the kernel\'s');
      const [a, b] = [glbJson(gpu.glb), glbJson(cpu.glb)];
      assert(a.meshes.length === 6 && b.meshes.length === 6, `meshes ${a.meshes.length}, ${b.meshes.length}`);
      let worst = 0;
      let vertices = 0;
      for (let m = 0; m < a.meshes.length; m += 1) {
        for (let p = 0; p < a.meshes[m].primitives.length; p += 1) {
          const [pa, pb] = [a.meshes[m].primitives[p], b.meshes[m].primitives[p]];
          const [ia, ib] = [glbAccessorBytes(gpu.glb, pa.indices), glbAccessorBytes(cpu.glb, pb.indices)];
          assert(a.accessors[pa.indices].count === b.accessors[pb.indices].count, `mesh ${m}: the same triangles`);
          assert(Buffer.compare(Buffer.from(ia), Buffer.from(ib)) === 0, `mesh ${m}: the same indices`);
          const [xa, xb] = [glbFloats(gpu.glb, pa.attributes.POSITION), glbFloats(cpu.glb, pb.attributes.POSITION)];
          const lo = b.accessors[pb.attributes.POSITION].min;
          const hi = b.accessors[pb.attributes.POSITION].max;
          const size = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
          for (let k = 0; k < xb.length; k += 3) {
            const d = Math.hypot(xa[k] - xb[k], xa[k + 1] - xb[k + 1], xa[k + 2] - xb[k + 2]);
            worst = Math.max(worst, d / size);
          }
          vertices += xb.length / 3;
        }
      }
      assert(worst > 0 && worst < 1e-5, `positions within f32 precision of each object's size: ${worst}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      console.log(`      ${vertices} vertices: the GPU's grids ${gpu.ms} ms, the kernel's ${cpu.ms} ms; largest position difference ${worst.toExponential(2)} of the size`);
      await page.close();
    });

    await check('a STEP file opens in the page as a watertight polysurface drawn by the GPU, exports a valid glTF; a broken one is refused', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const step = await readFile(new URL('../tests/reference/occ/step/box-hole-fillets.step', import.meta.url));
      const base64 = step.toString('base64');
      const openMs = await page.evaluate(async (b) => {
        const bytes = Uint8Array.from(atob(b), (c) => c.charCodeAt(0));
        const started = performance.now();
        window.knotwork.openFile('box-hole-fillets.step', bytes);
        while (window.knotwork.status().objects !== 1 || window.knotwork.status().patches === 0) {
          await new Promise((r) => requestAnimationFrame(r));
          if (performance.now() - started > 60_000) break;
        }
        return performance.now() - started;
      }, base64);
      const opened = await status(page);
      assert(opened.objects === 1 && opened.patches > 0 && opened.error === null, `STEP: ${JSON.stringify(opened)}`);
      const project = await page.evaluate(() => window.knotwork.project());
      assert(project.objects[0].type === 'polysurface' && project.objects[0].faces.length === 11,
        `a polysurface of 11 faces: ${JSON.stringify(project.objects[0]).slice(0, 200)}`);
      assert(project.unit === 'mm', `the project records millimetres: ${project.unit}`);
      const glb = await exportGlbBytes(page, {});
      const report = summary('step.glb', await validate(glb, 'step.glb'));
      assert(report.errors === 0 && report.warnings === 0, `validator: ${JSON.stringify(report)}`);
      // The 40 × 30 × 20 mm box is 0.04 × 0.02 × 0.03 m in glTF's Y-up metres.
      const json = glbJson(glb);
      const position = json.accessors[json.meshes[0].primitives[0].attributes.POSITION];
      const size = position.max.map((hi, k) => hi - position.min[k]);
      assert([0.04, 0.02, 0.03].every((want, k) => Math.abs(size[k] - want) < 1e-6), `glTF size in metres: ${size}`);
      // Export → STEP in the page writes every face.
      const written = await page.evaluate(() => window.knotwork.exportStep());
      const faces = (written.match(/ADVANCED_FACE\(/g) || []).length;
      assert(written.startsWith('ISO-10303-21;') && faces === 11, `exportStep: ${faces} faces, ${written.slice(0, 40)}`);
      // The box written by the page opens again with all 11 faces (its fillets and the hole's
      // cylinder are B-spline faces now, read through their p-curves), as one closed body.
      const boxAgain = await page.evaluate(async (text) => {
        const frames = async (test) => {
          for (let k = 0; k < 600 && !test(); k += 1) await new Promise((r) => requestAnimationFrame(r));
        };
        window.knotwork.newDocument({ empty: true });
        await frames(() => window.knotwork.status().objects === 0);
        window.knotwork.openFile('box-again.step', new TextEncoder().encode(text));
        await frames(() => window.knotwork.status().objects === 1 && window.knotwork.status().open_progress == null);
        const s = window.knotwork.status();
        return { objects: s.objects, error: s.error, faces: window.knotwork.project().objects[0]?.faces.length };
      }, written);
      assert(boxAgain.objects === 1 && boxAgain.faces === 11 && boxAgain.error === null, `the box written and opened again: ${JSON.stringify(boxAgain)}`);
      // The coloured two-part assembly written by the page opens again with both parts, all
      // their faces and their colours.
      const assembly = await readFile(new URL('../tests/reference/occ/step/assembly.step', import.meta.url));
      const reopened = await page.evaluate(async (b) => {
        const frames = async (test) => {
          for (let k = 0; k < 600 && !test(); k += 1) await new Promise((r) => requestAnimationFrame(r));
        };
        window.knotwork.openFile('assembly.step', Uint8Array.from(atob(b), (c) => c.charCodeAt(0)));
        await frames(() => window.knotwork.status().objects === 2);
        const first = window.knotwork.project();
        const text = await window.knotwork.exportStep();
        window.knotwork.newDocument({ empty: true });
        await frames(() => window.knotwork.status().objects === 0);
        window.knotwork.openFile('again.step', new TextEncoder().encode(text));
        await frames(() => window.knotwork.status().objects === 2);
        return [first, window.knotwork.project()];
      }, assembly.toString('base64'));
      const shape = (p) => JSON.stringify(p.objects.map((o) => [o.faces.length, o.color]));
      assert(reopened[0].objects.length === 2 && reopened[0].objects.every((o) => o.color && o.faces.length === 6),
        `the assembly: ${shape(reopened[0])}`);
      assert(shape(reopened[1]) === shape(reopened[0]) && reopened[1].unit === 'mm',
        `written and opened again: ${shape(reopened[1])} vs ${shape(reopened[0])}`);
      // Subdivision surfaces whose faces do not nest (Doo-Sabin on a cube cage, √3 on an
      // octahedron) are written as patches and open again as two closed bodies.
      const corner = (k) => [k & 4 ? 10 : -10, k & 2 ? 10 : -10, k & 1 ? 10 : -10];
      const cubeFaces = [[0, 2, 6, 4], [1, 5, 7, 3], [0, 4, 5, 1], [2, 3, 7, 6], [0, 1, 3, 2], [4, 6, 7, 5]];
      const octahedronPoints = [[12, 0, 0], [-12, 0, 0], [0, 12, 0], [0, -12, 0], [0, 0, 12], [0, 0, -12]];
      const octahedronFaces = [];
      for (const x of [0, 1]) {
        for (const y of [2, 3]) {
          for (const z of [4, 5]) {
            // Turned to face outwards: (b − a) × (c − a) along a + b + c.
            const [a, b, c] = [x, y, z].map((i) => octahedronPoints[i]);
            const u = b.map((v, k) => v - a[k]);
            const w = c.map((v, k) => v - a[k]);
            const n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
            const out = n.reduce((sum, v, k) => sum + v * (a[k] + b[k] + c[k]), 0) > 0;
            octahedronFaces.push(out ? [x, y, z] : [x, z, y]);
          }
        }
      }
      const subdivided = await page.evaluate(async (text) => {
        const frames = async (test) => {
          for (let k = 0; k < 600 && !test(); k += 1) await new Promise((r) => requestAnimationFrame(r));
        };
        window.knotwork.newDocument({ empty: true });
        await frames(() => window.knotwork.status().objects === 0);
        window.knotwork.openProject('subdivided.json', text);
        await frames(() => window.knotwork.status().objects === 2);
        const written = await window.knotwork.exportStep();
        window.knotwork.newDocument({ empty: true });
        await frames(() => window.knotwork.status().objects === 0);
        window.knotwork.openFile('subdivided.step', new TextEncoder().encode(written));
        await frames(() => window.knotwork.status().objects === 2 && window.knotwork.status().open_progress == null);
        const count = (pattern) => (written.match(pattern) || []).length;
        return {
          written: count(/ADVANCED_FACE\(/g),
          closed: count(/CLOSED_SHELL\(/g),
          error: window.knotwork.status().error,
          faces: window.knotwork.project().objects.map((o) => o.faces.length),
        };
      }, JSON.stringify({
        format: 'knotwork', version: 2, objects: [
          { type: 'subdivision_surface', name: 'Doo-Sabin cube', scheme: 'doo-sabin', level: 2,
            points: [...Array(8).keys()].map(corner), faces: cubeFaces },
          { type: 'subdivision_surface', name: '√3 octahedron', scheme: 'sqrt3', level: 2,
            points: octahedronPoints, faces: octahedronFaces },
        ],
      }));
      assert(subdivided.closed === 2 && subdivided.error === null && subdivided.faces.length === 2
        && subdivided.faces.every((f) => f > 0) && subdivided.faces[0] + subdivided.faces[1] === subdivided.written,
        `Doo-Sabin and √3 written and opened again: ${JSON.stringify(subdivided)}`);
      await page.evaluate((b) => window.knotwork.openFile('box-hole-fillets.step', Uint8Array.from(atob(b), (c) => c.charCodeAt(0))), base64);
      await page.waitForFunction(() => window.knotwork.status().objects === 1 && window.knotwork.project().objects[0].faces.length === 11, null, { timeout: 60_000 });
      const before = await page.evaluate(() => window.knotwork.project());
      await page.evaluate((b) => window.knotwork.openFile('cut.step',
        Uint8Array.from(atob(b), (c) => c.charCodeAt(0)).subarray(0, 20000)), base64);
      await page.waitForFunction(() => /STEP|ISO-10303-21|truncated/.test(window.knotwork.status().error ?? ''), null, { timeout: 30_000 })
        .catch(async () => { throw new Error(`a truncated STEP file: ${(await status(page)).error}`); });
      const after = await page.evaluate(() => window.knotwork.project());
      assert(JSON.stringify(after) === JSON.stringify(before), 'the document is unchanged');
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      console.log(`      STEP (11 faces, ${step.length} bytes) opened and drawn in ${openMs.toFixed(0)} ms; export ${glb.length} bytes, validator clean; exportStep ${written.length} bytes, reopened; Doo-Sabin and √3 written as ${subdivided.faces.join(' + ')} faces in two closed shells, reopened`);
      await page.close();
    });

    await check('a large STEP file opens over many frames with a progress bar, and Cancel keeps the document', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      // OpenCASCADE's plate of 20 × 20 filleted holes: 806 faces, 2.8 MB.
      const plate = await readFile(new URL('../tests/reference/occ/step/plate-20.step', import.meta.url));
      await page.evaluate(() => window.knotwork.setContinuous(true));
      await installPageHelpers(page);
      const opened = await page.evaluate(async (b) => {
        const bytes = Uint8Array.from(atob(b), (c) => c.charCodeAt(0));
        const waitFor = (test, limit) => window.__waitFor(test, limit, 'open_progress');
        const before = JSON.stringify(window.knotwork.project());
        // Cancel once the progress bar shows.
        window.knotwork.openFile('plate-20.step', bytes);
        const shown = await waitFor(() => (window.knotwork.status().open_progress ?? 0) > 0.05, 60_000);
        window.knotwork.cancelOpen();
        await waitFor(() => window.knotwork.status().open_progress === null, 10_000);
        const unchanged = JSON.stringify(window.knotwork.project()) === before;
        // Open it to the end.
        const started = performance.now();
        window.knotwork.openFile('plate-20.step', bytes);
        const open = await waitFor(() => window.knotwork.status().open_progress === null && window.knotwork.status().objects === 1, 120_000);
        const drawn = await waitFor(() => window.knotwork.status().patches > 0, 60_000);
        const faces = window.knotwork.project().objects[0].faces.length;
        // The same work all at once, timed inside the page (what the native bench prints).
        const timing = window.knotwork.benchStepOpen(bytes);
        // Read and meshed at 1e-4 of the diagonal (what the native bench compares with
        // OpenCASCADE).
        const mesh = window.knotwork.benchStepMesh(bytes);
        return { shown, unchanged, open, drawnMs: performance.now() - started, faces, timing, mesh };
      }, plate.toString('base64'));
      await page.evaluate(() => window.knotwork.setContinuous(false));
      assert(opened.shown.progress.length > 0 && opened.unchanged, `Cancel: progress ${opened.shown.progress.slice(-1)}, unchanged ${opened.unchanged}`);
      assert(opened.faces === 806, `806 faces: ${opened.faces}`);
      const rising = opened.open.progress.every((p, k, all) => k === 0 || p >= all[k - 1]);
      // The page keeps drawing while the file opens: the work is spread over frames (four
      // times what the rest of the frame took, 30 ms to 1 s of it, starting short and at
      // most doubling; one step, a face, is far shorter), and the progress only rises.
      const t = opened.timing;
      assert(opened.open.frames >= 3 && rising && opened.open.progress.length >= 2, `opened over ${opened.open.frames} frames, progress rising: ${rising}`);
      assert(t.faces === 806 && t.longest_step_ms < 1000, `page timing: ${JSON.stringify(t)}`);
      const m = opened.mesh;
      assert(m.faces === 806 && m.triangles > 100000, `page mesh timing: ${JSON.stringify(m)}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      console.log(`      plate-20 (806 faces, ${plate.length} bytes) opened in the editor in ${opened.open.ms.toFixed(0)} ms over ${opened.open.frames} frames, drawn after ${opened.drawnMs.toFixed(0)} ms (SwiftShader draws each frame); the same open timed in the page: first step ${t.first_step_ms.toFixed(0)} ms, then ${t.steps} steps ${t.steps_ms.toFixed(0)} ms (longest ${t.longest_step_ms.toFixed(1)} ms); cancelled at ${(100 * opened.shown.progress.slice(-1)[0]).toFixed(0)} % with the document unchanged; read ${m.read_ms.toFixed(0)} ms and meshed ${m.mesh_ms.toFixed(0)} ms at ${m.tolerance.toExponential(3)} (${m.triangles} triangles) in the page`);
      await page.close();
    });

    await check('every core in the page: Web Workers on shared memory where the page is isolated, the same bytes as one thread, one thread where it is not', async () => {
      // The same work in the threaded page, in the page asked for one thread, and in a page
      // served without the isolation headers: the plate opened and exported, a Catmull-Clark
      // cage at level 4 (stencil tables) exported, and the plate read and meshed as the
      // bench does.
      const plate = await readFile(new URL('../tests/reference/occ/step/plate-20.step', import.meta.url));
      const run = async (pageUrl) => {
        const { page, errors } = await openEditor(browser, pageUrl);
        await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
        await installPageHelpers(page);
        // SwiftShader rasterizes the first frames on the same cores for a few seconds: the
        // timings start after it is done.
        await page.waitForTimeout(5000);
        const outcome = await page.evaluate(async (b) => {
          const digest = async (bytes) => Array.from(new Uint8Array(await crypto.subtle.digest('SHA-256', bytes)))
            .map((x) => x.toString(16).padStart(2, '0')).join('');
          const bytes = Uint8Array.from(atob(b), (c) => c.charCodeAt(0));
          const threads = window.knotwork.threads();
          // Pure arithmetic on the threads: the best of three.
          const arithmetic = [0, 1, 2].map(() => window.knotwork.benchThreads(400));
          const arithmeticMs = Math.min(...arithmetic.map((a) => a.ms));
          window.knotwork.openFile('plate-20.step', bytes);
          await window.__waitFor(() => window.knotwork.status().open_progress === null && window.knotwork.status().objects === 1, 120_000, 'open_progress');
          let started = performance.now();
          const plateGlb = await window.knotwork.exportGlb({ tolerance: 2e-3 });
          const plateMs = performance.now() - started;
          const points = [];
          for (let k = 0; k < 8; k += 1) points.push([k & 1 ? 1 : -1.3, k & 2 ? 0.9 : -1, k & 4 ? 1.2 : -1]);
          const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
          window.knotwork.openProject('cage.json', JSON.stringify({ format: 'knotwork', version: 2, objects: [{ type: 'subdivision_surface', name: 'cage', points, faces, level: 4 }] }));
          started = performance.now();
          const cageGlb = await window.knotwork.exportGlb({ curvature: true });
          const cageMs = performance.now() - started;
          // Opened as the editor opens it (four faces a thread a step), all at once.
          const opens = [0, 1, 2].map(() => window.knotwork.benchStepOpen(bytes));
          const openMs = Math.min(...opens.map((t) => t.first_step_ms + t.steps_ms));
          const meshes = [0, 1, 2].map(() => window.knotwork.benchStepMesh(bytes));
          const mesh = meshes.reduce((best, m) => (m.mesh_ms < best.mesh_ms ? m : best));
          return {
            threads, isolated: self.crossOriginIsolated, arithmeticMs, openMs, openFaces: opens[0].faces, checksum: arithmetic[0].checksum, plate: await digest(plateGlb), plateBytes: plateGlb.length,
            plateMs, cage: await digest(cageGlb), cageMs, mesh, error: window.knotwork.status().error,
          };
        }, plate.toString('base64'));
        assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
        await page.close();
        return outcome;
      };
      const many = await run(url);
      const one = await run(`${url}?threads=1`);
      const plain = await run(`http://127.0.0.1:${plainServer.address().port}/index.html`);
      const cores = await (await browser.newPage()).evaluate(() => navigator.hardwareConcurrency);
      assert(many.isolated && many.threads === cores && cores >= 2, `threaded page: ${JSON.stringify(many)}, ${cores} cores`);
      assert(one.isolated && one.threads === 1, `?threads=1: ${JSON.stringify(one)}`);
      assert(!plain.isolated && plain.threads === 1, `not isolated: ${JSON.stringify(plain)}`);
      for (const [name, other] of [['one thread', one], ['not isolated', plain]]) {
        assert(other.plate === many.plate && other.cage === many.cage && other.mesh.triangles === many.mesh.triangles
          && other.openFaces === many.openFaces
          && other.checksum === many.checksum,
          `${name}: the exports differ from the threaded page's (${JSON.stringify(other)} against ${JSON.stringify(many)})`);
      }
      assert(many.error === null && one.error === null && plain.error === null, `errors: ${many.error} ${one.error} ${plain.error}`);
      const figures = (o) => `arithmetic ${o.arithmeticMs.toFixed(0)} ms, plate opened ${o.openMs.toFixed(0)} ms, plate export ${o.plateMs.toFixed(0)} ms, cage export ${o.cageMs.toFixed(0)} ms, read ${o.mesh.read_ms.toFixed(0)} + mesh ${o.mesh.mesh_ms.toFixed(0)} ms (best of 3)`;
      console.log(`      ${many.threads} threads (${cores} cores): ${figures(many)}; one thread: ${figures(one)}; not isolated: ${figures(plain)}; exports the same bytes (plate ${many.plateBytes} bytes, sha-256 ${many.plate.slice(0, 12)}…)`);
    });

    await check('an export reads the document just opened, carries curvature for subdivision surfaces, and a tiny tolerance neither freezes nor runs away', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const points = [];
      for (let k = 0; k < 8; k += 1) points.push([k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1]);
      const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
      const cage = (level) => JSON.stringify({ format: 'knotwork', version: 2, objects: [{ type: 'subdivision_surface', name: 'cage', points, faces, level }] });
      // Open a level-4 cage, then a level-3 one, and export at once each time, with no frame
      // between: each export is of the document just opened (Catmull-Clark on a cube: 6 · 4^L
      // quads, 6 · 4^L + 2 limit vertices).
      const exported = await page.evaluate(async ([four, three]) => {
        const base64 = (glb) => {
          let text = '';
          for (let k = 0; k < glb.length; k += 0x8000) text += String.fromCharCode(...glb.subarray(k, k + 0x8000));
          return btoa(text);
        };
        window.knotwork.openProject('four.json', four);
        const a = await window.knotwork.exportGlb({ curvature: true, colors: 'mean' });
        window.knotwork.openProject('three.json', three);
        const b = await window.knotwork.exportGlb({ curvature: true, colors: 'k1' });
        return [base64(a), base64(b)];
      }, [cage(4), cage(3)]);
      for (const [k, level] of [[0, 4], [1, 3]]) {
        const bytes = new Uint8Array(Buffer.from(exported[k], 'base64'));
        const json = glbJson(bytes);
        const attributes = json.meshes[0].primitives[0].attributes;
        const count = (name) => json.accessors[attributes[name]].count;
        const vertices = 6 * 4 ** level + 2;
        assert(count('POSITION') === vertices, `level ${level}: ${count('POSITION')} vertices, not ${vertices}`);
        assert(count('_CURVATURE') === vertices && count('COLOR_0') === vertices, `level ${level}: curvature ${count('_CURVATURE')}, colours ${count('COLOR_0')}`);
        const report = summary(`cage-${level}.glb`, await validate(bytes, `cage-${level}.glb`));
        assert(report.errors === 0 && report.warnings === 0, `validator: ${JSON.stringify(report)}`);
      }

      // A tolerance that would need millions of triangles is refused from the estimate, at
      // once, with a tolerance that would fit; the page keeps drawing.
      await page.evaluate(() => window.knotwork.newDocument());
      await page.waitForFunction(() => window.knotwork.status().objects > 1, null, { timeout: 30_000 });
      const refused = await page.evaluate(async () => {
        const started = performance.now();
        try {
          await window.knotwork.exportGlb({ tolerance: 1e-7 });
          return { message: null };
        } catch (e) {
          return { message: String(e.message ?? e), ms: performance.now() - started };
        }
      });
      assert(/about \d+ triangles/.test(refused.message) && /tolerance of [0-9.e-]+ or more/.test(refused.message), `refused: ${JSON.stringify(refused)}`);
      assert(refused.ms < 5000, `refused in ${refused.ms} ms`);
      // Bad options are refused with the value.
      for (const [options, pattern] of [[{ segments: 0 }, /segments must be a whole number from 1 to \d+, got 0/], [{ tolerance: -1 }, /tolerance must be a number > 0, got -1/], [{ colors: 'red' }, /colors must be/], [{ backend: 'tpu' }, /backend must be auto, gpu or cpu, got "tpu"/]]) {
        const message = await page.evaluate(async (o) => window.knotwork.exportGlb(o).then(() => null, (e) => e.message), options);
        assert(pattern.test(message), `${JSON.stringify(options)}: ${message}`);
      }
      // A long export runs in steps between frames with its progress in the status, and
      // Cancel stops it: the promise says so and nothing is left running.
      const many = [];
      for (let k = 0; k < 20; k += 1) many.push(landscapeObject(6, 8));
      await openObjects(page, many);
      const cancelled = await page.evaluate(async () => {
        const running = window.knotwork.exportGlb({ tolerance: 3e-4 });
        const progress = [];
        for (let frame = 0; frame < 200; frame += 1) {
          await new Promise((r) => requestAnimationFrame(r));
          const p = window.knotwork.status().export_progress;
          if (p !== null) progress.push(p);
          if (p > 0) break;
        }
        window.knotwork.cancelExport();
        const message = await running.then(() => null, (e) => e.message);
        return { progress, message };
      });
      assert(cancelled.progress.some((p) => p > 0 && p < 1), `progress: ${JSON.stringify(cancelled.progress)}`);
      assert(/cancelled/.test(cancelled.message), `cancelled: ${cancelled.message}`);
      await page.waitForFunction(() => window.knotwork.status().export_progress === null, null, { timeout: 30_000 });
      console.log(`      refused 1e-7 in ${refused.ms.toFixed(0)} ms: ${refused.message}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('the script interface refuses every bad argument with a message naming it, and the document stays', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const before = await page.evaluate(() => window.knotwork.project());
      // Refused at the call: the call, the argument and the value are named.
      const thrown = await page.evaluate(() => {
        const calls = [
          ['setSegments', () => window.knotwork.setSegments(-1)],
          ['trimCircle', () => window.knotwork.trimCircle(0, NaN, 0.5, 0.1)],
          ['moveControlPoint', () => window.knotwork.moveControlPoint(0, 0, 'abc')],
          ['moveControlPoint', () => window.knotwork.moveControlPoint(0, 0, [0, Infinity, 0])],
          ['setShading', () => window.knotwork.setShading('bogus')],
          ['select', () => window.knotwork.select(1.5)],
          ['selectPoints', () => window.knotwork.selectPoints([0, -3])],
          ['setRange', () => window.knotwork.setRange(2, 1)],
          ['openFile', () => window.knotwork.openFile('a.obj', 'v 0 0 0')],
          ['setQuality', () => window.knotwork.setQuality('high')],
          ['addLattice', () => window.knotwork.addLattice([0], 0, 2, 2)],
        ];
        return calls.map(([name, call]) => {
          try {
            call();
            return `${name}: accepted`;
          } catch (e) {
            return e.message;
          }
        });
      });
      const expected = [
        /^knotwork\.setSegments: n must be a whole number from 1 .*, got -1$/,
        /^knotwork\.trimCircle: u must be a finite number, got NaN$/,
        /^knotwork\.moveControlPoint: position must be an array of three finite numbers .*, got "abc"$/,
        /^knotwork\.moveControlPoint: position must be .*, got \[0,null,0\]$/,
        /^knotwork\.setShading: mode must be one of 'plain'.*, got "bogus"$/,
        /^knotwork\.select: i must be a whole number .*, got 1\.5$/,
        /^knotwork\.selectPoints: points\[1\] must be a whole number .*, got -3$/,
        /^knotwork\.setRange: hi must be greater than lo \(2\), got 1$/,
        /^knotwork\.openFile: bytes must be a Uint8Array.*, got "v 0 0 0"$/,
        /^knotwork\.setQuality: q must be a finite number, got "high"$/,
        /^knotwork\.addLattice: l must be a whole number from 1 .*, got 0$/,
      ];
      thrown.forEach((message, k) => assert(expected[k].test(message), `call ${k}: ${message}`));
      // Refused by the editor, which alone knows the document: named in status().error.
      const refusedByEditor = [
        [() => window.knotwork.select(99), /no object 99; the scene has 6/],
        [() => window.knotwork.moveControlPoint(3, 99999, [0, 0, 0]), /99999/],
        [() => window.knotwork.moveControlPoint(3, 0, [1e300, 0, 0]), /point 0: the coordinate 1e300 is outside/],
        [() => window.knotwork.setCrease(0, 0, 1, 2), /subdivision|cage/],
      ];
      for (const [call, pattern] of refusedByEditor) {
        await page.evaluate(call);
        await page.waitForFunction((source) => new RegExp(source).test(window.knotwork.status().error ?? ''), pattern.source, { timeout: 30_000 })
          .catch(async () => { throw new Error(`${call}: ${JSON.stringify((await status(page)).error)}`); });
      }
      await page.evaluate(() => window.knotwork.select(3));
      await page.evaluate(() => window.knotwork.selectPoints([99999]));
      await page.waitForFunction(() => /has no point 99999; its points are 0 to 62/.test(window.knotwork.status().error ?? ''), null, { timeout: 30_000 })
        .catch(async () => { throw new Error(`selectPoints: ${(await status(page)).error}`); });
      // A file of a format knotwork does not read says which it is and what it reads.
      for (const [name, format] of [['part.igs', 'IGES'], ['part.3dm', 'Rhino'], ['part.stl', 'STL']]) {
        await page.evaluate((n) => window.knotwork.openFile(n, new TextEncoder().encode('solid x')), name);
        await page.waitForFunction((f) => (window.knotwork.status().error ?? '').includes(f), format, { timeout: 30_000 });
        const message = (await status(page)).error;
        assert(/knotwork does not read; it reads knotwork project/.test(message), `${name}: ${message}`);
      }
      const after = await page.evaluate(() => window.knotwork.project());
      assert(JSON.stringify(after) === JSON.stringify(before), 'the document is unchanged');
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('a subdivision cage in the page: limit stencils on the GPU, a mouse drag, a crease, a cage tool, undo', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const points = [];
      for (let k = 0; k < 8; k += 1) points.push([k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1]);
      const cage = {
        type: 'subdivision_surface', name: 'cage', points, level: 3,
        faces: [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]],
      };
      await openObjects(page, [cage]);
      let s = await status(page);
      // Level 3: each quad's four level-1 quads are grids of 5 x 5 limit stencils.
      assert(s.error === null && s.patches === 24 && s.vertices === 24 * 25, `cage: ${JSON.stringify(s)}`);
      const viewport = VIEWPORT;
      const { index, before } = await dragFirstObjectHandle(page);
      const dragged = await page.evaluate(() => window.knotwork.project());
      assert(JSON.stringify(dragged.objects[0].points[index]) !== JSON.stringify(points[index]), `cage point ${index} moved`);
      await nextFrames(page);
      const moved = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/cage-dragged.png`, moved);
      const change = await screenshotDifference(page, before, moved, viewport, 24);
      assert(change.differing > 200, `the canvas changed with the drag (${change.differing} px)`);

      await page.evaluate(() => window.knotwork.setCrease(0, 0, 1, 10));
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 2, null, { timeout: 30_000 });
      const creased = await page.evaluate(() => window.knotwork.project());
      const creases = creased.objects[0].creases;
      assert(creases.length === 1 && creases[0][2] === 10, `the crease is in the document: ${JSON.stringify(creases)}`);
      await nextFrames(page);
      const sharp = await page.locator('#knotwork-canvas').screenshot();
      const creaseChange = await screenshotDifference(page, moved, sharp, viewport, 24);
      assert(creaseChange.differing > 50, `the canvas changed with the crease (${creaseChange.differing} px)`);
      s = await status(page);
      assert(s.error === null, `error: ${s.error}`);
      // A crease on an edge the cage lacks is refused and changes nothing.
      await page.evaluate(() => window.knotwork.setCrease(0, 0, 7, 2));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 30_000 });
      s = await status(page);
      assert(/edge/.test(s.error) && s.undo_steps === 2, `refused: ${JSON.stringify(s.error)}`);

      await page.evaluate(() => window.knotwork.undo());
      await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 0, null, { timeout: 30_000 });
      const undone = await page.evaluate(() => window.knotwork.project());
      assert(undone.objects[0].points.every((p, k) => p.every((x, c) => x === points[k][c])), 'undo brings the cage back');
      assert(undone.objects[0].creases.length === 0, 'undo removes the crease');

      // A cage tool through the page's operation road: corner 7 rounded in two segments. Its
      // three faces become hexagons and three quads fill the corner, so the level-3 limit has
      // 3 x 4 (the other faces) + 3 x 6 + 3 x 4 = 42 level-1 quads of 5 x 5 stencils; undo
      // gives the cube back.
      await nextFrames(page);
      const cube = await page.locator('#knotwork-canvas').screenshot();
      await page.evaluate(() => window.knotwork.apply({
        op: 'cage', object: 0, tool: { 'bevel-vertices': { vertices: [7], width: 0.6, segments: 2 } },
      }));
      await waitForPatches(page, 42, 'the beveled corner\'s 42 patches', errors);
      s = await status(page);
      assert(s.error === null && s.vertices === 42 * 25, `beveled: ${JSON.stringify(s)}`);
      const rounded = (await page.evaluate(() => window.knotwork.project())).objects[0];
      assert(rounded.points.length === 8 - 1 + 7 && rounded.faces.length === 9, `the rounded corner: ${rounded.points.length} points, ${rounded.faces.length} faces`);
      await nextFrames(page);
      const beveled = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/cage-corner-rounded.png`, beveled);
      const bevelChange = await screenshotDifference(page, cube, beveled, viewport, 24);
      assert(bevelChange.differing > 50, `the canvas changed with the bevel (${bevelChange.differing} px)`);
      await page.evaluate(() => window.knotwork.undo());
      await waitForPatches(page, 24, 'the cube\'s 24 patches after undo', errors);
      console.log(`      cage drag changed ${change.differing} px, the crease ${creaseChange.differing} px, the corner bevel ${bevelChange.differing} px`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('an exception thrown inside the editor\'s WebAssembly says that the editor stopped', async () => {
      const { page } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      // A script's own error is not the editor's.
      await page.evaluate(() => { setTimeout(() => { throw new Error('a script error'); }); });
      await page.waitForTimeout(300);
      let s = await status(page);
      assert(s.error === null, `a script error is not taken for the editor stopping: ${s.error}`);
      // What a trap in a frame throws (here a wait on the page's thread): an error whose stack
      // runs through the module.
      await page.evaluate(() => {
        const error = new TypeError('Atomics.wait cannot be called in this context');
        error.stack = `TypeError: ${error.message}\n    at knotwork_bg.wasm.f (wasm://wasm/knotwork-1a2b:wasm-function[42]:0x1f)`;
        window.dispatchEvent(new ErrorEvent('error', { error, message: `Uncaught ${error}` }));
      });
      s = await status(page);
      assert(/^the editor stopped: .*Atomics\.wait/.test(s.error), `status error: ${s.error}`);
      const shown = await page.locator('#message').textContent();
      assert(await page.locator('#message').isVisible() && /The editor stopped.*reload/s.test(shown), `the page says so: ${shown}`);
      await page.close();
    });

    await check('efficient substitutes in the page: Gregory and ACC patches, PN triangles on the GPU, a mouse drag, undo', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const points = [];
      for (let k = 0; k < 8; k += 1) points.push([k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1]);
      const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
      const cage = (display) => ({ type: 'subdivision_surface', name: display, points, faces, level: 3, display });
      // Every face of the cube has valence-3 corners: one substitute patch of 8 x 8 segments each.
      await openObjects(page, [cage('acc')]);
      let s = await status(page);
      assert(s.error === null && s.patches === 6 && s.vertices === 6 * 81, `ACC: ${JSON.stringify(s)}`);
      await openObjects(page, [cage('gregory')]);
      await page.waitForFunction(() => window.knotwork.project().objects[0].display === 'gregory', null, { timeout: 60_000 });
      await nextFrames(page);
      s = await status(page);
      assert(s.error === null && s.patches === 6 && s.vertices === 6 * 81, `Gregory: ${JSON.stringify(s)}`);
      const viewport = VIEWPORT;
      const { index, before } = await dragFirstObjectHandle(page);
      await nextFrames(page);
      const moved = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/gregory-dragged.png`, moved);
      const change = await screenshotDifference(page, before, moved, viewport, 24);
      assert(change.differing > 200, `the canvas changed with the drag (${change.differing} px)`);
      await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 0, null, { timeout: 30_000 });
      const undone = await page.evaluate(() => window.knotwork.project());
      assert(undone.objects[0].points[index].every((x, c) => x === points[index][c]), 'undo brings the point back');
      assert(undone.objects[0].display === 'gregory', 'the display is saved');
      // PN triangles on a Loop octahedron: one cubic triangle per face.
      const octahedron = {
        type: 'subdivision_surface', name: 'pn', scheme: 'loop', level: 2, display: 'pn-triangles',
        points: [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]],
        faces: [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]],
      };
      await openObjects(page, [octahedron]);
      await page.waitForFunction(() => window.knotwork.project().objects[0].display === 'pn-triangles', null, { timeout: 60_000 });
      await nextFrames(page);
      s = await status(page);
      assert(s.error === null && s.patches === 8 && s.vertices === 8 * 25, `PN triangles: ${JSON.stringify(s)}`);
      console.log(`      Gregory drag changed ${change.differing} px`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('adaptive subdivision in the page: fewer vertices than the uniform level, refinement levels in colour, depths chosen again after a move, undo', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      // A flat 6 x 6 grid cage with its middle point raised into a bump: flat around, curved
      // in the middle (corners kept sharp, so the flat part's outline is straight).
      const points = [];
      for (let i = 0; i < 7; i += 1) for (let j = 0; j < 7; j += 1) points.push([i - 3, j - 3, i === 3 && j === 3 ? 3 : 0]);
      const faces = [];
      for (let i = 0; i < 6; i += 1) for (let j = 0; j < 6; j += 1) faces.push([7 * i + j, 7 * i + j + 7, 7 * i + j + 8, 7 * i + j + 1]);
      const cage = (display, tolerance) => ({ type: 'subdivision_surface', name: display, points, faces, level: 3, boundary: 'edge-and-corner', display, ...(tolerance ? { tolerance } : {}) });
      // Fixed tessellation: the uniform limit's regular faces at their level's segments.
      await page.evaluate(() => window.knotwork.setTessellation(false, 0.5));
      await page.waitForFunction(() => window.knotwork.status().tessellation === 'fixed', null, { timeout: 30_000 });
      await openObjects(page, [cage('limit')]);
      const uniform = await status(page);
      await openObjects(page, [cage('adaptive', 0.002)]);
      await page.waitForFunction(() => window.knotwork.project().objects[0].display === 'adaptive', null, { timeout: 60_000 });
      await nextFrames(page);
      let s = await status(page);
      assert(s.error === null && s.patches === 144 && s.vertices < uniform.vertices / 2, `adaptive ${JSON.stringify(s)} vs uniform ${uniform.vertices} vertices`);
      assert((await page.evaluate(() => window.knotwork.project())).objects[0].tolerance === 0.002, 'the tolerance is saved');
      await page.evaluate(() => window.knotwork.frame());
      assert(await page.evaluate(() => window.knotwork.setShading('level')), 'level is a mode');
      await nextFrames(page);
      const shot = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/adaptive-levels.png`, shot);
      // Pixels of the level colours (lit): blue (level 1), cyan (2), green (3).
      const hues = await page.evaluate(async (data) => {
        const bytes = Uint8Array.from(atob(data), (c) => c.charCodeAt(0));
        const bitmap = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
        const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
        const context = canvas.getContext('2d');
        context.drawImage(bitmap, 0, 0);
        const p = context.getImageData(0, 0, bitmap.width, bitmap.height).data;
        const count = { blue: 0, cyan: 0, green: 0 };
        for (let i = 0; i < p.length; i += 4) {
          const [r, g, b] = [p[i], p[i + 1], p[i + 2]];
          if (b > g + 40 && b > r + 60) count.blue += 1;
          else if (g > r + 60 && b > r + 60 && Math.abs(g - b) < 60) count.cyan += 1;
          else if (g > r + 60 && g > b + 60) count.green += 1;
        }
        return count;
      }, shot.toString('base64'));
      const shown = Object.values(hues).filter((n) => n > 200).length;
      assert(shown >= 2, `at least two refinement levels in colour: ${JSON.stringify(hues)}`);
      // Flattening the bump: the depths are chosen again (fewer vertices), undo restores.
      const before = s.vertices;
      await page.evaluate(() => window.knotwork.moveControlPoint(0, 24, [0, 0, 0]));
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 1, null, { timeout: 60_000 });
      await nextFrames(page);
      s = await status(page);
      assert(s.error === null && s.vertices < before, `after the move ${s.vertices} vertices, before ${before}`);
      await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 0, null, { timeout: 30_000 });
      await nextFrames(page);
      s = await status(page);
      assert(s.error === null && s.vertices === before, `undo: ${s.vertices} vertices, ${before} before`);
      // The script interface switches displays: back to the uniform limit, then adaptive again.
      const mosaic = await thrownBy(page, () => window.knotwork.setSubdivisionDisplay(0, 'mosaic'));
      assert(/display must be one of .*got "mosaic"/.test(mosaic ?? ''), `unknown displays are refused: ${mosaic}`);
      assert(await page.evaluate(() => window.knotwork.setSubdivisionDisplay(0, 'limit')), 'limit is a display');
      await page.waitForFunction(() => window.knotwork.project().objects[0].display === 'limit', null, { timeout: 60_000 });
      await page.evaluate(() => window.knotwork.setSubdivisionDisplay(0, 'adaptive', 0.01));
      await page.waitForFunction(() => window.knotwork.project().objects[0].tolerance === 0.01, null, { timeout: 60_000 });
      await nextFrames(page);
      s = await status(page);
      assert(s.error === null && s.vertices < before, `a coarser tolerance: ${s.vertices} vertices, ${before} before`);
      console.log(`      adaptive ${before} vertices against ${uniform.vertices} uniform; level colours ${JSON.stringify(hues)}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('a triangular Bezier patch in the page: the GPU lattice, curvature shading, a move, undo, export validates', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      // A cubic dome over a triangle: b_ijk at (i A + j B + k C)/3, raised inside.
      const [A, B, C] = [[2, 0, 0], [-1, 1.7, 0], [-1, -1.7, 0]];
      const points = [];
      for (let j = 0; j <= 3; j += 1) {
        for (let i = 0; i <= 3 - j; i += 1) {
          const k = 3 - i - j;
          const p = [0, 1, 2].map((c) => (i * A[c] + j * B[c] + k * C[c]) / 3);
          p[2] += 0.6 * (i * j + j * k + k * i) / 3;
          points.push(p);
        }
      }
      await openObjects(page, [{ type: 'triangular_bezier', name: 'dome', degree: 3, points }]);
      let s = await status(page);
      // Degree 3: a lattice of 24 segments per edge, (24 + 1)^2 slots and two triangles per cell
      // (those past the diagonal degenerate, as every triangle lattice's).
      assert(s.error === null && s.patches === 1 && s.vertices === 625 && s.triangles === 1152, `dome: ${JSON.stringify(s)}`);
      await page.evaluate(() => window.knotwork.frame());
      assert(await page.evaluate(() => window.knotwork.setShading('mean')), 'mean is a mode');
      await nextFrames(page);
      const before = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/triangle-mean.png`, before);
      // The middle point (b_111, index 5) raised: the surface follows, undo restores it.
      await page.evaluate(() => window.knotwork.moveControlPoint(0, 5, [0, 0, 2.5]));
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 1, null, { timeout: 60_000 });
      await nextFrames(page);
      const moved = await page.locator('#knotwork-canvas').screenshot();
      const viewport = VIEWPORT;
      const change = await screenshotDifference(page, before, moved, viewport, 24);
      assert(change.differing > 500, `the canvas changed with the move (${change.differing} px)`);
      const bytes = await exportGlbBytes(page, { tolerance: 0.001 });
      const report = summary('triangle.glb', await validate(bytes, 'triangle.glb'));
      assert(report.errors === 0 && report.warnings === 0, `validator: ${JSON.stringify(report)}`);
      await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 0, null, { timeout: 30_000 });
      const undone = await page.evaluate(() => window.knotwork.project());
      assert(undone.objects[0].type === 'triangular_bezier' && undone.objects[0].points[5][2] === points[5][2], 'undo brings the point back');
      console.log(`      the move changed ${change.differing} px; export ${bytes.length} bytes, validator clean`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('displacement in the page: a displaced plane on the GPU, export validates, a drag keeps it', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const plate = (displacement) => ({
        type: 'nurbs_surface', name: 'plate', degree: [1, 1], knots: [[0, 0, 1, 1], [0, 0, 1, 1]], segments: 48,
        points: [[[-2, -2, 0], [-2, 2, 0]], [[2, -2, 0], [2, 2, 0]]],
        ...(displacement ? { displacement } : {}),
      });
      await openObjects(page, [plate(null)]);
      await page.evaluate(() => window.knotwork.frame());
      await nextFrames(page);
      const flat = await page.locator('#knotwork-canvas').screenshot();
      await openObjects(page, [plate({ pattern: 'ripples', amplitude: 0.3, frequency: 3 })]);
      await page.waitForFunction(() => window.knotwork.project().objects[0].displacement?.pattern === 'ripples', null, { timeout: 60_000 });
      await nextFrames(page);
      let s = await status(page);
      // The view-adaptive tessellation gives the flat plate at least 8 segments per cycle of
      // its pattern (3 cycles: 24 per edge).
      assert(s.error === null && s.vertices >= 25 * 25, `displaced: ${JSON.stringify(s)}`);
      const rippled = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/displaced-ripples.png`, rippled);
      const viewport = VIEWPORT;
      const change = await screenshotDifference(page, flat, rippled, viewport, 24);
      assert(change.differing > 2000, `the ripples show (${change.differing} px)`);
      const bytes = await exportGlbBytes(page, { tolerance: 0.001 });
      const report = summary('displaced.glb', await validate(bytes, 'displaced.glb'));
      assert(report.errors === 0 && report.warnings === 0, `validator: ${JSON.stringify(report)}`);
      // Moving a corner: the plate tilts and stays displaced; undo.
      await page.evaluate(() => window.knotwork.moveControlPoint(0, 3, [2, 2, 1.5]));
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 1, null, { timeout: 60_000 });
      const moved = await page.evaluate(() => window.knotwork.project());
      assert(moved.objects[0].displacement.amplitude === 0.3, 'the displacement stays with the object');
      await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 0, null, { timeout: 30_000 });
      s = await status(page);
      assert(s.error === null, `after undo: ${s.error}`);
      // The script interface: another pattern, an unknown one refused, removal.
      const plaid = await thrownBy(page, () => window.knotwork.setDisplacement(0, 'plaid', 0.1, 2));
      assert(/pattern must be one of .*got "plaid"/.test(plaid ?? ''), `unknown patterns are refused: ${plaid}`);
      assert(await page.evaluate(() => window.knotwork.setDisplacement(0, 'waves', 0.2, 2)), 'waves is a pattern');
      await page.waitForFunction(() => window.knotwork.project().objects[0].displacement?.pattern === 'waves', null, { timeout: 60_000 });
      await page.evaluate(() => window.knotwork.setDisplacement(0, 'waves', 0.2, -1));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 30_000 });
      s = await status(page);
      assert(/frequency/.test(s.error), `a bad frequency is refused: ${s.error}`);
      // An image height map: a radial gradient drawn by the page itself, tiled twice.
      const pngBytes = await page.evaluate(async () => {
        const canvas = new OffscreenCanvas(32, 32);
        const g = canvas.getContext('2d');
        const gradient = g.createRadialGradient(16, 16, 2, 16, 16, 16);
        gradient.addColorStop(0, '#ffffff');
        gradient.addColorStop(1, '#000000');
        g.fillStyle = gradient;
        g.fillRect(0, 0, 32, 32);
        const blob = await canvas.convertToBlob({ type: 'image/png' });
        const png = new Uint8Array(await blob.arrayBuffer());
        window.knotwork.setDisplacementImage(0, png, 0.3, 2);
        return png.length;
      });
      await page.waitForFunction(() => window.knotwork.project().objects[0].displacement?.pattern === 'image', null, { timeout: 60_000 });
      await nextFrames(page);
      s = await status(page);
      assert(s.error === null, `image displacement: ${s.error}`);
      const domes = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/displaced-image.png`, domes);
      const imageChange = await screenshotDifference(page, flat, domes, viewport, 24);
      assert(imageChange.differing > 2000, `the image's domes show (${imageChange.differing} px)`);
      const imageGlb = await exportGlbBytes(page, { tolerance: 0.001 });
      const imageReport = summary('displaced-image.glb', await validate(imageGlb, 'displaced-image.glb'));
      assert(imageReport.errors === 0 && imageReport.warnings === 0, `validator: ${JSON.stringify(imageReport)}`);
      const refusal = await page.evaluate(() => {
        try {
          window.knotwork.setDisplacementImage(0, new Uint8Array([1, 2, 3]), 0.1, 1);
          return null;
        } catch (e) {
          return String(e);
        }
      });
      assert(refusal && /PNG/.test(refusal), `an unreadable image is refused: ${refusal}`);
      await page.evaluate(() => window.knotwork.setDisplacement(0, 'none'));
      await page.waitForFunction(() => !window.knotwork.project().objects[0].displacement, null, { timeout: 60_000 });
      console.log(`      ripples changed ${change.differing} px, a ${pngBytes}-byte image ${imageChange.differing} px; exports ${bytes.length} and ${imageGlb.length} bytes, validator clean`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('free-form deformation in the page: one lattice bends two sheets on the GPU, export validates, apply is exact, undo', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const sheet = {
        type: 'nurbs_surface', name: 'sheet', degree: [3, 3], segments: 16,
        knots: [[0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 0, 0, 1, 1, 1, 1]],
        points: [0, 1, 2, 3].map((i) => [0, 1, 2, 3].map((j) => [i - 1.5, j - 1.5, 0])),
      };
      const second = { ...sheet, name: 'second', points: sheet.points.map((row) => row.map(([x, y, z]) => [x, y + 3.5, z])) };
      await openObjects(page, [sheet, second]);
      await page.evaluate(() => window.knotwork.frame());
      await nextFrames(page);
      const flat = await page.locator('#knotwork-canvas').screenshot();
      await page.evaluate(() => window.knotwork.addLattice([0, 1], 1, 1, 1));
      await page.waitForFunction(() => window.knotwork.project().objects[1].lattice?.points?.length === 8, null, { timeout: 60_000 });
      let s = await status(page);
      assert(s.error === null && s.control_points > 0, `lattice added: ${JSON.stringify(s.error)}`);
      // Lift one corner of the lattice's top: the sheet bends on the GPU.
      const lattice = (await page.evaluate(() => window.knotwork.project())).objects[0].lattice;
      const top = lattice.points[7];
      await page.evaluate(([x, y, z]) => window.knotwork.moveControlPoint(0, 7, [x, y, z + 2]), top);
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 2, null, { timeout: 60_000 });
      await nextFrames(page);
      s = await status(page);
      assert(s.error === null, `after the lattice drag: ${s.error}`);
      const shared = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(JSON.stringify(shared[0].lattice) === JSON.stringify(shared[1].lattice), 'the second sheet shares the moved lattice');
      const bent = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/lattice-bent.png`, bent);
      const change = await screenshotDifference(page, flat, bent, VIEWPORT, 24);
      assert(change.differing > 2000, `the bend shows (${change.differing} px)`);
      const bytes = await exportGlbBytes(page, { tolerance: 0.001 });
      const report = summary('lattice.glb', await validate(bytes, 'lattice.glb'));
      assert(report.errors === 0 && report.warnings === 0, `validator: ${JSON.stringify(report)}`);
      // Apply: a bicubic sheet through a trilinear lattice is exactly a degree-9 surface.
      await page.evaluate(() => window.knotwork.applyLattice(0, 0.001));
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 3, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.error === null && /exact/.test(s.notice ?? ''), `apply: ${s.error} / ${s.notice}`);
      const bakedBoth = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(bakedBoth.every((o) => !o.lattice && o.degree[0] === 9 && o.degree[1] === 9), `baked: degrees ${bakedBoth.map((o) => o.degree)}`);
      await nextFrames(page);
      const applied = await page.locator('#knotwork-canvas').screenshot();
      const same = await screenshotDifference(page, bent, applied, VIEWPORT, 24);
      assert(same.differing < change.differing / 10, `the baked surface looks like the live one (${same.differing} px differ)`);
      // Undo twice: the flat sheet with its lattice released is the original again.
      await page.evaluate(() => window.knotwork.undo());
      await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 1, null, { timeout: 30_000 });
      await page.evaluate(() => window.knotwork.releaseLattice(0));
      await page.waitForFunction(() => window.knotwork.project().objects.every((o) => !o.lattice), null, { timeout: 30_000 });
      console.log(`      bend changed ${change.differing} px, baked differs by ${same.differing} px; export ${bytes.length} bytes, validator clean`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('a trimmed surface in the page: a circle drawn with the mouse cuts a hole, export validates, undo', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const plate = {
        type: 'nurbs_surface', name: 'plate', degree: [1, 1], knots: [[0, 0, 1, 1], [0, 0, 1, 1]],
        points: [[[-1, -1, 0], [-1, 1, 0]], [[1, -1, 0], [1, 1, 0]]],
      };
      await openObjects(page, [plate]);
      await page.evaluate(() => window.knotwork.frame());
      await page.evaluate(() => window.knotwork.select(0));
      await page.waitForFunction(() => window.knotwork.status().selected === 0, null, { timeout: 30_000 });
      await nextFrames(page);
      const canvas = await page.locator('#knotwork-canvas').boundingBox();
      const corners = await page.evaluate(() => window.knotwork.handles());
      assert(corners.every((h) => h), 'the four corners are on screen');
      // The screen point of (u, v): the corners' bilinear blend (near enough on the plate).
      const at = (u, v) => [0, 1].map((c) => (1 - u) * ((1 - v) * corners[0][c] + v * corners[1][c])
        + u * ((1 - v) * corners[2][c] + v * corners[3][c]));
      const [cx, cy] = at(0.5, 0.5);
      const [ex, ey] = at(0.7, 0.5);
      const around = { x: Math.round(cx) - 4, y: Math.round(cy) - 4, width: 9, height: 9 };
      const before = await page.locator('#knotwork-canvas').screenshot();
      await page.evaluate(() => window.knotwork.setTrimTool('circle'));
      await page.mouse.click(canvas.x + cx, canvas.y + cy);
      await page.mouse.click(canvas.x + ex, canvas.y + ey);
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 1, null, { timeout: 60_000 });
      let s = await status(page);
      assert(s.error === null, `error: ${s.error}`);
      const trimmed = await page.evaluate(() => window.knotwork.project());
      assert(trimmed.objects[0].trims.length === 2, `the boundary and the hole: ${JSON.stringify(trimmed.objects[0].trims?.length)}`);
      await page.evaluate(() => window.knotwork.setTrimTool(''));
      await nextFrames(page);
      const holed = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/trim-hole.png`, holed);
      const hole = await screenshotDifference(page, before, holed, around, 24);
      assert(hole.differing === hole.total, `the hole shows through at its centre (${hole.differing} of ${hole.total} px changed)`);

      // A trim loop that crosses the outer one is refused and changes nothing.
      await page.evaluate(() => window.knotwork.trimCircle(0, 0.95, 0.5, 0.2, false));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 30_000 });
      s = await status(page);
      assert(/trims\[/.test(s.error) && s.undo_steps === 1, `refused: ${JSON.stringify(s.error)}`);

      const bytes = await exportGlbBytes(page, { tolerance: 0.001 });
      const report = summary('trimmed.glb', await validate(bytes, 'trimmed.glb'));
      assert(report.errors === 0 && report.warnings === 0, `validator: ${JSON.stringify(report)}`);

      await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 0, null, { timeout: 30_000 });
      const undone = await page.evaluate(() => window.knotwork.project());
      assert(!undone.objects[0].trims, 'undo removes the trims');
      await nextFrames(page);
      const back = await page.locator('#knotwork-canvas').screenshot();
      const restored = await screenshotDifference(page, before, back, around, 24);
      assert(restored.differing === 0, `undo fills the hole (${restored.differing} px differ)`);
      console.log(`      trimmed glb ${bytes.length} bytes, validator infos ${report.infos}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('curves in the page: drawn by clicks on the ground, picked with Shift + click, lofted; a dragged section moves the loft on the GPU; undo back to the start', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      await openObjects(page, []);
      await page.evaluate(() => window.knotwork.setView('top'));
      await nextFrames(page);
      const canvas = await page.locator('#knotwork-canvas').boundingBox();
      const empty = await page.locator('#knotwork-canvas').screenshot();
      const base = (await status(page)).undo_steps;
      // Three curves of four clicked control points each, one row of clicks per curve.
      const rows = [260, 400, 540];
      const columns = [520, 680, 840, 1000];
      const clicks = rows.map((y, r) => columns.map((x, c) => [x, y + (c % 2 === 1 ? 30 : -10) * (r + 1)]));
      for (const [r, row] of clicks.entries()) {
        await page.evaluate(() => window.knotwork.drawCurve('control', 3, 'ground'));
        await page.waitForFunction(() => window.knotwork.status().drawing === 0, null, { timeout: 30_000 });
        for (const [k, [x, y]] of row.entries()) {
          await page.mouse.click(canvas.x + x, canvas.y + y);
          await page.waitForFunction((n) => window.knotwork.status().drawing === n, k + 1, { timeout: 30_000 });
        }
        await page.keyboard.press('Enter');
        await page.waitForFunction((n) => {
          const s = window.knotwork.status();
          return s.objects === n && s.drawing === null;
        }, r + 1, { timeout: 30_000 });
      }
      let s = await status(page);
      assert(s.error === null && s.undo_steps - base === 3, `three steps: ${JSON.stringify([s.error, s.undo_steps, base])}`);
      assert(s.curve_segments === 3 && s.curve_vertices > 3 * 16, `curve segments on the GPU: ${s.curve_segments}, ${s.curve_vertices} vertices`);
      const drawn = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(drawn.every((o) => o.type === 'nurbs_curve' && o.points.every((p) => Math.abs(p[2] / (p[3] ?? 1)) < 1e-9)), 'three curves on the ground');
      // The clicks became the control points: their handles are where the mouse clicked.
      await page.evaluate(() => window.knotwork.select(0));
      await page.waitForFunction(() => window.knotwork.status().selected === 0, null, { timeout: 30_000 });
      await nextFrames(page);
      const handles = await page.evaluate(() => window.knotwork.handles());
      const off = Math.max(...handles.map((h, k) => Math.hypot(h[0] - clicks[0][k][0], h[1] - clicks[0][k][1])));
      assert(handles.length === 4 && off < 1.5, `handles ${JSON.stringify(handles)} vs clicks ${JSON.stringify(clicks[0])} (${off.toFixed(2)} px)`);
      // The curves are drawn: a clamped curve starts at its first control point.
      await page.evaluate(() => window.knotwork.select(-1));
      await nextFrames(page);
      const curves = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/curves-drawn.png`, curves);
      for (const row of clicks) {
        const [x, y] = row[0];
        const around = { x: x - 4, y: y - 4, width: 9, height: 9 };
        const line = await screenshotDifference(page, empty, curves, around, 40);
        assert(line.differing >= 6, `a curve is drawn through (${x}, ${y}): ${line.differing} px`);
      }

      // Shift + click on each curve's start picks the sections in order; then the loft.
      await page.keyboard.down('Shift');
      for (const row of clicks) await page.mouse.click(canvas.x + row[0][0], canvas.y + row[0][1]);
      await page.keyboard.up('Shift');
      await page.waitForFunction(() => window.knotwork.status().picked_curves.length === 3, null, { timeout: 30_000 });
      s = await status(page);
      assert(JSON.stringify(s.picked_curves) === '[0,1,2]', `picked ${JSON.stringify(s.picked_curves)}`);
      await page.evaluate(() => window.knotwork.construct({ construct: 'loft', curves: [{ input: 0 }, { input: 1 }, { input: 2 }] }, window.knotwork.status().picked_curves));
      await page.waitForFunction(() => window.knotwork.status().objects === 4, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.error === null && s.patches > 0, `loft: ${s.error}, ${s.patches} patches`);
      const lofted = (await page.evaluate(() => window.knotwork.project())).objects[3];
      assert(lofted.type === 'nurbs_surface' && lofted.history?.operation?.curves?.length === 3, `the loft keeps its history: ${JSON.stringify(lofted.history)}`);

      // Drag a middle control point of the middle section with the mouse: every step builds
      // the loft again and the GPU shows it.
      await page.evaluate(() => window.knotwork.select(1));
      await page.waitForFunction(() => window.knotwork.status().selected === 1, null, { timeout: 30_000 });
      await nextFrames(page);
      const before = await page.locator('#knotwork-canvas').screenshot();
      const [hx, hy] = (await page.evaluate(() => window.knotwork.handles()))[1];
      const times = await dragWithMouse(page, canvas.x + hx, canvas.y + hy, 5, 0, 14);
      await page.waitForFunction((n) => {
        const t = window.knotwork.status();
        return t.undo_steps - (window.__base ?? 0) === n && !t.dragging;
      }, base + 5, { timeout: 60_000 });
      s = await status(page);
      assert(s.error === null && /move 1 point/.test(s.last_edit), `drag: ${s.error}, ${s.last_edit}`);
      const moved = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(JSON.stringify(moved[3].points) !== JSON.stringify(lofted.points), 'the loft followed its section');
      assert(moved[3].history?.operation?.curves?.length === 3, 'and keeps its history');
      await nextFrames(page);
      const after = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/curves-loft-dragged.png`, after);
      const band = { x: 480, y: 300, width: 560, height: 200 };
      const followed = await screenshotDifference(page, before, after, band, 24);
      assert(followed.differing > 100, `the loft moved on screen (${followed.differing} px)`);
      console.log(`      loft drag-to-new-frame: median ${times[times.length >> 1]} ms (${times.join(', ')}); ${followed.differing} px changed`);

      // Undo everything: the drag (loft and section together), the loft, the three curves.
      for (let k = 0; k < 5; k += 1) await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction((n) => {
        const t = window.knotwork.status();
        return t.undo_steps - (window.__base ?? 0) === n && t.objects === 0;
      }, base, { timeout: 60_000 });
      s = await status(page);
      assert(s.error === null && s.curve_segments === 0, `back to the start: ${JSON.stringify([s.error, s.curve_segments])}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('surface tools in the page: a fillet trims two planes back on the GPU, an offset, a join into a polysurface; undo back to the start', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      // A floor (normal +z) and a wall (normal -y) meeting along the x axis.
      await openObjects(page, [
        plane('Floor', [[[-1, -2, 0], [-1, 0, 0]], [[1, -2, 0], [1, 0, 0]]]),
        plane('Wall', [[[-1, 0, 0], [-1, 0, 2]], [[1, 0, 0], [1, 0, 2]]]),
      ]);
      await page.evaluate(() => window.knotwork.frame());
      await nextFrames(page);
      const before = await page.locator('#knotwork-canvas').screenshot();
      await page.evaluate(() => window.knotwork.fillet(0, 1, 0.5, { frontA: true, frontB: true }));
      await page.waitForFunction(() => window.knotwork.status().objects === 3, null, { timeout: 60_000 });
      let s = await status(page);
      assert(s.error === null && /fillet Floor and Wall/.test(s.last_edit), `fillet: ${s.error}, ${s.last_edit}`);
      let objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(objects[2].name === 'fillet' && objects[0].trims?.length === 1 && objects[1].trims?.length === 1, `trimmed back, fillet added: ${JSON.stringify(objects.map((o) => [o.name, o.trims?.length]))}`);
      await nextFrames(page);
      const filleted = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/surface-tools-fillet.png`, filleted);
      const changed = await screenshotDifference(page, before, filleted, { x: 200, y: 100, width: 1000, height: 600 }, 24);
      assert(changed.differing > 200, `the fillet shows on screen (${changed.differing} px)`);
      await page.evaluate(() => window.knotwork.offset(2, 0.1));
      await page.waitForFunction(() => window.knotwork.status().objects === 4, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.error === null && /offset fillet/.test(s.last_edit), `offset: ${s.error}, ${s.last_edit}`);
      await page.evaluate(() => window.knotwork.join([0, 1, 2]));
      await page.waitForFunction(() => window.knotwork.status().objects === 2, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.error === null && /join: Floor \(3 faces, 2 shared edges/.test(s.last_edit), `join: ${s.error}, ${s.last_edit}`);
      objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(objects[0].type === 'polysurface' && objects[0].faces.length === 3, `a polysurface: ${objects[0].type}`);
      assert(s.patches > 0, `its faces on the GPU: ${s.patches} patches`);
      // Bad input is refused with the reason and changes nothing.
      await page.evaluate(() => window.knotwork.fillet(0, 1, 50));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.objects === 2, `a refused fillet changes nothing: ${s.error}`);
      // Any operation as its value: the page's apply reads it through the registry.
      await page.evaluate(() => window.knotwork.apply({ op: 'explode', object: 0 }));
      await page.waitForFunction(() => window.knotwork.status().objects === 4, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.error === null && /explode Floor into 3 faces/.test(s.last_edit), `apply explode: ${s.error}, ${s.last_edit}`);
      let refused = '';
      try { await page.evaluate(() => window.knotwork.apply({ op: 'offset', object: 0, distance: 'far' })); } catch (e) { refused = String(e); }
      assert(/distance/.test(refused), `a bad field is named: ${refused}`);
      for (let k = 0; k < 4; k += 1) await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => {
        const t = window.knotwork.status();
        return t.undo_steps - (window.__base ?? 0) === 0 && t.objects === 2;
      }, null, { timeout: 60_000 });
      objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(objects.every((o) => o.type === 'nurbs_surface' && !o.trims), 'back to the two planes');

      // Trim the floor by a slanted plane through it, keeping the part at -x: drawn by the
      // frame after the command.
      await openObjects(page, [
        plane('Floor', [[[-1, -2, 0], [-1, 0, 0]], [[1, -2, 0], [1, 0, 0]]]),
        plane('Cutter', [[[-0.3, -3, -1], [0.3, -3, 1]], [[-0.3, 1, -1], [0.3, 1, 1]]]),
      ]);
      await nextFrames(page);
      const whole = await page.locator('#knotwork-canvas').screenshot();
      const frames = await page.evaluate(() => window.knotwork.status().frames);
      await page.evaluate(() => window.knotwork.trimBy(0, [1], [-0.9, -1.0, 0]));
      await page.waitForFunction(() => /trim Floor/.test(window.knotwork.status().last_edit ?? ''), null, { timeout: 60_000 });
      const shownAt = await page.evaluate(() => window.knotwork.status().frames);
      s = await status(page);
      assert(s.error === null, `trim: ${s.error}`);
      objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(objects[0].trims?.length >= 1, `the floor is trimmed: ${JSON.stringify(objects[0].trims?.length)}`);
      console.log(`      trim by intersection: the frame after ${shownAt - frames} frame(s)`);
      await nextFrames(page);
      const holed = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/surface-tools-trim.png`, holed);
      const hole = await screenshotDifference(page, whole, holed, { x: 200, y: 100, width: 1000, height: 600 }, 24);
      assert(hole.differing > 100, `the trim shows on screen (${hole.differing} px)`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('a live boolean in the page: two boxes joined into bodies, their difference with history follows the moved tool on the GPU, printed as STL and 3MF; undo back', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      // Each box as six planes; join makes each a closed polysurface.
      const box = (name, [x0, y0, z0], [x1, y1, z1]) => [
        plane(`${name} bottom`, [[[x0, y0, z0], [x0, y1, z0]], [[x1, y0, z0], [x1, y1, z0]]]),
        plane(`${name} top`, [[[x0, y0, z1], [x0, y1, z1]], [[x1, y0, z1], [x1, y1, z1]]]),
        plane(`${name} front`, [[[x0, y0, z0], [x0, y0, z1]], [[x1, y0, z0], [x1, y0, z1]]]),
        plane(`${name} back`, [[[x0, y1, z0], [x0, y1, z1]], [[x1, y1, z0], [x1, y1, z1]]]),
        plane(`${name} left`, [[[x0, y0, z0], [x0, y0, z1]], [[x0, y1, z0], [x0, y1, z1]]]),
        plane(`${name} right`, [[[x1, y0, z0], [x1, y0, z1]], [[x1, y1, z0], [x1, y1, z1]]]),
      ];
      await openObjects(page, [...box('A', [-1, -0.5, 0], [1, 0.5, 1.5]), ...box('B', [0, 0, 0.5], [2, 1, 2])]);
      await page.evaluate(() => window.knotwork.join([]));
      await page.waitForFunction(() => window.knotwork.status().objects === 2, null, { timeout: 60_000 });
      let objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(objects.every((o) => o.type === 'polysurface' && o.faces.length === 6), `two bodies: ${JSON.stringify(objects.map((o) => [o.type, o.faces?.length]))}`);
      await page.evaluate(() => window.knotwork.frame());
      await nextFrames(page);
      const before = await page.locator('#knotwork-canvas').screenshot();
      await page.evaluate(() => window.knotwork.apply({ op: 'boolean', operation: 'difference', a: [0], b: [1] }, { keepHistory: true }));
      await page.waitForFunction(() => window.knotwork.status().objects === 3, null, { timeout: 120_000 });
      let s = await status(page);
      assert(s.error === null && /difference of A bottom and B bottom/.test(s.last_edit), `difference: ${s.error}, ${s.last_edit}`);
      objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(!objects[0].visible && !objects[1].visible, 'the inputs are hidden');
      assert(objects[2].type === 'polysurface' && objects[2].faces.length > 6, `the result: ${objects[2].type}, ${objects[2].faces?.length} faces`);
      await nextFrames(page);
      const cut = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/boolean-difference.png`, cut);
      const shown = await screenshotDifference(page, before, cut, { x: 200, y: 100, width: 1000, height: 600 }, 24);
      assert(shown.differing > 200, `the difference shows on screen (${shown.differing} px)`);
      // Move the tool: the difference is made again through its history, and drawn.
      const faces = objects[2].faces.length;
      const started = await page.evaluate(() => performance.now());
      await page.evaluate(() => window.knotwork.apply({ op: 'transform', object: 1, matrix: [[1, 0, 0], [0, 1, 0], [0, 0, 1]], translation: [0, 0, 0.4] }));
      await page.waitForFunction(() => /transform/.test(window.knotwork.status().last_edit ?? ''), null, { timeout: 60_000 });
      await nextFrames(page);
      const took = Math.round((await page.evaluate(() => performance.now())) - started);
      s = await status(page);
      assert(s.error === null, `move: ${s.error}`);
      const moved = await page.locator('#knotwork-canvas').screenshot();
      const followed = await screenshotDifference(page, cut, moved, { x: 200, y: 100, width: 1000, height: 600 }, 24);
      assert(followed.differing > 50, `the difference followed the tool on screen (${followed.differing} px)`);
      objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(objects[2].type === 'polysurface' && objects[2].faces.length >= faces - 2, `still a body: ${objects[2].faces?.length} faces`);
      // The result printed from the page: a binary STL holding its volume (the tool now
      // takes 1 x 0.5 x 0.6 from the 2 x 1 x 1.5 block: 2.7), and a 3MF package.
      await installPageHelpers(page);
      const printed = await page.evaluate(async () => {
        const stl = await window.knotwork.exportStl();
        const { facets, volume } = window.__stlVolume(stl);
        const package3mf = await window.knotwork.export3mf();
        const text = new TextDecoder().decode(package3mf);
        return {
          stlBytes: stl.length, facets, volume,
          zip: package3mf[0] === 0x50 && package3mf[1] === 0x4b && package3mf[2] === 3 && package3mf[3] === 4,
          objects: (text.match(/<object /g) || []).length,
          unit: /<model unit="[a-z]+"/.test(text),
        };
      });
      assert(printed.stlBytes === 84 + 50 * printed.facets && Math.abs(printed.volume - 2.7) < 1e-5, `exportStl: ${JSON.stringify(printed)}`);
      assert(printed.zip && printed.objects === 1 && printed.unit, `export3mf: ${JSON.stringify(printed)}`);
      console.log(`      live boolean: the tool moved and the difference drawn again in ${took} ms; printed as STL (${printed.facets} facets, volume ${printed.volume.toFixed(6)}) and 3MF`);
      // A refused boolean (a body with itself) changes nothing.
      await page.evaluate(() => window.knotwork.apply({ op: 'boolean', operation: 'union', a: [2], b: [2] }));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.objects === 3 && /itself/.test(s.error), `refused: ${s.error}`);
      for (let k = 0; k < 3; k += 1) await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => {
        const t = window.knotwork.status();
        return t.undo_steps - (window.__base ?? 0) === 0 && t.objects === 12;
      }, null, { timeout: 60_000 });
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('edge features in the page: a box joined into a body, every edge filleted with history, drawn on the GPU, printed with the rounded box\'s volume; the radius edited in place, a shell, undo back', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const [x0, y0, z0, x1, y1, z1] = [-1, -0.5, 0, 1, 0.5, 1.5];
      await openObjects(page, [
        plane('bottom', [[[x0, y0, z0], [x0, y1, z0]], [[x1, y0, z0], [x1, y1, z0]]]),
        plane('top', [[[x0, y0, z1], [x0, y1, z1]], [[x1, y0, z1], [x1, y1, z1]]]),
        plane('front', [[[x0, y0, z0], [x0, y0, z1]], [[x1, y0, z0], [x1, y0, z1]]]),
        plane('back', [[[x0, y1, z0], [x0, y1, z1]], [[x1, y1, z0], [x1, y1, z1]]]),
        plane('left', [[[x0, y0, z0], [x0, y0, z1]], [[x0, y1, z0], [x0, y1, z1]]]),
        plane('right', [[[x1, y0, z0], [x1, y0, z1]], [[x1, y1, z0], [x1, y1, z1]]]),
      ]);
      await page.evaluate(() => window.knotwork.join([]));
      await page.waitForFunction(() => window.knotwork.status().objects === 1, null, { timeout: 60_000 });
      await page.evaluate(() => window.knotwork.frame());
      await nextFrames(page);
      const before = await page.locator('#knotwork-canvas').screenshot();
      await page.evaluate(() => window.knotwork.filletEdges(0, 0.2, { keepHistory: true }));
      await page.waitForFunction(() => window.knotwork.status().objects === 2, null, { timeout: 60_000 });
      let s = await status(page);
      assert(s.error === null && /fillet of 12 edges/.test(s.last_edit), `fillet: ${s.error}, ${s.last_edit}`);
      let objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(!objects[0].visible && objects[1].type === 'polysurface' && objects[1].faces.length === 26, `the rounded box: ${objects[1].type}, ${objects[1].faces?.length} faces`);
      await nextFrames(page);
      const rounded = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/fillet-edges.png`, rounded);
      const shown = await screenshotDifference(page, before, rounded, { x: 200, y: 100, width: 1000, height: 600 }, 24);
      assert(shown.differing > 100, `the fillets show on screen (${shown.differing} px)`);
      // The rounded 2 × 1 × 1.5 box at r: the inner box grown by a ball.
      const volumeAt = (r) => {
        const [a, b, c] = [2 - 2 * r, 1 - 2 * r, 1.5 - 2 * r];
        return a * b * c + 2 * r * (a * b + b * c + c * a) + Math.PI * r * r * (a + b + c) + 4 * Math.PI * r ** 3 / 3;
      };
      // The printed mesh's chords lie inside the curved faces: its volume a little below.
      const near = (mesh, exact) => mesh <= exact + 1e-9 && exact - mesh < 4e-3 * exact;
      await installPageHelpers(page);
      let printed = await page.evaluate(async () => window.__stlVolume(await window.knotwork.exportStl()));
      assert(near(printed.volume, volumeAt(0.2)), `exportStl volume ${printed.volume} against ${volumeAt(0.2)}`);
      // The radius edited in place: one undo step, the history kept.
      await page.evaluate(() => window.knotwork.editHistory(1, { op: 'fillet_edges', object: 0, radius: 0.3 }));
      await page.waitForFunction(() => /edit fillet/.test(window.knotwork.status().last_edit ?? ''), null, { timeout: 60_000 });
      printed = await page.evaluate(async () => window.__stlVolume(await window.knotwork.exportStl()));
      assert(near(printed.volume, volumeAt(0.3)), `edited: volume ${printed.volume} against ${volumeAt(0.3)}`);
      // Too large a radius is refused, naming the edge; a bad value throws.
      await page.evaluate(() => window.knotwork.editHistory(1, { op: 'fillet_edges', object: 0, radius: 0.6 }));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 60_000 });
      s = await status(page);
      assert(/too large/.test(s.error) && s.objects === 2, `refused: ${s.error}`);
      let thrown = null;
      try { await page.evaluate(() => window.knotwork.filletEdges(0, 'big')); } catch (e) { thrown = String(e); }
      assert(thrown !== null && /radius/.test(thrown), `a bad radius throws: ${thrown}`);
      // A shell of the box with its top open.
      await page.evaluate(() => window.knotwork.shell(0, -0.1, { open: [[0, 0, 1.5]] }));
      await page.waitForFunction(() => window.knotwork.status().objects === 3, null, { timeout: 60_000 });
      printed = await page.evaluate(async () => window.__stlVolume(await window.knotwork.exportStl()));
      assert(near(printed.volume, volumeAt(0.3) + 3 - 1.8 * 0.8 * 1.4), `shell: volume ${printed.volume}`);
      for (let k = 0; k < 3; k += 1) await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => window.knotwork.status().objects === 1, null, { timeout: 60_000 });
      console.log(`      edge features: 26 faces drawn, printed volume ${volumeAt(0.3).toFixed(6)} after the edit`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('a long boolean in the page: the plate minus its 144 pins (145 bodies from two STEP files) runs over frames with progress and Cancel, the page drawing meanwhile; run to its end, 150 faces whose STL holds OpenCASCADE\'s volume', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const fixture = async (name) => (await readFile(new URL(`../tests/reference/boolean/${name}`, import.meta.url))).toString('base64');
      const [plate, pins] = [await fixture('plate-a.step'), await fixture('plate-b.step')];
      const reference = JSON.parse(await readFile(new URL('../tests/reference/boolean/occt-plate.json', import.meta.url), 'utf8')).difference;
      await installPageHelpers(page);
      const ran = await page.evaluate(async ([plateB64, pinsB64]) => {
        const decode = (b) => Uint8Array.from(atob(b), (c) => c.charCodeAt(0));
        const waitFor = (test, limit) => window.__waitFor(test, limit, 'boolean_progress');
        // Each file opened, its bodies taken (the plate, then one per pin); all put in one
        // document.
        const bodies = [];
        const phases = [];
        for (const [name, b64] of [['plate-a.step', plateB64], ['plate-b.step', pinsB64]]) {
          window.knotwork.openFile(name, decode(b64));
          const opened = await waitFor(() => window.knotwork.status().open_progress === null && window.knotwork.status().objects >= 1 && (window.knotwork.status().last_edit ?? '').includes(name), 120_000);
          phases.push({ name, ms: Math.round(opened.ms), last_edit: window.knotwork.status().last_edit, error: window.knotwork.status().error });
          bodies.push(...window.knotwork.project().objects);
        }
        const project = window.knotwork.project();
        project.objects = bodies;
        window.knotwork.openProject('plate.json', JSON.stringify(project));
        await waitFor(() => window.knotwork.status().objects === bodies.length && (window.knotwork.status().last_edit ?? '').includes('plate.json'), 60_000);
        const before = JSON.stringify(window.knotwork.project());
        const count = window.knotwork.status().objects;
        phases.push({ merged: count, error: window.knotwork.status().error });
        const pins = Array.from({ length: count - 1 }, (_, k) => k + 1);
        window.knotwork.runBoolean({ operation: 'difference', a: [0], b: pins });
        const shown = await waitFor(() => (window.knotwork.status().boolean_progress ?? 0) > 0.2, 120_000);
        phases.push({ shownMs: Math.round(shown.ms), status: JSON.stringify(window.knotwork.status()).slice(0, 600) });
        window.knotwork.cancelBoolean();
        await waitFor(() => window.knotwork.status().boolean_progress === null, 10_000);
        const unchanged = JSON.stringify(window.knotwork.project()) === before;
        window.knotwork.runBoolean({ operation: 'difference', a: [0], b: pins });
        const run = await waitFor(() => window.knotwork.status().boolean_progress === null && window.knotwork.status().objects === count + 1, 300_000);
        const s = window.knotwork.status();
        const objects = window.knotwork.project().objects;
        const { volume } = window.__stlVolume(await window.knotwork.exportStl());
        return { phases, count, shown, unchanged, run, error: s.error, lastEdit: s.last_edit, hidden: objects.slice(0, count).every((o) => !o.visible), shown_result: objects[count]?.visible, faces: objects[count]?.faces?.length, volume };
      }, [plate, pins]);
      const rising = ran.run.progress.every((p, k, all) => k === 0 || p >= all[k - 1]);
      // The page's animation frames keep coming between the boolean's turns.
      assert(ran.shown.progress.length >= 2 && ran.shown.frames >= 2, `progress shown while the page runs: ${ran.shown.progress.length} readings over ${ran.shown.frames} animation frames; ${JSON.stringify(ran.phases)}`);
      assert(ran.unchanged, 'Cancel leaves the document as it was');
      assert(ran.error === null && /difference/.test(ran.lastEdit ?? ''), `applied: ${ran.error}, ${ran.lastEdit}`);
      assert(rising && ran.run.progress.length >= 3, `the progress only rises over the run: ${ran.run.progress.length} readings`);
      assert(ran.count === 145 && ran.hidden && ran.shown_result && ran.faces === 150, `the plate and 144 pins hidden, a result of 150 faces: ${ran.count} objects, hidden ${ran.hidden}, ${ran.faces} faces`);
      // The STL's holes are polygons inscribed in the pins' circles at the export tolerance
      // (1e-3 of the diagonal): its volume is OpenCASCADE's and a little more (under 2 %).
      assert(ran.volume >= reference && ran.volume - reference < 0.02 * reference, `volume ${ran.volume} against OpenCASCADE's ${reference}`);
      console.log(`      long boolean: cancelled at ${(100 * ran.shown.progress.slice(-1)[0]).toFixed(0)} % after ${ran.shown.frames} frames; run to its end in ${Math.round(ran.run.ms)} ms over ${ran.run.frames} frames (${ran.run.progress.length} progress readings); STL volume ${ran.volume.toFixed(3)} against OpenCASCADE's ${reference.toFixed(3)}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('a body split by a surface in the page: two closed pieces, the body hidden, the surface kept; a split by itself refused; undo back', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const [x0, y0, z0, x1, y1, z1] = [-1, -0.5, 0, 1, 0.5, 1.5];
      // The box as six planes, and a slanted sheet through it (x = 0.35 - 0.15 z).
      await openObjects(page, [
        plane('Box bottom', [[[x0, y0, z0], [x0, y1, z0]], [[x1, y0, z0], [x1, y1, z0]]]),
        plane('Box top', [[[x0, y0, z1], [x0, y1, z1]], [[x1, y0, z1], [x1, y1, z1]]]),
        plane('Box front', [[[x0, y0, z0], [x0, y0, z1]], [[x1, y0, z0], [x1, y0, z1]]]),
        plane('Box back', [[[x0, y1, z0], [x0, y1, z1]], [[x1, y1, z0], [x1, y1, z1]]]),
        plane('Box left', [[[x0, y0, z0], [x0, y0, z1]], [[x0, y1, z0], [x0, y1, z1]]]),
        plane('Box right', [[[x1, y0, z0], [x1, y0, z1]], [[x1, y1, z0], [x1, y1, z1]]]),
        plane('Sheet', [[[0.5, -2, -1], [0.5, 2, -1]], [[-0.1, -2, 3], [-0.1, 2, 3]]]),
      ]);
      await page.evaluate(() => window.knotwork.join([0, 1, 2, 3, 4, 5]));
      await page.waitForFunction(() => window.knotwork.status().objects === 2, null, { timeout: 60_000 });
      let objects = (await page.evaluate(() => window.knotwork.project())).objects;
      const body = objects.findIndex((o) => o.type === 'polysurface');
      const sheet = objects.findIndex((o) => o.type !== 'polysurface');
      assert(body >= 0 && sheet >= 0, `a body and a sheet: ${JSON.stringify(objects.map((o) => o.type))}`);
      await page.evaluate(([a, b]) => window.knotwork.apply({ op: 'boolean', operation: 'split', a: [a], b: [b] }, { keepHistory: true }), [body, sheet]);
      await page.waitForFunction(() => window.knotwork.status().objects === 4, null, { timeout: 120_000 });
      let s = await status(page);
      assert(s.error === null && /split of .* 2 pieces/.test(s.last_edit), `split: ${s.error}, ${s.last_edit}`);
      objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(!objects[body].visible && objects[sheet].visible, 'the body hidden, the sheet kept');
      const pieces = objects.slice(2);
      assert(pieces.every((o) => o.type === 'polysurface' && o.faces.length === 6 && o.visible), `two six-faced pieces: ${JSON.stringify(pieces.map((o) => [o.type, o.faces?.length]))}`);
      // A body split by itself is refused, with the reason, changing nothing.
      await page.evaluate((k) => window.knotwork.apply({ op: 'boolean', operation: 'split', a: [k], b: [k] }), body);
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.objects === 4 && /split/.test(s.error), `refused: ${s.error}`);
      await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => window.knotwork.status().objects === 2, null, { timeout: 60_000 });
      console.log('      split: a box cut by a slanted sheet into two closed six-faced pieces');
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('blend, match, contour, projection and a varying fillet in the page: each one undo step, refusals change nothing', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      // Two level plates with a gap between x = -1 and x = 1, the right one higher, and a
      // line above the left one.
      await openObjects(page, [
        plane('Left', [[[-3, 0, 0], [-3, 2, 0]], [[-1, 0, 0], [-1, 2, 0]]]),
        plane('Right', [[[1, 0, 0.5], [1, 2, 0.5]], [[3, 0, 0.5], [3, 2, 0.5]]]),
        { type: 'nurbs_curve', name: 'Line', degree: 1, knots: [0, 0, 1, 1], points: [[-2.5, 0.5, 2, 1], [-1.5, 1.5, 2, 1]] },
      ]);
      await page.evaluate(() => window.knotwork.frame());
      await nextFrames(page);
      const before = await page.locator('#knotwork-canvas').screenshot();
      await page.evaluate(() => window.knotwork.blend(0, 1, { continuity: 'G2' }));
      await page.waitForFunction(() => window.knotwork.status().objects === 4, null, { timeout: 60_000 });
      let s = await status(page);
      assert(s.error === null && /G2 blend from Left u1 to Right u0/.test(s.last_edit), `blend: ${s.error}, ${s.last_edit}`);
      await nextFrames(page);
      const blended = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/surface-tools-blend.png`, blended);
      const changed = await screenshotDifference(page, before, blended, { x: 200, y: 100, width: 1000, height: 600 }, 24);
      assert(changed.differing > 200, `the blend shows on screen (${changed.differing} px)`);
      // Match the right plate's near edge onto the left's at G1: its first rows move.
      await page.evaluate(() => window.knotwork.matchEdge(1, 0, { continuity: 'G1' }));
      await page.waitForFunction(() => /match Right/.test(window.knotwork.status().last_edit ?? ''), null, { timeout: 60_000 });
      let objects = (await page.evaluate(() => window.knotwork.project())).objects;
      const edge = objects[1].points[0][0];
      assert(Math.abs(edge[0] / edge[3] + 1) < 1e-6 && Math.abs(edge[2] / edge[3]) < 1e-6, `the edge moved onto Left's: ${JSON.stringify(edge)}`);
      // Contours of the left plate every 0.4 across x, and the line projected down onto it.
      await page.evaluate(() => window.knotwork.contour(0, 0.4, { normal: [1, 0, 0], origin: [0.1, 0, 0] }));
      await page.waitForFunction(() => window.knotwork.status().objects === 9, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.error === null && /contour Left: 5 curve/.test(s.last_edit), `contour: ${s.error}, ${s.last_edit}`);
      await page.evaluate(() => window.knotwork.projectCurves([2], 0, [0, 0, -1]));
      await page.waitForFunction(() => window.knotwork.status().objects === 10, null, { timeout: 60_000 });
      objects = (await page.evaluate(() => window.knotwork.project())).objects;
      const projected = objects[9];
      assert(projected.name === 'Line projected' && projected.points.every((p) => Math.abs(p[2] / (p[3] ?? 1)) < 1e-6), `on the left plate: ${JSON.stringify(projected.points.slice(0, 2))}`);
      // Refusals: bad arguments throw; what only the document can check is refused in the
      // status and changes nothing.
      let thrown = null;
      try { await page.evaluate(() => window.knotwork.blend(0, 1, { continuity: 'G7' })); } catch (e) { thrown = String(e); }
      assert(thrown !== null && /options.continuity must be one of/.test(thrown), `a bad continuity throws: ${thrown}`);
      await page.evaluate(() => window.knotwork.matchEdge(0, 0));
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.objects === 10 && /two different objects/.test(s.error), `a refused match changes nothing: ${s.error}`);
      for (let k = 0; k < 4; k += 1) await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => window.knotwork.status().objects === 3, null, { timeout: 60_000 });
      objects = (await page.evaluate(() => window.knotwork.project())).objects;
      assert(Math.abs(objects[1].points[0][0][0] - 1) < 1e-12, 'undo brings the right plate back');
      // A fillet whose radius runs from 0.2 to 0.5 between a floor and a wall.
      await openObjects(page, [
        plane('Floor', [[[-1, -2, 0], [-1, 0, 0]], [[1, -2, 0], [1, 0, 0]]]),
        plane('Wall', [[[-1, 0, 0], [-1, 0, 2]], [[1, 0, 0], [1, 0, 2]]]),
      ]);
      await page.evaluate(() => window.knotwork.fillet(0, 1, 0.2, { frontA: true, frontB: true, radiusEnd: 0.5 }));
      await page.waitForFunction(() => window.knotwork.status().objects === 3, null, { timeout: 60_000 });
      s = await status(page);
      assert(s.error === null && /fillet Floor and Wall, radius 0.2/.test(s.last_edit), `varying fillet: ${s.error}, ${s.last_edit}`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

    await check('editing latency in the browser: pick among 10,000 points, drag-to-new-frame', async () => {
      const { page, errors } = await openEditor(browser, url);
      await page.waitForFunction(() => window.knotwork.status().frames >= 1, null, { timeout: 120_000 });
      const canvas = await page.locator('#knotwork-canvas').boundingBox();
      const teapot = (await page.evaluate(() => window.knotwork.project())).objects[0];

      // Pick: a 100 x 100 net (2 segments per span keeps SwiftShader's frame short).
      await openObjects(page, [landscapeObject(100, 2)]);
      await page.evaluate(() => window.knotwork.select(0));
      await page.waitForFunction(() => window.knotwork.status().selected === 0, null, { timeout: 30_000 });
      await nextFrames(page, 1);
      const handles = await page.evaluate(() => window.knotwork.handles());
      const onScreen = handles.filter((h) => h).length;
      assert(onScreen === 10000, `all 10,000 handles on screen: ${onScreen}`);
      const picks = [];
      for (let k = 0; k < 3; k += 1) {
        const [, [hx, hy]] = await freeHandle(page, 0);
        await page.evaluate(() => window.knotwork.selectPoints([]));
        await page.waitForFunction(() => window.knotwork.status().selected_points.length === 0, null, { timeout: 30_000 });
        const t0 = Date.now();
        await page.mouse.click(canvas.x + hx + k, canvas.y + hy);
        await page.waitForFunction(() => window.knotwork.status().selected_points.length === 1, null, { timeout: 30_000 });
        picks.push(Date.now() - t0);
      }

      // Drag-to-new-frame: the teapot tessellated for the view; then, fixed, the teapot at 64
      // segments and a 64 x 64-point bicubic surface at 8.
      await openObjects(page, [teapot]);
      const adaptiveTimes = await dragToFrame(page, canvas);
      const adaptive = await status(page);
      await page.evaluate(() => window.knotwork.setTessellation(false, 0.5));
      await page.waitForFunction(() => window.knotwork.status().tessellation === 'fixed', null, { timeout: 30_000 });
      await openObjects(page, [{ ...teapot, segments: 64 }]);
      assert((await status(page)).vertices === 32 * 65 * 65, 'the teapot at 64 segments');
      const teapotTimes = await dragToFrame(page, canvas);
      await openObjects(page, [landscapeObject(64, 8)]);
      const sheetTimes = await dragToFrame(page, canvas);
      const s = await status(page);
      assert(s.error === null, `error: ${s.error}`);
      console.log(`      pick among 10,000 points (click to selection): ${picks.join(', ')} ms`);
      console.log(`      drag-to-new-frame, teapot adaptive 0.5 px (${adaptive.vertices} vertices): median ${adaptiveTimes[adaptiveTimes.length >> 1]} ms (${adaptiveTimes.join(', ')})`);
      console.log(`      drag-to-new-frame, teapot 64 segments: median ${teapotTimes[teapotTimes.length >> 1]} ms (${teapotTimes.join(', ')})`);
      console.log(`      drag-to-new-frame, 64 x 64 points at 8 per span (${s.vertices} vertices): median ${sheetTimes[sheetTimes.length >> 1]} ms (${sheetTimes.join(', ')})`);
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });

  } finally {
    await browser.close();
  }

  // The WebGL2 fallback, in a browser started without WebGPU.
  const webgl = await chromium.launch({ executablePath: chromiumPath, headless: true, args: webgl2Flags });
  try {
    await check('without WebGPU the editor runs on WebGL2, the CPU evaluating the surfaces', async () => {
      const { page, errors } = await openEditor(webgl, url, { hideWebGpu: true });
      await page.waitForFunction(() => {
        const s = window.knotwork.status();
        return s.frames >= 1 || s.error;
      }, null, { timeout: 120_000 });
      let s = await status(page);
      assert(s.error === null, `error: ${s.error}`);
      assert(s.backend === 'webgl2/gl', `backend ${s.backend}`);
      assert(/CPU/.test(s.evaluator), `evaluator ${s.evaluator}`);
      // The fixed tessellation (the view-adaptive one runs in compute shaders).
      assert(s.tessellation === 'fixed', `tessellation ${s.tessellation}`);
      assert(s.patches === 84 && s.vertices === 32 * 13 * 13 + 52 * 17 * 17, JSON.stringify(s));
      console.log(`      adapter "${s.adapter}", ${s.vertices} vertices, ${s.frame_samples} sample(s)`);
      await page.evaluate(() => window.knotwork.setTessellation(true, 0.5));
      await nextFrames(page, 2);
      s = await status(page);
      assert(s.tessellation === 'fixed', `stays fixed: ${s.tessellation}`);
      const canvas = await page.locator('#knotwork-canvas').boundingBox();
      const viewport = { x: 320, y: 100, width: 900, height: 600 };
      const plain = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/webgl2.png`, plain);
      const stats = await screenshotStats(page, plain, viewport, [33, 36, 41], 12);
      console.log(`      ${stats.differing} of ${stats.total} viewport pixels differ from the background`);
      assert(stats.differing > 0.03 * stats.total, `the viewport looks blank (${stats.differing} px differ)`);

      // A drag with the mouse re-evaluates the moved point's support on the CPU.
      const times = await dragToFrame(page, canvas);
      s = await status(page);
      assert(s.patches_reevaluated >= 1 && s.patches_reevaluated < 84, `re-evaluated ${s.patches_reevaluated}`);
      console.log(`      WebGL2 drag-to-new-frame, demo scene: median ${times[times.length >> 1]} ms (${times.join(', ')})`);
      await page.evaluate(() => window.knotwork.undo());
      await page.waitForFunction(() => (window.knotwork.status().undo_steps - (window.__base ?? 0)) === 0, null, { timeout: 30_000 });

      // A curvature mode from the vertices' curvature.
      assert(await page.evaluate(() => window.knotwork.setShading('mean')), 'mean is a mode');
      await page.waitForFunction(() => window.knotwork.status().shading === 'mean', null, { timeout: 30_000 });
      await nextFrames(page, 2);
      const mean = await page.locator('#knotwork-canvas').screenshot();
      await writeFile(`${resultsDir}/webgl2-mean.png`, mean);
      const changed = await screenshotDifference(page, plain, mean, viewport, 24);
      assert(changed.differing > 0.02 * changed.total, `the mean curvature view looks like the plain one (${changed.differing} px)`);

      // Export and the project file work as on WebGPU.
      const glb = await page.evaluate(async () => Array.from(await window.knotwork.exportGlb({ segments: 4 })));
      const report = summary('webgl2.glb', await validate(new Uint8Array(glb), 'webgl2.glb'));
      assert(report.errors === 0 && report.warnings === 0, `validator: ${JSON.stringify(report)}`);
      const project = await page.evaluate(() => window.knotwork.project());
      assert(project && project.objects.length === 6, 'the project has the six objects');
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });
  } finally {
    await webgl.close();
  }

  // A browser with neither WebGPU nor WebGL2.
  const bare = await chromium.launch({
    executablePath: chromiumPath, headless: true, args: [...webgl2Flags, '--disable-webgl', '--disable-3d-apis'],
  });
  try {
    await check('with neither WebGPU nor WebGL2 the page says so and how to enable them', async () => {
      const { page, errors } = await openEditor(bare, url, { hideWebGpu: true });
      await page.waitForFunction(() => window.knotwork.status().error !== null, null, { timeout: 30_000 });
      const s = await status(page);
      assert(/WebGPU/.test(s.error) && /WebGL2/.test(s.error), `status error: ${s.error}`);
      const text = await page.locator('#message').innerText();
      assert(/Neither WebGPU nor WebGL2/.test(text) && /enable-unsafe-webgpu/.test(text), `message: ${text}`);
      await writeFile(`${resultsDir}/no-gpu.png`, await page.screenshot());
      assert(errors.length === 0, `console errors:\n${errors.join('\n')}`);
      await page.close();
    });
  } finally {
    await bare.close();
    server.close();
    plainServer.close();
  }

  const failed = results.filter((r) => !r.ok).length;
  console.log(`browser: ${results.length - failed} passed, ${failed} failed`);
  process.exit(failed === 0 ? 0 : 1);
}

main().catch((error) => {
  console.log(`FAIL  ${error.stack ?? error}`);
  console.log('browser: 0 passed, 1 failed');
  process.exit(1);
});
