// flourish serve: the painting page. Strokes are kept in document units
// (the sketch's px); each finished stroke is shown at once as a stand-in
// and sent alone to /api/synthesize, whose result SVG replaces it. The
// exported result is the server's synthesis of the whole sketch, so it is
// exactly what the command line gives for the exported sketch and seed.
'use strict';

const SVG_NS = 'http://www.w3.org/2000/svg';
const $ = (id) => document.getElementById(id);

/** The page's state; `window.flourish` for tests and the console. */
const state = {
  W: 800, // document width, px
  H: 560, // document height, px
  styles: [], // [{name, kind, exemplars}]
  // [{id, mode, style, points: [[x, y, w]], widths, seed, closed, gen, svg, status}]:
  // `widths` the pressure widths at evenly spaced positions along the
  // stroke (its data-widths; null when constant), `seed` its own seed
  // (data-seed; undefined: the drawing's).
  strokes: [],
  refine: [], // refinement strokes over brush results: [{points: [[x, y, w]], add}]
  history: [], // undo entries: {type: 'add'|'erase'|'seed'|'stroke-seed'|'refine', ...}
  current: null, // the stroke "another one" draws again: the last drawn
  seed: 0,
  nextId: 1,
  generation: 0,
  view: { x: 0, y: 0, w: 800, h: 560 },
  latencies: [], // ms from stroke end to ornament on screen
  pending: 0, // syntheses in flight
  settled: null, // {key, svg}: the whole drawing synthesized at once, when current
};
window.flourish = state;

const fmt = (v) => String(Math.round(v * 100) / 100);

function mode() {
  return document.querySelector('input[name=mode]:checked').value;
}

function tool() {
  return document.querySelector('input[name=tool]:checked').value;
}

function status(text, cls) {
  const s = $('status');
  s.textContent = text;
  s.className = cls || '';
}

// ---- styles ---------------------------------------------------------

/** The chosen style per mode, remembered when the mode changes. */
const chosen = {};

async function loadStyles() {
  const r = await fetch('/api/styles');
  const body = await r.json();
  state.styles = body.styles;
  fillStylePicker();
  status('draw a stroke');
}

function fillStylePicker() {
  const m = mode();
  const sel = $('style');
  sel.replaceChildren();
  for (const s of state.styles.filter((s) => s.kind === m)) {
    const o = document.createElement('option');
    o.value = s.name;
    o.textContent = s.name;
    sel.append(o);
  }
  if (chosen[m]) sel.value = chosen[m];
  showExemplars();
}

function showExemplars() {
  const name = $('style').value;
  const style = state.styles.find((s) => s.name === name);
  const aside = $('exemplars');
  aside.replaceChildren();
  // A style made here can be taken home as a style folder.
  const own = /^mine-(\d+)$/.exec(name || '');
  const link = $('download-style');
  link.hidden = !own;
  if (own) {
    link.href = `/api/uploads/${own[1]}/zip`;
    link.download = `${name}.zip`;
  }
  if (!style) return;
  for (let i = 0; i < style.exemplars; i++) {
    const img = document.createElement('img');
    img.alt = `${name} exemplar ${i + 1}`;
    img.src = `/api/styles/${encodeURIComponent(name)}/exemplars/${i}`;
    aside.append(img);
  }
}

/** Makes `files` (dropped or chosen) a style of the current mode on the
 * server, shows its check's warnings, and picks it. */
async function ownStyle(files) {
  const kind = mode();
  const post = async (url, body) => {
    const r = await fetch(url, { method: 'POST', body });
    const reply = await r.json().catch(() => ({ error: `HTTP ${r.status}` }));
    if (r.status !== 200) throw new Error(reply.error || `HTTP ${r.status}`);
    return reply;
  };
  try {
    status(`making a ${kind} style of ${files.length} exemplars…`);
    const { id } = await post('/api/uploads');
    for (const f of files) await post(`/api/uploads/${id}/files`, f);
    const made = await post(`/api/uploads/${id}/style/${kind}`);
    await loadStyles();
    chosen[kind] = made.name;
    fillStylePicker();
    const warn = made.warnings.length ? `: ${made.warnings.join('; ')}` : '';
    status(`style ${made.name} (${made.kind}, ${made.exemplars} exemplars)${warn}`, warn ? 'warn' : '');
    state.ownStyles = (state.ownStyles || []).concat([made]);
  } catch (e) {
    status(`new style: ${e.message}`, 'error');
  }
}

