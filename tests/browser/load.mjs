// Load test of `flourish serve` on the loopback interface: CLIENTS clients
// draw at once for SECONDS seconds, each sending a brush stroke, waiting
// for its ornament, then pausing as a person does before the next stroke
// (THINK_MS). Fails on any error, on a request slower than 5 s, or on the
// server's peak resident memory above 2 GB; prints the latencies and the
// memory. Bounded: it stops by itself after SECONDS (+ the last replies).
//
// FLOURISH_BIN names the binary (default target/release/flourish, else
// target/debug/flourish).

import { startServer } from './server.mjs';
import { existsSync, readFileSync } from 'node:fs';
import { join, dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const CLIENTS = Number(process.env.CLIENTS || 20);
const SECONDS = Number(process.env.SECONDS_RUN || 30);
const THINK_MS = Number(process.env.THINK_MS || 1500);
const LIMIT_MS = 5000;
const MEMORY_LIMIT_KB = 2 * 1024 * 1024;

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
const bin = process.env.FLOURISH_BIN
  || [join(root, 'target/release/flourish'), join(root, 'target/debug/flourish')].find(existsSync);
if (!bin) {
  console.error('load test: build flourish first');
  process.exit(1);
}

const started = startServer(bin);
const server = started.server;
const url = await started.url;

/** Resident memory of the server now and at its peak, in KB. */
function memory() {
  const status = readFileSync(`/proc/${server.pid}/status`, 'utf8');
  const kb = (key) => Number(new RegExp(`${key}:\\s+(\\d+)`).exec(status)?.[1] || 0);
  return { rss: kb('VmRSS'), hwm: kb('VmHWM') };
}

/** A stroke of client `c`, number `n`: a wave at a height of its own. */
function sketch(c, n) {
  const y = 60 + ((c * 37 + n * 11) % 440);
  const amp = 20 + ((c + n) % 4) * 10;
  const pts = Array.from({ length: 30 }, (_, i) => {
    const t = i / 29;
    return `${(80 + 640 * t).toFixed(2)} ${(y + amp * Math.sin(t * Math.PI * 2)).toFixed(2)}`;
  });
  return '<svg xmlns="http://www.w3.org/2000/svg" width="800" height="560" viewBox="0 0 800 560">'
    + `<path id="s-${n}" data-style="vine" d="M${pts.join(' L')}" fill="none" stroke="black" stroke-width="20"/></svg>`;
}

const styles = ['vine', 'scroll', 'doodle'];
const times = [];
const errors = [];
const end = Date.now() + SECONDS * 1000;
let peakRss = 0;
const sampler = setInterval(() => { peakRss = Math.max(peakRss, memory().rss); }, 500);

async function client(c) {
  // People do not lift their pens at the same millisecond: each client
  // starts at its own moment within the first pause.
  await new Promise((r) => setTimeout(r, (THINK_MS * c) / CLIENTS));
  for (let n = 1; Date.now() < end; n++) {
    const body = JSON.stringify({
      sketch: sketch(c, n).replace('data-style="vine"', `data-style="${styles[c % 3]}"`),
      mode: 'brush',
      style: styles[c % 3],
      seed: n,
      lane: `c${c}-s${n}`,
      generation: 1,
    });
    const t0 = performance.now();
    try {
      const r = await fetch(`${url}api/synthesize`, { method: 'POST', body });
      const reply = await r.json();
      if (r.status !== 200 || !reply.svg) errors.push(`client ${c}: HTTP ${r.status} ${reply.error || ''}`);
    } catch (e) {
      errors.push(`client ${c}: ${e.message}`);
    }
    times.push(performance.now() - t0);
    await new Promise((r) => setTimeout(r, THINK_MS));
  }
}

// Styles analysed before the clock starts, as a running server has them.
for (const s of styles) {
  await fetch(`${url}api/synthesize`, {
    method: 'POST',
    body: JSON.stringify({ sketch: sketch(0, 0).replace('vine', s), mode: 'brush', style: s }),
  });
}
await Promise.all(Array.from({ length: CLIENTS }, (_, c) => client(c)));
clearInterval(sampler);
const { hwm } = memory();
server.kill();

const sorted = [...times].sort((a, b) => a - b);
const q = (f) => Math.round(sorted[Math.min(sorted.length - 1, Math.floor(f * sorted.length))]);
console.log(`load: ${CLIENTS} clients, ${SECONDS} s, ${THINK_MS} ms between strokes: ${times.length} strokes, `
  + `${errors.length} errors; latency median ${q(0.5)} ms, 95th ${q(0.95)} ms, max ${q(1)} ms; `
  + `server peak resident memory ${Math.round(hwm / 1024)} MB`);
const failed = [];
if (errors.length) failed.push(`errors: ${errors.slice(0, 3).join('; ')}`);
if (sorted[sorted.length - 1] > LIMIT_MS) failed.push(`a request took ${q(1)} ms (limit ${LIMIT_MS})`);
if (hwm > MEMORY_LIMIT_KB) failed.push(`peak memory ${Math.round(hwm / 1024)} MB (limit ${MEMORY_LIMIT_KB / 1024} MB)`);
console.log(`${failed.length ? 0 : 1} passed, ${failed.length ? 1 : 0} failed`);
if (failed.length) {
  console.error(`load test: ${failed.join('; ')}`);
  process.exit(1);
}
