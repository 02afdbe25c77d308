// End-to-end test of the editor in headless Chromium (Debian's package), driven by
// playwright-core. Starts the editor's server, opens the page and, through real mouse
// events on the plan view: adds three nodes with the chain tool and closes the loop,
// switches the new cell to Suburbia in the cell inspector, drags a node, undoes the
// drag; after each step it checks the page's state (`window.polis`). Any page error,
// failed request or unmet expectation fails the test (exit code 1).
//
//   node editor.test.mjs                   the test (server binary from $EDITOR_BIN)
//   BENCH=200 node editor.test.mjs         then 200 scripted edits: round-trip p50/p95
//
// Environment: EDITOR_BIN (default ../../../target/debug/examples/editor), EDITOR_ARGS
// (extra server arguments, space-separated), OUT (output dir, default ./out), CHROMIUM
// (default /usr/bin/chromium).

import { spawn } from 'node:child_process';
import { mkdirSync, mkdtempSync, writeFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const BIN = process.env.EDITOR_BIN || resolve(here, '../../../target/debug/examples/editor');
const ARGS = (process.env.EDITOR_ARGS || '--preset citygen --size 1600').split(' ').filter(Boolean);
const OUT = resolve(process.env.OUT || join(here, 'out'));
const BENCH = parseInt(process.env.BENCH || '0', 10);
const STEP_TIMEOUT = 60_000;

mkdirSync(OUT, { recursive: true });
let failures = 0;
let passes = 0;
function check(cond, what) {
  if (cond) {
    passes++;
    console.log(`ok   ${what}`);
  } else {
    failures++;
    console.log(`FAIL ${what}`);
  }
  return cond;
}

function startServer() {
  return new Promise((resolveUrl, reject) => {
    const proc = spawn(BIN, [...ARGS, '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
    proc.stderr.on('data', (d) => process.stderr.write(`server: ${d}`));
    let buf = '';
    const timer = setTimeout(() => reject(new Error('the server printed no URL within 5 minutes')), 300_000);
    proc.stdout.on('data', (d) => {
      buf += d.toString();
      const m = buf.match(/http:\/\/\S+\//);
      if (m) {
        clearTimeout(timer);
        resolveUrl({ proc, url: m[0] });
      }
    });
    proc.on('exit', (code) => reject(new Error(`the server exited with ${code}`)));
    proc.on('error', reject);
  });
}

const { proc, url } = await startServer();
// Whatever happens below, the server goes with this process.
process.on('exit', () => proc.kill());
const profile = mkdtempSync(join(tmpdir(), 'polis-e2e-'));
// A fresh profile directory: playwright takes it as the persistent context's user data
// dir (it refuses --user-data-dir in `args`).
const context = await chromium.launchPersistentContext(profile, {
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  headless: true,
  viewport: { width: 1600, height: 900 },
  args: [
    '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
  ],
});

async function finish() {
  if (failures) {
    // The server's output log helps to see why.
    try {
      const res = await fetch(new URL('/api/log', url));
      for (const line of (await res.json()).slice(-30)) console.log(`log  ${line}`);
    } catch (_) {}
  }
  await context.close().catch(() => {});
  proc.kill();
  rmSync(profile, { recursive: true, force: true });
  console.log(`${passes} passed, ${failures} failed`);
  process.exit(failures ? 1 : 0);
}

try {
  const page = context.pages()[0] || (await context.newPage());
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  page.on('console', (m) => m.type() === 'error' && pageErrors.push(m.text()));
  if (process.env.DEBUG) page.on('request', (r) => r.url().endsWith('/api/apply') && console.log(`apply ${r.postData()}`));
  await page.goto(url);
  await page.waitForFunction(() => window.polis && window.polis.ready(), null, { timeout: STEP_TIMEOUT });
  const start = await page.evaluate(() => window.polis.summary());
  console.log('scene', JSON.stringify(start));
  check(start.nodes > 0 && start.cells > 0 && start.buildings > 0, 'the page shows a generated city');

  // Canvas-relative pixels to page coordinates (the canvas's box is read every time).
  const toPage = async (x, y) => {
    const box = await page.locator('#plan').boundingBox();
    const [sx, sy] = await page.evaluate(([x, y]) => window.polis.toScreen(x, y), [x, y]);
    return [box.x + sx, box.y + sy];
  };
  const click = async (x, y) => {
    const [px, py] = await toPage(x, y);
    await page.mouse.move(px, py, { steps: 4 });
    await page.mouse.click(px, py);
  };
  const waitRevision = async (after) =>
    page.waitForFunction((r) => window.polis.state.revision > r && !window.polis.state.busy, after, { timeout: STEP_TIMEOUT });
  const revision = () => page.evaluate(() => window.polis.state.revision);

  // A triangle well inside the largest city cell: around the sample point farthest from
  // its boundary, with a third of that clearance as radius.
  const tri = await page.evaluate(() => {
    const s = window.polis.state;
    let best = null;
    for (const [id, c] of s.cells) if (!best || c.area > best.c.area) best = { id, c };
    const ring = best.c.ring;
    const [x0, y0, x1, y1] = best.c.bbox;
    const inside = (x, y) => {
      let r = false;
      for (let i = 0, j = ring.length / 2 - 1; i < ring.length / 2; j = i++) {
        const xi = ring[2 * i], yi = ring[2 * i + 1], xj = ring[2 * j], yj = ring[2 * j + 1];
        if ((yi > y) !== (yj > y) && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) r = !r;
      }
      return r;
    };
    const clearance = (x, y) => {
      let d = Infinity;
      const roads = [...s.roads.values()].map((r) => r.pts);
      for (const p of [ring, ...roads]) for (let i = 0; i + 3 < p.length; i += 2) {
        const ax = p[i], ay = p[i + 1], dx = p[i + 2] - ax, dy = p[i + 3] - ay;
        const l2 = dx * dx + dy * dy;
        const t = l2 ? Math.max(0, Math.min(1, ((x - ax) * dx + (y - ay) * dy) / l2)) : 0;
        d = Math.min(d, Math.hypot(x - ax - t * dx, y - ay - t * dy));
      }
      return d;
    };
    let c = null;
    for (let i = 1; i < 24; i++) for (let j = 1; j < 24; j++) {
      const x = x0 + ((x1 - x0) * i) / 24, y = y0 + ((y1 - y0) * j) / 24;
      if (!inside(x, y)) continue;
      const d = clearance(x, y);
      if (!c || d > c.d) c = { x, y, d };
    }
    // At most 200 m: the plotted primary roads follow the terrain and bend more over
    // longer sides, and on the full preset a 400 m triangle's closing road met its first
    // side at 5° (refused below the 15° minimum).
    const r = Math.min(c.d * 0.6, 200);
    const pts = [0, 1, 2].map((k) => [c.x + r * Math.cos(Math.PI / 2 + (2 * Math.PI * k) / 3), c.y + r * Math.sin(Math.PI / 2 + (2 * Math.PI * k) / 3)]);
    return { cell: best.id, centre: [c.x, c.y], r, pts };
  });
  console.log('triangle', JSON.stringify(tri));
  check(tri.r > 30, 'found room for a new loop inside a city cell');

  // Zoom the plan view onto the triangle so clicks are precise.
  await page.evaluate(([cx, cy, r]) => {
    const p = window.polis.plan;
    p.fit([cx - 2.5 * r, cy - 2.5 * r, cx + 2.5 * r, cy + 2.5 * r]);
  }, [tri.centre[0], tri.centre[1], tri.r]);

  // --- chain tool: three nodes and the closing click ---
  await page.click('#modes button[data-mode=node]');
  await page.click('#tools button[data-tool=add]');
  let rev = await revision();
  await click(...tri.pts[0]);
  await waitRevision(rev);
  const afterFirst = await page.evaluate(() => ({ ...window.polis.summary(), chain: window.polis.state.chain }));
  check(afterFirst.nodes === start.nodes + 1 && afterFirst.chain != null, 'Add Node made a node and started a chain from it');
  const a = afterFirst.chain;
  for (const p of tri.pts.slice(1)) {
    rev = await revision();
    // Moving the cursor shows the preview (Fig. 69) before the click commits.
    const [px, py] = await toPage(...p);
    await page.mouse.move(px, py, { steps: 6 });
    await page.waitForFunction(() => window.polis.state.preview !== null, null, { timeout: STEP_TIMEOUT });
    const preview = await page.evaluate(() => window.polis.state.preview);
    check(preview.ok && preview.proposed.length > 0 && preview.roads.length > 0, 'the chain preview has a red proposed and a green corrected road');
    await page.mouse.click(px, py);
    await waitRevision(rev);
  }
  rev = await revision();
  await click(...tri.pts[0]); // back on the first node: closes the loop
  await waitRevision(rev);
  const loop = await page.evaluate((a) => {
    const s = window.polis.state;
    return { ...window.polis.summary(), chain: s.chain, a: s.nodes.get(a) };
  }, a);
  check(loop.nodes === start.nodes + 3, `three nodes added (${start.nodes} → ${loop.nodes})`);
  check(loop.roads === start.roads + 3, `three roads added (${start.roads} → ${loop.roads})`);
  check(loop.chain === a, 'closing the loop snapped to the first node and the chain continues from it');
  const newCell = await page.evaluate(([x, y]) => {
    const id = window.polis.plan.hitCell(x, y);
    const c = id == null ? null : window.polis.state.cells.get(id);
    return c && { id, area: c.area, pattern: c.pattern };
  }, tri.centre);
  const triArea = (3 * Math.sqrt(3) / 4) * tri.r * tri.r;
  check(newCell && Math.abs(newCell.area - triArea) < 0.1 * triArea, `the loop is a new city cell (area ${newCell && newCell.area.toFixed(0)} m², triangle ${triArea.toFixed(0)} m²)`);
  await page.keyboard.press('Escape');
  await page.screenshot({ path: join(OUT, '1-loop.png') });

  // --- cell edit: Suburbia ---
  await page.click('#modes button[data-mode=cell]');
  await click(...tri.centre);
  await page.waitForSelector('#cell-preset', { timeout: STEP_TIMEOUT });
  rev = await revision();
  await page.selectOption('#cell-preset', 'suburbia');
  await waitRevision(rev);
  const sub = await page.evaluate(([x, y]) => {
    const p = window.polis;
    const id = p.plan.hitCell(x, y);
    const c = p.state.cells.get(id);
    // Buildings whose first corner lies in this cell (and in no smaller one).
    let buildings = 0;
    for (const b of p.state.blocks.values()) {
      for (const f of b.buildings) if (p.plan.hitCell(f.ring[0], f.ring[1]) === id) buildings++;
    }
    return { id, pattern: c.pattern, buildings, streets: c.streets.length };
  }, tri.centre);
  check(sub.pattern === 'suburbia', `the new cell is Suburbia (${sub.pattern})`);
  check(sub.streets > 0 && sub.buildings > 0, `Suburbia grew in it: ${sub.streets} street segments, ${sub.buildings} buildings`);
  await page.screenshot({ path: join(OUT, '2-suburbia.png') });

  // --- node edit: drag node a, then undo ---
  await page.click('#modes button[data-mode=node]');
  await page.click('#tools button[data-tool=select]');
  const before = await page.evaluate((a) => window.polis.state.nodes.get(a), a);
  // Outward from the loop's centre (node a is its top corner) and a little aside, so the
  // loop grows and its two roads at a cannot be re-plotted across each other. Where the
  // roads plotted over the terrain still would cross or meet at too sharp an angle (the
  // full citygen preset refused the first such target), the server's preview picks the
  // first of a few targets it accepts: the drag below must then commit.
  const dragTo = await page.evaluate(async ([a, r]) => {
    const n = window.polis.state.nodes.get(a);
    const candidates = [];
    for (const scale of [0.2, 0.12, 0.3]) {
      for (const turn of [0.05, -0.05, 0.5, -0.5, 1.0, -1.0]) {
        candidates.push([n.x + turn * scale * r, n.y + scale * r]);
      }
    }
    for (const to of candidates) {
      const pv = await window.polis.preview({ op: 'move_node', node: a, to });
      if (pv.ok) return to;
    }
    return candidates[0];
  }, [a, tri.r]);
  rev = await revision();
  {
    const [sx, sy] = await toPage(before.x, before.y);
    const [tx, ty] = await toPage(...dragTo);
    await page.mouse.move(sx, sy);
    await page.mouse.down();
    await page.mouse.move(tx, ty, { steps: 8 });
    await page.waitForFunction(() => window.polis.state.preview !== null, null, { timeout: STEP_TIMEOUT });
    // Fig. 69 while dragging: the proposed roads in red, the corrected ones in green.
    const pv = await page.evaluate(() => window.polis.state.preview);
    check(pv.ok && pv.proposed.length === 2 && pv.roads.length === 2, 'dragging previews both roads of the node');
    await page.screenshot({ path: join(OUT, '3-drag-preview.png') });
    await page.mouse.up();
  }
  await waitRevision(rev);
  const moved = await page.evaluate((a) => window.polis.state.nodes.get(a), a);
  check(Math.hypot(moved.x - dragTo[0], moved.y - dragTo[1]) < 2, `the drag moved the node to the cursor (${moved.x.toFixed(1)}, ${moved.y.toFixed(1)})`);
  await page.screenshot({ path: join(OUT, '3-dragged.png') });
  rev = await revision();
  await page.click('#undo');
  await waitRevision(rev);
  const undone = await page.evaluate((a) => ({ n: window.polis.state.nodes.get(a), s: window.polis.summary() }), a);
  check(Math.hypot(undone.n.x - before.x, undone.n.y - before.y) < 1e-6, 'undo put the node back');
  check(undone.s.nodes === loop.nodes && undone.s.roads === loop.roads, 'undo kept the loop');
  const cellAgain = await page.evaluate(([x, y]) => window.polis.state.cells.get(window.polis.plan.hitCell(x, y)).pattern, tri.centre);
  check(cellAgain === 'suburbia', 'undo of the drag kept the Suburbia cell');

  // The 3-D view drew something: read its pixels.
  const lit = await page.evaluate(() => {
    const v = window.polis.view;
    v.draw();
    const gl = v.gl;
    // The whole picture: a line through the middle can fall on plain ground alone.
    const [w, h] = [gl.drawingBufferWidth, gl.drawingBufferHeight];
    const px = new Uint8Array(4 * w * h);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const colours = new Set();
    for (let i = 0; i < px.length; i += 4) colours.add(`${px[i]},${px[i + 1]},${px[i + 2]}`);
    return { buffers: v.buffers.size, colours: colours.size };
  });
  check(lit.buffers > 1 && lit.colours > 1, `the 3-D view has ${lit.buffers} buffers and draws a varied image`);

  // Exports answer with files.
  for (const f of ['geojson', 'svg', 'stats']) {
    const r = await page.evaluate(async (f) => {
      const res = await fetch(`/api/export/${f}`);
      return { status: res.status, size: (await res.arrayBuffer()).byteLength };
    }, f);
    check(r.status === 200 && r.size > 100, `export ${f}: ${r.size} bytes`);
  }
  await page.screenshot({ path: join(OUT, '4-final.png') });

  if (BENCH > 0) await bench(page, a, tri);

  check(pageErrors.length === 0, `no page errors${pageErrors.length ? ': ' + pageErrors.join(' | ') : ''}`);
  const errors = await page.evaluate(() => window.polis.state.errors);
  check(errors === 0, `no failed requests (${errors})`);
} catch (e) {
  failures++;
  console.log(`FAIL ${e.stack || e}`);
}
await finish();

// Round trip over BENCH scripted edits through the page's own commit path: alternately
// move the loop's first node by a few metres and set a growth parameter of the cell.
async function bench(page, node, tri) {
  const result = await page.evaluate(async ([node, n, centre]) => {
    const p = window.polis;
    const cell = p.plan.hitCell(centre[0], centre[1]);
    const start = p.state.nodes.get(node);
    // The moves: 6 m from the node's start in 24 directions, those the server accepts
    // from the start (asked before the clock runs; a move it would refuse re-plots no
    // roads and regrows no cell, so it would not be the edit being timed).
    const moves = [];
    for (let k = 0; k < 24; k++) {
      const a = (k / 24) * 2 * Math.PI;
      const to = [start.x + 6 * Math.cos(a), start.y + 6 * Math.sin(a)];
      if ((await p.preview({ op: 'move_node', node, to })).ok) moves.push(to);
    }
    if (moves.length === 0) moves.push([start.x, start.y]);
    const first = p.state.roundTrips.length;
    const draws = [];
    for (let i = 0; i < n; i++) {
      if (i % 2 === 0) {
        await p.commit({ op: 'move_node', node, to: moves[(i / 2) % moves.length] });
      } else {
        const c = p.state.cells.get(p.plan.hitCell(centre[0], centre[1])) ? p.plan.hitCell(centre[0], centre[1]) : cell;
        await p.commit({ op: 'set_cell_param', cell: c, param: { building_height: { value: 6 + (i % 7), deviance: 0.1 } } });
      }
      await new Promise((r) => requestAnimationFrame(() => r()));
      draws.push(p.plan.drawMs);
    }
    return { rt: p.state.roundTrips.slice(first), server: p.state.serverMs.slice(first), edit: p.state.editMs.slice(first), draws, errors: p.state.errors, moves: moves.length };
  }, [node, BENCH, tri.centre]);
  const q = (xs, f) => {
    const s = [...xs].sort((x, y) => x - y);
    return s[Math.min(s.length - 1, Math.floor(f * s.length))];
  };
  const row = (name, xs) => `${name}: p50 ${q(xs, 0.5).toFixed(1)} ms, p95 ${q(xs, 0.95).toFixed(1)} ms, max ${Math.max(...xs).toFixed(1)} ms`;
  const lines = [
    `${result.rt.length} edits (${ARGS.join(' ')}; node moves among ${result.moves} accepted targets)`,
    row('round trip', result.rt),
    row('server', result.server),
    row('  of which the editor (apply + regenerate)', result.edit),
    row('  of which the page (round trip − server)', result.rt.map((x, i) => x - result.server[i])),
    row('plan redraw', result.draws),
  ];
  for (const l of lines) console.log(`bench ${l}`);
  writeFileSync(join(OUT, 'bench.txt'), lines.join('\n') + '\n');
  check(result.errors === 0 && result.rt.length === BENCH, `bench: ${BENCH} edits without error`);
}