function kindOf(name) {
  const s = state.styles.find((s) => s.name === name);
  return s ? s.kind : null;
}

// ---- the sketch -----------------------------------------------------

function pathData(stroke) {
  const p = stroke.points;
  let d = `M${fmt(p[0][0])} ${fmt(p[0][1])}`;
  for (let i = 1; i < p.length; i++) d += ` L${fmt(p[i][0])} ${fmt(p[i][1])}`;
  return stroke.closed ? d + ' Z' : d;
}

/** The stroke's width in px: the mean of its points' pressure widths. */
function meanWidth(stroke) {
  const p = stroke.points;
  return Math.round((p.reduce((a, q) => a + q[2], 0) / p.length) * 100) / 100;
}

/** The arc length from a polyline's start to each of its points. */
function arcLengths(points) {
  const at = [0];
  for (let i = 1; i < points.length; i++) {
    at.push(at[i - 1] + Math.hypot(points[i][0] - points[i - 1][0], points[i][1] - points[i - 1][1]));
  }
  return at;
}

/** Most values of a stroke's `data-widths`. */
const MAX_WIDTHS = 32;

/** The stroke's pressure widths as `data-widths` has them: at `n` evenly
 * spaced positions along its length, first at the start and last at the
 * end (rounded to 0.01 px); null when they are all the same. */
function widthProfile(points) {
  const at = arcLengths(points);
  const total = at[at.length - 1];
  const n = Math.max(2, Math.min(MAX_WIDTHS, points.length));
  const out = [];
  let j = 0;
  for (let i = 0; i < n; i++) {
    const s = (total * i) / (n - 1);
    while (j < at.length - 2 && at[j + 1] < s) j++;
    const span = at[j + 1] - at[j];
    const f = span > 0 ? Math.min(1, Math.max(0, (s - at[j]) / span)) : 0;
    const w = points[j][2] * (1 - f) + points[Math.min(j + 1, points.length - 1)][2] * f;
    out.push(Math.max(0.01, Math.round(w * 100) / 100));
  }
  return out.every((w) => w === out[0]) ? null : out;
}

/** The value of evenly spaced `widths` at `share` (0..1) of the length. */
function profileAt(widths, share) {
  if (widths.length === 1) return widths[0];
  const x = Math.min(1, Math.max(0, share)) * (widths.length - 1);
  const i = Math.min(widths.length - 2, Math.floor(x));
  return widths[i] * (1 - (x - i)) + widths[i + 1] * (x - i);
}

/** The stroke width written for an open stroke: the mean of its
 * `data-widths` over the length (the command line reads it so), else its
 * points' mean. */
function strokeWidth(stroke) {
  const w = stroke.widths;
  if (!w) return meanWidth(stroke);
  let sum = 0.5 * (w[0] + w[w.length - 1]);
  for (let i = 1; i < w.length - 1; i++) sum += w[i];
  return Math.round((sum / (w.length - 1)) * 100) / 100;
}

function shapeElement(stroke) {
  const attrs = [`id="${stroke.id}"`, `data-style="${stroke.style}"`];
  if (stroke.seed !== undefined) attrs.push(`data-seed="${stroke.seed}"`);
  attrs.push(`d="${pathData(stroke)}"`);
  if (stroke.closed) {
    attrs.push('fill="black"');
  } else {
    attrs.push('fill="none" stroke="black"', `stroke-width="${fmt(strokeWidth(stroke))}"`,
      'stroke-linecap="round" stroke-linejoin="round"');
    if (stroke.widths) attrs.push(`data-widths="${stroke.widths.map(fmt).join(' ')}"`);
  }
  return `<path ${attrs.join(' ')}/>`;
}

