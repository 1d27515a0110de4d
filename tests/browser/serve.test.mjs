// Browser tests of `flourish serve`: Playwright (playwright-core) drives
// Debian's chromium against the real server. Strokes are drawn with pen
// pointer events carrying pressure; each result shown on the page is
// compared byte for byte with the command line's output on the sketch the
// page exports, with the same seed. The latency from stroke end to
// ornament on screen is printed per stroke and as a median.
//
// FLOURISH_BIN names the binary (default: target/release/flourish, else
// target/debug/flourish); UPDATE_SCREENSHOTS=1 writes the README's
// screenshots into docs/.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { startServer } from './server.mjs';
import { mkdtempSync, writeFileSync, readFileSync, existsSync, mkdirSync, rmSync, readdirSync, copyFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const root = resolve(here, '..', '..');
const bin = process.env.FLOURISH_BIN
  || [join(root, 'target/release/flourish'), join(root, 'target/debug/flourish')].find(existsSync);
const work = mkdtempSync(join(tmpdir(), 'flourish-browser-'));
const out = join(here, 'out');
mkdirSync(out, { recursive: true });

let server;
let url;
let context;
let page;
let cdp;
const latencies = [];

before(async () => {
  assert.ok(bin && existsSync(bin), 'build flourish first (cargo build --release)');
  const started = startServer(bin);
  server = started.server;
  url = await started.url;
  context = await chromium.launchPersistentContext(join(work, 'profile'), {
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    acceptDownloads: true,
    viewport: { width: 1100, height: 720 },
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  page = context.pages()[0] || await context.newPage();
  page.on('pageerror', (e) => console.error('page error:', e.message));
  await page.goto(url);
  await page.waitForFunction(() => window.flourish && window.flourish.styles.length > 0);
  cdp = await context.newCDPSession(page);
});

after(async () => {
  if (latencies.length) {
    const s = [...latencies].sort((a, b) => a - b);
    console.log(`latency, stroke end to ornament on screen: median ${Math.round(s[s.length >> 1])} ms ` +
      `over ${s.length} strokes (min ${Math.round(s[0])}, max ${Math.round(s[s.length - 1])})`);
  }
  await context?.close();
  server?.kill();
  rmSync(work, { recursive: true, force: true });
});

/** Page coordinates of document point (x, y). */
async function toPage(x, y) {
  return page.evaluate(([x, y]) => {
    const board = document.getElementById('board');
    const p = board.createSVGPoint();
    p.x = x;
    p.y = y;
    const q = p.matrixTransform(board.getScreenCTM());
    return [q.x, q.y];
  }, [x, y]);
}

/** Draws through document points `pts` with a pen whose pressure goes
 * from 0.2 to 0.9 and back, as real pointer events. */
async function drawPen(pts) {
  const n = pts.length;
  for (let i = 0; i < n; i++) {
    const [x, y] = await toPage(pts[i][0], pts[i][1]);
    const force = 0.2 + 0.7 * Math.sin((Math.PI * i) / (n - 1));
    const type = i === 0 ? 'mousePressed' : 'mouseMoved';
    await cdp.send('Input.dispatchMouseEvent', {
      type, x, y, button: 'left', buttons: 1, clickCount: 1, force, pointerType: 'pen',
    });
  }
  const [x, y] = await toPage(pts[n - 1][0], pts[n - 1][1]);
  await cdp.send('Input.dispatchMouseEvent', {
    type: 'mouseReleased', x, y, button: 'left', buttons: 0, clickCount: 1, force: 0, pointerType: 'pen',
  });
}

/** A wavy line across the page from (x0, y) to (x1, y). */
function wave(x0, x1, y, amp = 40, n = 40) {
  return Array.from({ length: n }, (_, i) => {
    const t = i / (n - 1);
    return [x0 + (x1 - x0) * t, y + amp * Math.sin(t * Math.PI * 2)];
  });
}

/** A closed loop around (cx, cy). */
function loop(cx, cy, r, n = 48) {
  return Array.from({ length: n }, (_, i) => {
    const a = (2 * Math.PI * i) / n;
    return [cx + r * Math.cos(a), cy + 0.8 * r * Math.sin(a)];
  });
}

/** Waits until every stroke shows its synthesized result; returns the
 * latencies new since `seen`. */
async function settled(seen) {
  await page.waitForFunction(() => window.flourish.pending === 0
    && window.flourish.strokes.every((s) => s.status === 'done'), null, { timeout: 60000 });
  const all = await page.evaluate(() => window.flourish.latencies);
  return all.slice(seen);
}

/** The SVG the board shows once the drawing has settled. */
async function shown() {
  await page.waitForFunction(() => window.flourish.shownSvg() !== null, null, { timeout: 60000 });
  return page.evaluate(() => window.flourish.shownSvg());
}

async function choose(mode, style) {
  await page.check(`input[name=mode][value=${mode}]`);
  await page.selectOption('#style', style);
}

/** Clicks `button` and returns the downloaded file's text. */
async function downloaded(button) {
  const [d] = await Promise.all([page.waitForEvent('download'), page.click(button)]);
  const path = join(work, d.suggestedFilename());
  await d.saveAs(path);
  return readFileSync(path, 'utf8');
}

/** The command line's output for `sketch` (text) in `mode` with `style`,
 * `seed` (and a refinement sketch, text). */
function cli(mode, style, seed, sketch, refine) {
  const input = join(work, `cli-${mode}-${style}-${seed}.svg`);
  writeFileSync(input, sketch);
  const output = join(work, `cli-${mode}-${style}-${seed}-out.svg`);
  const args = [mode, '--quiet', '--style', style, '--seed', String(seed), input, '-o', output];
  if (refine) {
    const r = join(work, 'cli-refine.svg');
    writeFileSync(r, refine);
    args.push('--refine', r);
  }
  execFileSync(bin, args);
  return readFileSync(output, 'utf8');
}

async function clear() {
  await page.evaluate(() => {
    while (window.flourish.history.length) document.getElementById('undo').click();
  });
  assert.equal(await page.evaluate(() => window.flourish.strokes.length), 0);
}

test('brush strokes drawn with a pen equal the command line, with pressure widths', { timeout: 120000 }, async () => {
  await choose('brush', 'vine');
  for (const [i, y] of [150, 300, 450].entries()) {
    const seen = await page.evaluate(() => window.flourish.latencies.length);
    await drawPen(wave(80, 720, y, 30 + 10 * i));
    const l = await settled(seen);
    assert.equal(l.length, 1);
    console.log(`brush stroke ${i + 1}: ornament on screen ${Math.round(l[0])} ms after the stroke`);
    latencies.push(l[0]);
  }
  const sketch = await downloaded('#export-sketch');
  const widths = /data-widths="([^"]+)"/.exec(sketch)[1].split(' ').map(Number);
  assert.ok(Math.max(...widths) > 1.5 * Math.min(...widths), `pressure sets the width: ${widths}`);
  const want = cli('brush', 'vine', 0, sketch);
  assert.equal(await shown(), want, 'the board shows what flourish brush gives');
  // The ornament follows the pressure: without its widths the same sketch
  // gives other outlines.
  const flat = sketch.replace(/ data-widths="[^"]+"/g, '');
  assert.notEqual(cli('brush', 'vine', 0, flat), want, 'the widths change the ornament');
  assert.equal(await downloaded('#export-result'), want, 'exported result = flourish brush');
  // Each stroke's own result has the same ornament (rounded alike or finer).
  const own = await page.evaluate(() => window.flourish.strokes.map((s) => s.svg));
  for (const svg of own) {
    const first = /<g id="(s-\d+)">\n<path fill="([^"]+)"/.exec(svg);
    assert.ok(first && want.includes(first[0]), 'a stroke result has its group');
  }
  await page.screenshot({ path: join(out, 'serve-brush.png') });
  if (process.env.UPDATE_SCREENSHOTS) {
    await page.screenshot({ path: join(root, 'docs/serve-brush.png') });
  }
});