/** The sketch SVG of `strokes` (default: all of them). */
function sketchSvg(strokes) {
  const list = strokes || state.strokes;
  return `<svg xmlns="http://www.w3.org/2000/svg" width="${state.W}" height="${state.H}" ` +
    `viewBox="0 0 ${state.W} ${state.H}">\n` +
    list.map((s) => '  ' + shapeElement(s) + '\n').join('') + '</svg>\n';
}
state.sketchSvg = sketchSvg;

/** The refinement sketch (DecoBrush §5.5; the command line's
 * `--refine`): black strokes add ornament, white ones erase it. */
function refineSvg() {
  return `<svg xmlns="http://www.w3.org/2000/svg" width="${state.W}" height="${state.H}" ` +
    `viewBox="0 0 ${state.W} ${state.H}">\n` +
    state.refine.map((r) => `  <path d="${pathData({ points: r.points })}" fill="none" ` +
      `stroke="${r.add ? 'black' : 'white'}" stroke-width="${fmt(meanWidth(r))}" ` +
      'stroke-linecap="round" stroke-linejoin="round"/>\n').join('') + '</svg>\n';
}
state.refineSvg = refineSvg;

/** The request that synthesizes `strokes` as the command line would. */
function request(strokes, lane, generation) {
  const styles = new Set(strokes.map((s) => s.style));
  const one = styles.size === 1 ? [...styles][0] : null;
  const mode = one ? kindOf(one) : 'decorate';
  const body = {
    sketch: sketchSvg(strokes),
    mode,
    style: one,
    seed: state.seed,
    lane,
    generation,
  };
  if (mode === 'brush' && state.refine.length) body.refine = refineSvg();
  return body;
}
state.request = request;

async function synthesize(body) {
  const r = await fetch('/api/synthesize', {
    method: 'POST',
    headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify(body),
  });
  const reply = await r.json().catch(() => ({ error: `HTTP ${r.status}` }));
  return { status: r.status, reply };
}

// ---- drawing on the board ---------------------------------------------

function strokeLayer(stroke) {
  let g = document.querySelector(`#results > g[data-stroke="${stroke.id}"]`);
  if (!g) {
    g = document.createElementNS(SVG_NS, 'g');
    g.dataset.stroke = stroke.id;
    $('results').append(g);
  }
  return g;
}

/** An open stroke's outline with its pressure widths: each point offset
 * by half its width along the normal, both sides, closed. */
function outlineData(stroke) {
  const p = stroke.points;
  const left = [];
  const right = [];
  for (let i = 0; i < p.length; i++) {
    const a = p[Math.max(0, i - 1)];
    const b = p[Math.min(p.length - 1, i + 1)];
    const len = Math.hypot(b[0] - a[0], b[1] - a[1]) || 1;
    const nx = -(b[1] - a[1]) / len;
    const ny = (b[0] - a[0]) / len;
    const h = p[i][2] / 2;
    left.push(`${fmt(p[i][0] + nx * h)} ${fmt(p[i][1] + ny * h)}`);
    right.push(`${fmt(p[i][0] - nx * h)} ${fmt(p[i][1] - ny * h)}`);
  }
  return `M${left.join(' L')} L${right.reverse().join(' L')} Z`;
}

/** The sketch's drawing of `stroke`: a filled shape, or the outline of
 * its pressure widths. */
function sketchPath(stroke) {
  const path = document.createElementNS(SVG_NS, 'path');
  if (stroke.closed) {
    path.setAttribute('d', pathData(stroke));
    path.setAttribute('class', 'fill');
  } else {
    path.setAttribute('d', outlineData(stroke));
    path.setAttribute('class', 'pressure');
  }
  path.dataset.stroke = stroke.id;
  return path;
}

/** Draws every stroke again in drawing order: sketch lines and results. */
function redraw() {
  unsettle();
  scheduleSettle();
  const sketch = $('sketch');
  sketch.replaceChildren(...state.strokes.map((s) => sketchPath(s)));
  const results = $('results');
  const keep = new Set(state.strokes.map((s) => s.id));
  for (const g of [...results.children]) if (!keep.has(g.dataset.stroke)) g.remove();
  for (const s of state.strokes) results.append(strokeLayer(s));
}

function showStandIn(stroke) {
  const g = strokeLayer(stroke);
  g.setAttribute('class', 'standin');
  g.replaceChildren(sketchPath(stroke));
}

function showResult(stroke, svgText) {
  const doc = new DOMParser().parseFromString(svgText, 'image/svg+xml');
  const root = doc.documentElement;
  if (root.nodeName !== 'svg') throw new Error('the result is not an SVG');
  const node = document.importNode(root, true);
  node.setAttribute('x', '0');
  node.setAttribute('y', '0');
  node.setAttribute('width', String(state.W));
  node.setAttribute('height', String(state.H));
  const g = strokeLayer(stroke);
  g.removeAttribute('class');
  g.replaceChildren(node);
}

/** Sends `stroke` alone for synthesis; a newer request for it wins. */
async function run(stroke, started) {
  const generation = ++state.generation;
  stroke.gen = generation;
  stroke.status = 'pending';
  unsettle();
  showStandIn(stroke);
  state.pending++;
  try {
    const { status: code, reply } = await synthesize(request([stroke], stroke.id, generation));
    if (stroke.gen !== generation || !state.strokes.includes(stroke)) return;
    if (code !== 200) {
      if (code === 409) return;
      stroke.status = 'failed';
      const g = strokeLayer(stroke);
      g.setAttribute('class', 'failed');
      status(reply.error || `HTTP ${code}`, 'error');
      return;
    }
    stroke.svg = reply.svg;
    stroke.status = 'done';
    showResult(stroke, reply.svg);
    await new Promise((r) => requestAnimationFrame(() => r()));
    const ms = performance.now() - started;
    state.latencies.push(ms);
    const warn = reply.warnings && reply.warnings.length ? ` — ${reply.warnings.join('; ')}` : '';
    status(`${stroke.id}: ornament on screen ${Math.round(ms)} ms after the stroke ` +
      `(synthesis ${Math.round(reply.ms)} ms)${warn}`, warn ? 'warn' : '');
  } catch (e) {
    if (stroke.gen === generation) {
      stroke.status = 'failed';
      status(`${stroke.id}: ${e.message}`, 'error');
    }
  } finally {
    state.pending--;
    scheduleSettle();
  }
}

// ---- the settled drawing ----------------------------------------------
// Each stroke is first shown as synthesized alone. Once every stroke has
// its result and the drawing has been still for SETTLE_MS, the whole
// sketch is synthesized at once and shown instead: that SVG is exactly the
// command line's output for the exported sketch and seed (a stroke alone
// can be written with fewer decimals than in the whole drawing).

const SETTLE_MS = 400;
let settleTimer = 0;

/** The key of the drawing as it is now: the request that synthesizes it. */
function drawingKey() {
  const r = request(state.strokes);
  return JSON.stringify([r.sketch, r.mode, r.style, r.seed, r.refine || null]);
}

/** Forgets the settled drawing (something changed) and shows the strokes. */
function unsettle() {
  clearTimeout(settleTimer);
  if (state.settling) {
    // The drawing changed under its synthesis: the server ends it.
    state.settling = 0;
    fetch('/api/cancel', {
      method: 'POST',
      headers: { 'Content-Type': 'application/json' },
      body: JSON.stringify({ lane: 'drawing', generation: ++state.generation }),
    }).catch(() => {});
  }
  state.settled = null;
  $('settled').replaceChildren();
  $('results').removeAttribute('display');
}

function scheduleSettle() {
  clearTimeout(settleTimer);
  settleTimer = setTimeout(settle, SETTLE_MS);
}

async function settle() {
  if (!state.strokes.length || state.pending > 0) return;
  if (state.strokes.some((s) => s.status !== 'done')) return;
  const key = drawingKey();
  if (state.settled && state.settled.key === key) return;
  const generation = ++state.generation;
  state.settling = generation;
  const { status: code, reply } = await synthesize(request(state.strokes, 'drawing', generation));
  const stale = state.settling !== generation;
  if (!stale) state.settling = 0;
  if (stale || code !== 200 || drawingKey() !== key) return;
  state.settled = { key, svg: reply.svg };
  const doc = new DOMParser().parseFromString(reply.svg, 'image/svg+xml');
  const node = document.importNode(doc.documentElement, true);
  node.setAttribute('x', '0');
  node.setAttribute('y', '0');
  node.setAttribute('width', String(state.W));
  node.setAttribute('height', String(state.H));
  $('settled').replaceChildren(node);
  $('results').setAttribute('display', 'none');
}