test('another one draws one stroke again, the others stay; undo takes it back', { timeout: 120000 }, async () => {
  const before = await page.evaluate(() => window.flourish.strokes.map((s) => s.svg));
  const n = before.length;
  assert.ok(n >= 2, 'strokes from the first test');
  await page.click('#another');
  await settled(0);
  let after = await page.evaluate(() => window.flourish.strokes.map((s) => s.svg));
  assert.deepEqual(after.slice(0, n - 1), before.slice(0, n - 1), 'the other strokes keep their ornament');
  assert.notEqual(after[n - 1], before[n - 1], 'the last stroke is another one');
  let sketch = await downloaded('#export-sketch');
  assert.equal((sketch.match(/data-seed="1"/g) || []).length, 1, 'one stroke has a seed of its own');
  assert.equal(await shown(), cli('brush', 'vine', 0, sketch));
  assert.equal(await downloaded('#export-result'), cli('brush', 'vine', 0, sketch));
  // The another tool picks the first stroke.
  await page.check('input[name=tool][value=another]');
  const first = await page.evaluate(() => window.flourish.strokes[0].id);
  const [x, y] = await page.evaluate((id) => {
    const r = document.querySelector(`#sketch path[data-stroke="${id}"]`).getBoundingClientRect();
    return [r.x + r.width / 2, r.y + r.height / 2];
  }, first);
  const hit = await page.evaluate(([x, y]) => document.elementFromPoint(x, y)?.closest('[data-stroke]')?.dataset.stroke, [x, y]);
  assert.equal(hit, first, 'the first stroke is under the pointer');
  await page.mouse.click(x, y);
  await settled(0);
  const again = await page.evaluate(() => window.flourish.strokes.map((s) => s.svg));
  assert.notEqual(again[0], after[0], 'the picked stroke is another one');
  assert.deepEqual(again.slice(1), after.slice(1), 'the others stay');
  await page.click('#undo');
  await settled(0);
  await page.check('input[name=tool][value=draw]');
  await page.click('#undo');
  await settled(0);
  after = await page.evaluate(() => window.flourish.strokes.map((s) => s.svg));
  assert.deepEqual(after, before, 'undo takes the seed back');
  sketch = await downloaded('#export-sketch');
  assert.ok(!sketch.includes('data-seed'), 'no seed of its own left');
});