/** The SVG the board shows once settled (the command line's output), or null. */
state.shownSvg = () => (state.settled && state.settled.key === drawingKey() ? state.settled.svg : null);

function toDoc(e) {
  const board = $('board');
  const pt = board.createSVGPoint();
  pt.x = e.clientX;
  pt.y = e.clientY;
  const p = pt.matrixTransform(board.getScreenCTM().inverse());
  return [p.x, p.y];
}

/** A point's width in px: the width slider, scaled by pen or touch pressure. */
function widthAt(e) {
  const base = Number($('width').value);
  if (e.pointerType !== 'mouse' && e.pressure > 0) {
    return Math.max(1, base * (0.4 + 1.2 * e.pressure));
  }
  return base;
}

let drawing = null; // the stroke being drawn
let panning = null; // {x, y, view} at the start of a pan

function onDown(e) {
  if (e.button === 1 || tool() === 'pan') {
    panning = { x: e.clientX, y: e.clientY, view: { ...state.view } };
    $('board').setPointerCapture(e.pointerId);
    return;
  }
  if (e.button !== 0) return;
  if (tool() === 'erase' || tool() === 'another') {
    const id = e.target.closest('[data-stroke]')?.dataset.stroke || e.target.closest('#settled g[id]')?.id;
    const i = state.strokes.findIndex((s) => s.id === id);
    if (i >= 0 && tool() === 'another') {
      anotherOne(state.strokes[i]);
    } else if (i >= 0) {
      const [stroke] = state.strokes.splice(i, 1);
      state.history.push({ type: 'erase', stroke, index: i });
      redraw();
      status(`${stroke.id} erased`);
    }
    return;
  }
  const [x, y] = toDoc(e);
  if (tool().startsWith('refine')) {
    drawing = { refine: true, add: tool() === 'refine-add', points: [[x, y, widthAt(e)]] };
    $('board').setPointerCapture(e.pointerId);
    updateLive();
    return;
  }
  const style = $('style').value;
  if (!style) return;
  drawing = {
    id: `s-${state.nextId++}`,
    mode: mode(),
    style,
    points: [[x, y, widthAt(e)]],
    closed: mode() === 'fill',
  };
  $('board').setPointerCapture(e.pointerId);
  updateLive();
}

function onMove(e) {
  if (panning) {
    const board = $('board');
    const k = panning.view.w / board.getBoundingClientRect().width;
    state.view.x = panning.view.x - (e.clientX - panning.x) * k;
    state.view.y = panning.view.y - (e.clientY - panning.y) * k;
    applyView();
    return;
  }
  if (!drawing) return;
  const events = e.getCoalescedEvents ? e.getCoalescedEvents() : [e];
  for (const ev of events.length ? events : [e]) {
    const [x, y] = toDoc(ev);
    const last = drawing.points[drawing.points.length - 1];
    if (Math.hypot(x - last[0], y - last[1]) >= 2) drawing.points.push([x, y, widthAt(ev)]);
  }
  updateLive();
}

function onUp(e) {
  if (panning) {
    panning = null;
    return;
  }
  if (!drawing) return;
  const started = performance.now();
  const stroke = drawing;
  drawing = null;
  $('live').setAttribute('d', '');
  const p = stroke.points;
  let length = 0;
  for (let i = 1; i < p.length; i++) length += Math.hypot(p[i][0] - p[i - 1][0], p[i][1] - p[i - 1][1]);
  if (length < 4 || p.length < (stroke.closed ? 3 : 2)) return;
  if (stroke.refine) {
    const item = { points: stroke.points, add: stroke.add };
    state.refine.push(item);
    state.history.push({ type: 'refine', item });
    drawRefine();
    rerunAll(started);
    return;
  }
  if (!stroke.closed) stroke.widths = widthProfile(stroke.points);
  state.strokes.push(stroke);
  state.history.push({ type: 'add', stroke });
  state.current = stroke;
  redraw();
  run(stroke, started);
}

function updateLive() {
  const live = $('live');
  if (!drawing) return;
  live.setAttribute('d', pathData({ ...drawing, closed: false }));
  live.setAttribute('stroke-width', fmt(meanWidth(drawing)));
  live.setAttribute('stroke-opacity', '0.4');
}

// ---- undo, another one ------------------------------------------------

function undo() {
  const h = state.history.pop();
  if (!h) return;
  if (h.type === 'add') {
    state.strokes = state.strokes.filter((s) => s !== h.stroke);
    h.stroke.gen = -1;
  } else if (h.type === 'erase') {
    state.strokes.splice(h.index, 0, h.stroke);
  } else if (h.type === 'refine') {
    state.refine = state.refine.filter((r) => r !== h.item);
    drawRefine();
    rerunAll();
    status('undone');
    return;
  } else if (h.type === 'seed') {
    setSeed(h.seed);
    redraw();
    rerunAll();
    return;
  } else if (h.type === 'stroke-seed') {
    h.stroke.seed = h.seed;
    if (state.strokes.includes(h.stroke)) run(h.stroke, performance.now());
    status('undone');
    return;
  }
  redraw();
  if (h.type === 'erase') {
    const g = strokeLayer(h.stroke);
    if (h.stroke.svg && h.stroke.status === 'done') showResult(h.stroke, h.stroke.svg);
    else run(h.stroke, performance.now());
    g.dataset.stroke = h.stroke.id;
  }
  status('undone');
}

function setSeed(seed) {
  state.seed = seed;
  $('seed').textContent = String(seed);
}

function rerunAll(started) {
  const t = started || performance.now();
  unsettle();
  for (const s of state.strokes) run(s, t);
}

/** Draws the refinement strokes over the board. */
function drawRefine() {
  $('refine').replaceChildren(...state.refine.map((r) => {
    const p = document.createElementNS(SVG_NS, 'path');
    p.setAttribute('d', pathData({ points: r.points }));
    p.setAttribute('stroke-width', fmt(meanWidth(r)));
    p.setAttribute('class', r.add ? 'add' : 'erase');
    return p;
  }));
}

/** Another one of the whole drawing: the next seed for every stroke
 * without a seed of its own. */
function reseedAll() {
  state.history.push({ type: 'seed', seed: state.seed });
  setSeed(state.seed + 1);
  rerunAll();
}

/** Another one of `stroke` alone: its own next seed (`data-seed`), so the
 * other strokes keep their ornament. */
function anotherOne(stroke) {
  state.history.push({ type: 'stroke-seed', stroke, seed: stroke.seed });
  stroke.seed = (stroke.seed === undefined ? state.seed : stroke.seed) + 1;
  state.current = stroke;
  run(stroke, performance.now());
  status(`${stroke.id}: seed ${stroke.seed}`);
}

/** The button: another one of the last stroke drawn (or picked). */
function another() {
  const s = state.current;
  if (s && state.strokes.includes(s)) anotherOne(s);
  else status('draw a stroke first, or pick one with the "another" tool');
}

// ---- zoom and pan -----------------------------------------------------

function applyView() {
  const v = state.view;
  $('board').setAttribute('viewBox', `${v.x} ${v.y} ${v.w} ${v.h}`);
}

function zoom(k, cx, cy) {
  const v = state.view;
  const x = cx === undefined ? v.x + v.w / 2 : cx;
  const y = cy === undefined ? v.y + v.h / 2 : cy;
  const w = Math.min(Math.max(v.w * k, state.W / 20), state.W * 8);
  const s = w / v.w;
  state.view = { x: x - (x - v.x) * s, y: y - (y - v.y) * s, w, h: v.h * s };
  applyView();
}

function fit() {
  state.view = { x: 0, y: 0, w: state.W, h: state.H };
  const paper = $('paper');
  paper.setAttribute('width', String(state.W));
  paper.setAttribute('height', String(state.H));
  applyView();
}