test('reseed all takes the next seed for the drawing, and undo takes it back', { timeout: 120000 }, async () => {
  const before = await page.evaluate(() => window.flourish.strokes.map((s) => s.svg));
  await page.click('#reseed');
  await settled(0);
  assert.equal(await page.textContent('#seed'), '1');
  const after = await page.evaluate(() => window.flourish.strokes.map((s) => s.svg));
  assert.notDeepEqual(after, before, 'the next seed gives other ornament');
  const sketch = await downloaded('#export-sketch');
  assert.equal(await shown(), cli('brush', 'vine', 1, sketch));
  assert.equal(await downloaded('#export-result'), cli('brush', 'vine', 1, sketch));
  await page.click('#undo');
  await settled(0);
  assert.equal(await page.textContent('#seed'), '0');
  assert.deepEqual(await page.evaluate(() => window.flourish.strokes.map((s) => s.svg)), before);
});

test('erase removes a stroke and undo brings it back; undo removes strokes', { timeout: 120000 }, async () => {
  const n = await page.evaluate(() => window.flourish.strokes.length);
  await page.check('input[name=tool][value=erase]');
  const [x, y] = await toPage(400, 150);
  const id = await page.evaluate(([x, y]) => document.elementFromPoint(x, y)?.closest('[data-stroke]')?.dataset.stroke, [x, y]);
  assert.ok(id, 'a stroke is under the pointer');
  await page.mouse.click(x, y);
  assert.equal(await page.evaluate(() => window.flourish.strokes.length), n - 1);
  assert.equal(await page.locator(`#results > g[data-stroke="${id}"]`).count(), 0);
  await page.click('#undo');
  await settled(0);
  assert.equal(await page.evaluate(() => window.flourish.strokes.length), n);
  await page.check('input[name=tool][value=draw]');
  await page.click('#undo');
  assert.equal(await page.evaluate(() => window.flourish.strokes.length), n - 1);
  assert.equal(await page.locator('#results > g').count(), n - 1);
  await clear();
});