// ---- export and import ------------------------------------------------

function download(name, text) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([text], { type: 'image/svg+xml' }));
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

/** The whole sketch synthesized at once: the command line's output. */
async function resultSvg() {
  if (!state.strokes.length) throw new Error('nothing drawn yet');
  const shown = state.shownSvg();
  if (shown) return shown;
  const { status: code, reply } = await synthesize(request(state.strokes));
  if (code !== 200) throw new Error(reply.error || `HTTP ${code}`);
  return reply.svg;
}
state.resultSvg = resultSvg;

async function exportResult() {
  try {
    status('synthesizing the whole sketch…');
    download('flourish-result.svg', await resultSvg());
    status(`exported the result (seed ${state.seed})`);
  } catch (e) {
    status(`export: ${e.message}`, 'error');
  }
}

/** Points of an SVG path that is a polyline written by this page, or null. */
function polylinePoints(d) {
  const m = /^\s*M\s*(-?[\d.]+)[\s,]+(-?[\d.]+)((?:\s*L\s*-?[\d.]+[\s,]+-?[\d.]+)*)\s*(Z?)\s*$/i.exec(d || '');
  if (!m) return null;
  const pts = [[Number(m[1]), Number(m[2])]];
  for (const l of m[3].matchAll(/L\s*(-?[\d.]+)[\s,]+(-?[\d.]+)/gi)) pts.push([Number(l[1]), Number(l[2])]);
  return { pts, closed: m[4] !== '' };
}

/** Reads a sketch SVG's shapes as strokes (any shape, sampled every 3 px). */
function importSketch(text) {
  const doc = new DOMParser().parseFromString(text, 'image/svg+xml');
  const root = doc.documentElement;
  if (root.nodeName !== 'svg' || doc.querySelector('parsererror')) throw new Error('not an SVG file');
  const vb = (root.getAttribute('viewBox') || '').trim().split(/[\s,]+/).map(Number);
  const W = vb.length === 4 && vb[2] > 0 ? vb[2] : parseFloat(root.getAttribute('width')) || 800;
  const H = vb.length === 4 && vb[3] > 0 ? vb[3] : parseFloat(root.getAttribute('height')) || 560;
  const ox = vb.length === 4 ? vb[0] : 0;
  const oy = vb.length === 4 ? vb[1] : 0;
  // Measure in a hidden copy, so transforms and any shape kind count.
  const host = document.createElementNS(SVG_NS, 'svg');
  host.setAttribute('viewBox', `${ox} ${oy} ${W} ${H}`);
  host.setAttribute('width', String(W));
  host.setAttribute('height', String(H));
  host.style.position = 'absolute';
  host.style.visibility = 'hidden';
  for (const c of [...root.childNodes]) host.append(document.importNode(c, true));
  document.body.append(host);
  const strokes = [];
  try {
    for (const el of host.querySelectorAll('path, line, polyline, polygon, rect, circle, ellipse')) {
      const cs = getComputedStyle(el);
      const filled = cs.fill !== 'none';
      const stroked = cs.stroke !== 'none';
      if (!filled && !stroked) continue;
      let style = el.closest('[data-style]')?.getAttribute('data-style') || null;
      const wanted = filled ? 'fill' : mode() === 'fill' ? 'brush' : mode();
      if (!style || !kindOf(style)) style = chosen[wanted] || state.styles.find((s) => s.kind === wanted)?.name;
      if (!style) continue;
      let width = parseFloat(cs.strokeWidth) || 20;
      const list = (el.getAttribute('data-widths') || '').trim().split(/[\s,]+/).filter((t) => t).map(Number);
      const widths = !filled && list.length && list.every((w) => Number.isFinite(w) && w > 0) ? list : null;
      const seedText = el.closest('[data-seed]')?.getAttribute('data-seed');
      const seed = seedText && /^\d+$/.test(seedText.trim()) ? Number(seedText.trim()) : undefined;
      let pts;
      let closed = filled;
      const own = el.nodeName === 'path' && !el.getAttribute('transform') ? polylinePoints(el.getAttribute('d')) : null;
      const m = el.getCTM();
      const hm = host.getCTM();
      if (own && m && hm && m.a === hm.a && m.d === hm.d && m.e === hm.e && m.f === hm.f) {
        pts = own.pts;
        closed = own.closed || filled;
      } else {
        const len = el.getTotalLength();
        const n = Math.max(2, Math.ceil(len / 3));
        const toUser = hm.inverse().multiply(m);
        pts = [];
        for (let i = 0; i <= n; i++) {
          const p = el.getPointAtLength((len * i) / n).matrixTransform(toUser);
          pts.push([p.x, p.y]);
        }
      }
      const at = arcLengths(pts);
      const total = at[at.length - 1] || 1;
      const stroke = {
        id: `s-${state.nextId++}`,
        mode: kindOf(style),
        style,
        points: pts.map(([x, y], i) => [x - ox, y - oy, widths ? profileAt(widths, at[i] / total) : width]),
        widths: widths && widths.length > 1 && !widths.every((w) => w === widths[0]) ? widths : null,
        closed,
      };
      if (seed !== undefined && Number.isSafeInteger(seed)) stroke.seed = seed;
      strokes.push(stroke);
    }
  } finally {
    host.remove();
  }
  state.W = W;
  state.H = H;
  fit();
  for (const s of state.strokes) s.gen = -1;
  state.strokes = strokes;
  state.refine = [];
  drawRefine();
  state.history = strokes.map((stroke) => ({ type: 'add', stroke }));
  state.current = strokes[strokes.length - 1] || null;
  redraw();
  rerunAll();
  status(`imported ${strokes.length} shapes`);
}
state.importSketch = importSketch;

// ---- wiring -----------------------------------------------------------

function wire() {
  const board = $('board');
  board.addEventListener('pointerdown', onDown);
  board.addEventListener('pointermove', onMove);
  board.addEventListener('pointerup', onUp);
  board.addEventListener('pointercancel', onUp);
  board.addEventListener('wheel', (e) => {
    e.preventDefault();
    const [x, y] = toDoc(e);
    zoom(e.deltaY > 0 ? 1.15 : 1 / 1.15, x, y);
  }, { passive: false });
  for (const r of document.querySelectorAll('input[name=mode]')) {
    r.addEventListener('change', fillStylePicker);
  }
  for (const r of document.querySelectorAll('input[name=tool]')) {
    r.addEventListener('change', () => { board.setAttribute('class', tool()); });
  }
  $('style').addEventListener('change', () => {
    chosen[mode()] = $('style').value;
    showExemplars();
  });
  $('width').addEventListener('input', () => { $('width-value').textContent = $('width').value; });
  $('undo').addEventListener('click', undo);
  $('another').addEventListener('click', another);
  $('reseed').addEventListener('click', reseedAll);
  $('zoom-in').addEventListener('click', () => zoom(1 / 1.25));
  $('zoom-out').addEventListener('click', () => zoom(1.25));
  $('zoom-reset').addEventListener('click', fit);
  $('export-result').addEventListener('click', exportResult);
  $('export-sketch').addEventListener('click', () => download('flourish-sketch.svg', sketchSvg()));
  $('export-refine').addEventListener('click', () => download('flourish-refine.svg', refineSvg()));
  const drop = $('drop');
  drop.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('over'); });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    const files = [...e.dataTransfer.files];
    if (files.length) ownStyle(files);
  });
  $('own').addEventListener('change', (e) => {
    const files = [...e.target.files];
    e.target.value = '';
    if (files.length) ownStyle(files);
  });
  $('import').addEventListener('change', async (e) => {
    const file = e.target.files[0];
    if (!file) return;
    try {
      importSketch(await file.text());
    } catch (err) {
      status(`import: ${err.message}`, 'error');
    }
    e.target.value = '';
  });
  document.addEventListener('keydown', (e) => {
    if ((e.ctrlKey || e.metaKey) && e.key === 'z') {
      e.preventDefault();
      undo();
    }
  });
}

wire();
loadStyles().catch((e) => status(`styles: ${e.message}`, 'error'));