test('refine strokes add and erase ornament as flourish brush --refine does', { timeout: 120000 }, async () => {
  await choose('brush', 'vine');
  await drawPen(wave(80, 720, 280, 40));
  await settled(0);
  const plain = await shown();
  await page.check('input[name=tool][value=refine-erase]');
  await drawPen([[400, 200], [400, 240], [400, 280], [400, 320], [400, 360]]);
  await settled(0);
  const sketch = await downloaded('#export-sketch');
  const refine = await downloaded('#export-refine');
  assert.match(refine, /stroke="white"/);
  const refined = await shown();
  assert.notEqual(refined, plain, 'the erase stroke changes the ornament');
  assert.equal(refined, cli('brush', 'vine', 0, sketch, refine));
  await page.screenshot({ path: join(out, 'serve-refine.png') });
  await page.click('#undo');
  await settled(0);
  assert.equal(await shown(), plain, 'undo takes the refinement back');
  await page.check('input[name=tool][value=draw]');
  await clear();
});

test('a closed shape in fill mode is filled as the command line fills it', { timeout: 120000 }, async () => {
  await choose('fill', 'knot');
  const seen = await page.evaluate(() => window.flourish.latencies.length);
  await drawPen(loop(400, 280, 170));
  const l = await settled(seen);
  console.log(`fill shape: ornament on screen ${Math.round(l[0])} ms after the stroke`);
  const sketch = await downloaded('#export-sketch');
  assert.match(sketch, /Z" fill="black"/);
  assert.equal(await shown(), cli('fill', 'knot', 0, sketch));
  assert.equal(await downloaded('#export-result'), cli('fill', 'knot', 0, sketch));
  await page.screenshot({ path: join(out, 'serve-fill.png') });
  await clear();
});

test('pattern strokes equal the command line', { timeout: 120000 }, async () => {
  await choose('pattern', 'flowers');
  await drawPen(wave(100, 700, 280, 60));
  await settled(0);
  const sketch = await downloaded('#export-sketch');
  assert.equal(await shown(), cli('pattern', 'flowers', 0, sketch));
  assert.equal(await downloaded('#export-result'), cli('pattern', 'flowers', 0, sketch));
  await clear();
});

test('an imported sketch is synthesized and exports as it came in', { timeout: 120000 }, async () => {
  await choose('brush', 'scroll');
  await drawPen(wave(100, 700, 200, 50));
  await drawPen(wave(100, 700, 400, 50));
  await settled(0);
  const sketch = await downloaded('#export-sketch');
  const result = await downloaded('#export-result');
  await clear();
  assert.equal(await page.evaluate(() => window.flourish.strokes.length), 0);
  await page.setInputFiles('#import', { name: 'sketch.svg', mimeType: 'image/svg+xml', buffer: Buffer.from(sketch) });
  await page.waitForFunction(() => window.flourish.strokes.length === 2);
  await settled(0);
  const again = await downloaded('#export-sketch');
  // Ids are renumbered on import; the shapes are the same.
  const shapes = (s) => s.replace(/id="s-\d+"/g, '');
  assert.equal(shapes(again), shapes(sketch));
  assert.equal(await downloaded('#export-result'), cli('brush', 'scroll', 0, again));
  assert.equal(shapes(await downloaded('#export-result')), shapes(result));
  await clear();
});

test('dropped exemplars become a brush style that brushes as the command line does', { timeout: 180000 }, async () => {
  // Three of the shipped vine exemplars, as a designer's own drawings.
  const src = join(root, 'styles/vine');
  const names = readdirSync(src).filter((n) => n.endsWith('.svg')).sort().slice(0, 3);
  await page.check('input[name=mode][value=brush]');
  await page.setInputFiles('#own', names.map((n) => ({
    name: n, mimeType: 'image/svg+xml', buffer: readFileSync(join(src, n)),
  })));
  await page.waitForFunction(() => (window.flourish.ownStyles || []).length === 1, null, { timeout: 120000 });
  const made = await page.evaluate(() => window.flourish.ownStyles[0]);
  assert.equal(made.kind, 'brush');
  assert.equal(made.exemplars, 3);
  assert.equal(await page.inputValue('#style'), made.name);
  assert.equal(await page.locator('#exemplars img').count(), 3);
  await drawPen(wave(100, 700, 280, 40));
  await settled(0);
  const sketch = await downloaded('#export-sketch');
  // The same drawings made a style by the command line.
  const dir = join(work, 'own-style');
  mkdirSync(dir, { recursive: true });
  names.forEach((n, i) => copyFileSync(join(src, n), join(dir, `exemplar-0${i + 1}.svg`)));
  execFileSync(bin, ['style', 'init', '--quiet', dir]);
  const input = join(work, 'own-sketch.svg');
  writeFileSync(input, sketch);
  const output = join(work, 'own-out.svg');
  execFileSync(bin, ['brush', '--quiet', '--style', dir, '--seed', '0', input, '-o', output]);
  assert.equal(await shown(), readFileSync(output, 'utf8'));
  await page.screenshot({ path: join(out, 'serve-own-style.png') });
  // Downloaded as a style folder, it brushes the same from the command line.
  const [d] = await Promise.all([page.waitForEvent('download'), page.click('#download-style')]);
  const zipPath = join(work, d.suggestedFilename());
  await d.saveAs(zipPath);
  const unpacked = join(work, 'unzipped');
  execFileSync('python3', ['-m', 'zipfile', '-e', zipPath, unpacked]);
  const output2 = join(work, 'own-out-2.svg');
  execFileSync(bin, ['brush', '--quiet', '--styles', unpacked, '--style', made.name, '--seed', '0', input, '-o', output2]);
  assert.equal(readFileSync(output2, 'utf8'), readFileSync(output, 'utf8'));
  await clear();
});

test('a malformed request gets a 4xx and the page keeps working', { timeout: 120000 }, async () => {
  const codes = await page.evaluate(async () => {
    const post = (body) => fetch('/api/synthesize', { method: 'POST', body }).then((r) => r.status);
    return [
      await post('{not json'),
      await post(JSON.stringify({ sketch: '<svg', mode: 'brush', style: 'vine' })),
      await post(JSON.stringify({ sketch: '<svg xmlns="http://www.w3.org/2000/svg"/>', mode: 'brush', style: '../../etc' })),
      await post(JSON.stringify({ sketch: 'x', mode: 'paint', style: 'vine' })),
      await fetch('/api/styles/vine/exemplars/99').then((r) => r.status),
    ];
  });
  for (const c of codes) assert.ok(c >= 400 && c < 500, `4xx: ${codes}`);
  await choose('brush', 'vine');
  const seen = await page.evaluate(() => window.flourish.latencies.length);
  await drawPen(wave(100, 700, 280, 40));
  const l = await settled(seen);
  latencies.push(l[0]);
  const sketch = await downloaded('#export-sketch');
  assert.equal(await downloaded('#export-result'), cli('brush', 'vine', 0, sketch));
  await clear();
});
