// The editor page: state, the server protocol, edit modes and tools (Kelly §5), the
// property inspector and the output log. `window.polis` exposes the state for tests and
// for the curious (read it in the browser's console).

import { Plan, ringBBox, ringArea } from './plan.js';
import { View3d } from './view3d.js';

const state = {
  ready: false,
  revision: 0,
  bounds: [-1000, -1000, 1000, 1000],
  nodes: new Map(), // id → {x, y, label}
  roads: new Map(), // id → {a, b, w, pts, spec}
  cells: new Map(), // city cell id → {ring, bbox, area, pattern, streets}
  blocks: new Map(), // road-graph cell id → {rings, bbox, lots, buildings}
  presets: [],
  roadPresets: [],
  roadDefaults: null,
  layer: 'all',
  mode: 'view',
  tool: null,
  selection: { node: null, road: null, cell: null },
  hover: { node: null },
  chain: null, // the node the chain tool continues from
  preview: null, // {ok, proposed: [[x,y,…]], roads: [{w, pts}], nodes: [{x,y}], message}
  roadFrom: null, // the add-road tool's first node
  log: [],
  roundTrips: [], // ms from request to the page's state updated, per committed edit
  serverMs: [], // the server's share (Server-Timing), per committed edit
  editMs: [], // the editor's part of it (applying and regenerating)
  errors: 0,
  busy: false,
};

const TOOLS = {
  view: [],
  node: [['select', 'Select'], ['add', 'Add (chain)'], ['delete', 'Delete']],
  road: [['select', 'Select'], ['add', 'Add'], ['delete', 'Delete']],
  cell: [['select', 'Select']],
};

const $ = (id) => document.getElementById(id);
const plan = new Plan($('plan'), state);
const view = new View3d($('view3d'), state);

// ---- output log ----

function log(text, error = false) {
  const t = new Date().toISOString().slice(11, 19);
  state.log.push({ t, text, error });
  if (state.log.length > 500) state.log.shift();
  const el = $('log');
  const line = document.createElement('div');
  line.textContent = `${t}  ${text}`;
  if (error) line.className = 'err';
  el.appendChild(line);
  while (el.childNodes.length > 500) el.removeChild(el.firstChild);
  el.scrollTop = el.scrollHeight;
}

// ---- server protocol ----

async function call(method, url, body) {
  const init = { method, headers: {} };
  if (body !== undefined) {
    init.headers['Content-Type'] = 'application/json';
    init.body = JSON.stringify(body);
  }
  const res = await fetch(url, init);
  const text = await res.text();
  let data = null;
  try {
    data = text ? JSON.parse(text) : null;
  } catch (_) {
    data = { error: text };
  }
  // `edit;dur=…, total;dur=…`: the editor's share and the server's whole time.
  const timing = res.headers.get('Server-Timing') || '';
  const dur = (name) => {
    const m = timing.match(new RegExp(`${name};dur=([0-9.]+)`));
    return m ? parseFloat(m[1]) : NaN;
  };
  const serverMs = dur('total');
  const editMs = dur('edit');
  if (!res.ok) {
    const err = new Error((data && data.error) || `${res.status} ${res.statusText}`);
    err.status = res.status;
    throw err;
  }
  return { data, serverMs, editMs };
}

function cellFromWire(c) {
  return { ring: c.ring, bbox: ringBBox(c.ring), area: ringArea(c.ring), pattern: c.pattern, streets: c.streets, skipped: c.skipped };
}

function blockFromWire(b) {
  let bbox = [Infinity, Infinity, -Infinity, -Infinity];
  for (const r of [...b.rings, ...b.lots]) {
    const q = ringBBox(r);
    bbox = [Math.min(bbox[0], q[0]), Math.min(bbox[1], q[1]), Math.max(bbox[2], q[2]), Math.max(bbox[3], q[3])];
  }
  return { rings: b.rings, lots: b.lots, buildings: b.buildings, bbox };
}

// Applies a scene or a delta from the server; returns what the 3-D view must rebuild.
function applyDelta(d) {
  for (const id of d.nodes_removed || []) state.nodes.delete(id);
  for (const id of d.roads_removed || []) state.roads.delete(id);
  for (const id of d.cells_removed || []) state.cells.delete(id);
  for (const id of d.blocks_removed || []) state.blocks.delete(id);
  for (const n of d.nodes || []) state.nodes.set(n.id, { x: n.x, y: n.y, label: n.label });
  for (const r of d.roads || []) state.roads.set(r.id, { a: r.a, b: r.b, w: r.w, pts: r.pts, spec: r.spec });
  const changed = [];
  for (const c of d.cells || []) {
    state.cells.set(c.id, cellFromWire(c));
    changed.push('c' + c.id);
  }
  for (const b of d.blocks || []) {
    state.blocks.set(b.id, blockFromWire(b));
    changed.push('b' + b.id);
  }
  state.revision = d.revision;
  for (const k of ['node', 'road', 'cell']) {
    const map = k === 'node' ? state.nodes : k === 'road' ? state.roads : state.cells;
    if (state.selection[k] != null && !map.has(state.selection[k])) state.selection[k] = null;
  }
  if (state.chain != null && !state.nodes.has(state.chain)) state.chain = null;
  for (const line of d.log || []) log(line);
  const removed = [...(d.cells_removed || []).map((id) => 'c' + id), ...(d.blocks_removed || []).map((id) => 'b' + id)];
  return { changed, removed };
}

async function loadScene() {
  const { data } = await call('GET', '/api/scene');
  state.nodes.clear();
  state.roads.clear();
  state.cells.clear();
  state.blocks.clear();
  state.bounds = data.bounds;
  state.presets = data.presets;
  state.roadPresets = data.road_presets;
  state.roadDefaults = data.road_defaults;
  applyDelta(data);
  plan.fit(state.bounds);
  view.fit(state.bounds);
  view.rebuild();
  updateInspector();
  state.ready = true;
  log(`scene: ${state.nodes.size} nodes, ${state.roads.size} primary roads, ${state.cells.size} city cells, ${state.blocks.size} blocks`);
}

// Commits an action; records the round trip (request sent → state and buffers updated).
async function commit(action) {
  return run('POST', '/api/apply', action);
}

async function run(method, url, body) {
  state.busy = true;
  const t0 = performance.now();
  try {
    const { data, serverMs, editMs } = await call(method, url, body);
    const { changed, removed } = applyDelta(data);
    view.update(changed, removed);
    state.roundTrips.push(performance.now() - t0);
    state.serverMs.push(serverMs);
    state.editMs.push(editMs);
    state.preview = null;
    plan.requestDraw();
    updateInspector();
    $('status').textContent = `rev ${state.revision} · ${changed.length} cells and blocks updated · ${(performance.now() - t0).toFixed(0)} ms (server ${serverMs.toFixed(1)} ms)`;
    return data;
  } catch (e) {
    state.errors++;
    log(`${url}: ${e.message}`, true);
    return null;
  } finally {
    state.busy = false;
  }
}

// Proposes an action while the cursor moves: at most one request in flight, the latest
// position wins.
let previewWanted = null;
let previewInFlight = false;
function propose(action) {
  previewWanted = action;
  if (!previewInFlight) pumpPreview();
}
async function pumpPreview() {
  while (previewWanted) {
    const action = previewWanted;
    previewWanted = null;
    previewInFlight = true;
    try {
      const { data } = await call('POST', '/api/preview', action);
      state.preview = data;
      if (!data.ok && data.message) $('status').textContent = `would be refused: ${data.message}`;
    } catch (e) {
      state.preview = null;
    }
    previewInFlight = false;
    plan.requestDraw();
  }
}
function clearPreview() {
  previewWanted = null;
  state.preview = null;
  plan.requestDraw();
}

// ---- modes and tools ----

function setMode(mode) {
  state.mode = mode;
  state.tool = TOOLS[mode][0] ? TOOLS[mode][0][0] : null;
  state.chain = null;
  state.roadFrom = null;
  clearPreview();
  for (const b of document.querySelectorAll('#modes button')) b.classList.toggle('on', b.dataset.mode === mode);
  const tools = $('tools');
  tools.innerHTML = '';
  for (const [id, label] of TOOLS[mode]) {
    const b = document.createElement('button');
    b.textContent = label;
    b.dataset.tool = id;
    b.classList.toggle('on', id === state.tool);
    b.onclick = () => setTool(id);
    tools.appendChild(b);
  }
  updateInspector();
  plan.requestDraw();
}

function setTool(tool) {
  state.tool = tool;
  state.chain = null;
  state.roadFrom = null;
  clearPreview();
  for (const b of document.querySelectorAll('#tools button')) b.classList.toggle('on', b.dataset.tool === tool);
  plan.requestDraw();
}

const canvas = $('plan');
let drag = null; // {kind: 'pan'|'node', ...}

canvas.addEventListener('contextmenu', (e) => e.preventDefault());
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  const r = canvas.getBoundingClientRect();
  plan.zoomAt(e.clientX - r.left, e.clientY - r.top, Math.exp(-e.deltaY * 0.0015));
}, { passive: false });

canvas.addEventListener('mousedown', (e) => {
  canvas.focus();
  const [x, y] = plan.eventWorld(e);
  if (e.button === 2 && state.chain != null) {
    // Right click ends the chain.
    state.chain = null;
    clearPreview();
    return;
  }
  if (e.button !== 0 || state.mode === 'view' || e.shiftKey) {
    drag = { kind: 'pan', x: e.clientX, y: e.clientY };
    return;
  }
  if (state.mode === 'node') nodeDown(x, y, e);
  else if (state.mode === 'road') roadDown(x, y);
  else if (state.mode === 'cell') cellDown(x, y);
});

window.addEventListener('mousemove', (e) => {
  if (drag && drag.kind === 'pan') {
    plan.pan(e.clientX - drag.x, e.clientY - drag.y);
    drag.x = e.clientX;
    drag.y = e.clientY;
    return;
  }
  if (e.target !== canvas && !drag) return;
  const [x, y] = plan.eventWorld(e);
  if (drag && drag.kind === 'node') {
    drag.moved = true;
    drag.to = [x, y];
    propose({ op: 'move_node', node: drag.node, to: [x, y] });
    return;
  }
  const hover = state.mode === 'node' || state.mode === 'road' ? plan.hitNode(x, y) : null;
  if (hover !== state.hover.node) {
    state.hover.node = hover;
    plan.requestDraw();
  }
  if (state.mode === 'node' && state.tool === 'add' && state.chain != null) {
    propose(withSpec({ op: 'chain', from: state.chain, to: [x, y] }));
  }
});

window.addEventListener('mouseup', async (e) => {
  const d = drag;
  drag = null;
  if (!d || d.kind !== 'node') return;
  if (!d.moved) return;
  clearPreview();
  await commit({ op: 'move_node', node: d.node, to: d.to });
});

async function nodeDown(x, y) {
  const hit = plan.hitNode(x, y);
  if (state.tool === 'select') {
    state.selection.node = hit;
    if (hit != null) drag = { kind: 'node', node: hit, moved: false };
    updateInspector();
    plan.requestDraw();
  } else if (state.tool === 'delete') {
    if (hit != null) await commit({ op: 'delete_node', node: hit });
  } else if (state.tool === 'add') {
    if (state.chain == null) {
      if (hit != null) {
        // Kelly §5.3.1: clicking a node starts the chain from it.
        state.chain = hit;
      } else {
        const r = await commit({ op: 'add_node', at: [x, y] });
        // The chain continues from the new node (one click fewer than Kelly's).
        if (r && r.end_node != null) state.chain = r.end_node;
      }
      plan.requestDraw();
    } else {
      const to = hit != null ? [state.nodes.get(hit).x, state.nodes.get(hit).y] : [x, y];
      const r = await commit(withSpec({ op: 'chain', from: state.chain, to }));
      if (r && r.end_node != null) state.chain = r.end_node;
      plan.requestDraw();
    }
  }
}

async function roadDown(x, y) {
  if (state.tool === 'add') {
    const hit = plan.hitNode(x, y);
    if (hit == null) return;
    if (state.roadFrom == null) {
      state.roadFrom = hit;
      state.selection.node = hit;
    } else {
      await commit(withSpec({ op: 'add_road', from: { node: state.roadFrom }, to: { node: hit } }));
      state.roadFrom = null;
      state.selection.node = null;
    }
    plan.requestDraw();
    return;
  }
  const road = plan.hitRoad(x, y);
  if (state.tool === 'delete') {
    if (road != null) await commit({ op: 'delete_road', road });
    return;
  }
  state.selection.road = road;
  updateInspector();
  plan.requestDraw();
}

function cellDown(x, y) {
  state.selection.cell = plan.hitCell(x, y);
  updateInspector();
  plan.requestDraw();
}

// An edit with the spec for new roads (the road inspector's defaults) when set.
function withSpec(edit) {
  if (state.roadDefaults) edit.spec = state.roadDefaults;
  return edit;
}

// A cell parameter in the editor's JSON: `{"segment_size": {"value": 60, "deviance":
// 0.2}}` for a parameter with a deviance, `{"degree": 3}` for one without.
function cellParam(p, value, deviance) {
  const v = p.integer ? Math.round(+value) : +value;
  return { [p.name]: p.deviance != null ? { value: v, deviance: +deviance } : v };
}

// ---- property inspector ----

let inspected = null;

async function updateInspector() {
  const props = $('props');
  const key = `${state.mode}:${state.selection.node}:${state.selection.road}:${state.selection.cell}:${state.revision}`;
  if (key === inspected) return;
  inspected = key;
  props.innerHTML = '';
  if (state.mode === 'node' && state.selection.node != null) {
    const n = state.nodes.get(state.selection.node);
    head(props, `Node ${state.selection.node}`);
    const x = field(props, 'x (m)', n.x, null, 'wide');
    const y = field(props, 'y (m)', n.y, null, 'wide');
    const label = textField(props, 'label', n.label || '');
    button(props, 'Move', () => commit({ op: 'move_node', node: state.selection.node, to: [+x.value, +y.value] }));
    button(props, 'Set label', () => commit({ op: 'set_node_label', node: state.selection.node, label: label.value || null }));
  } else if (state.mode === 'road') {
    const id = state.selection.road;
    const spec = id != null ? state.roads.get(id).spec : state.roadDefaults;
    head(props, id != null ? `Road ${id}` : 'New roads (defaults)');
    const inputs = specInputs(props, spec);
    button(props, id != null ? 'Apply' : 'Set defaults', () => {
      const s = readSpec(spec, inputs);
      if (id != null) commit({ op: 'set_road', road: id, spec: s });
      else {
        state.roadDefaults = s;
        log('road defaults changed');
      }
    });
  } else if (state.mode === 'cell' && state.selection.cell != null) {
    const id = state.selection.cell;
    let info;
    try {
      info = (await call('GET', `/api/cell/${id}`)).data;
    } catch (e) {
      log(e.message, true);
      return;
    }
    head(props, `Cell ${id}`);
    const skipped = state.cells.get(id)?.skipped;
    if (skipped) {
      const note = document.createElement('p');
      note.className = 'warn';
      note.textContent = `No secondary streets: ${skipped}`;
      props.appendChild(note);
    }
    const sel = document.createElement('select');
    sel.id = 'cell-preset';
    for (const p of state.presets) {
      const o = document.createElement('option');
      o.value = p;
      o.textContent = p;
      o.selected = p === info.pattern;
      sel.appendChild(o);
    }
    sel.onchange = () => commit({ op: 'set_cell_pattern', cell: id, pattern: sel.value });
    wrap(props, 'Preset', sel);
    const cols = document.createElement('div');
    cols.className = 'cols';
    cols.innerHTML = '<span>parameter</span><span>value</span><span>deviance</span>';
    props.appendChild(cols);
    for (const p of info.params) {
      const [v, d] = pair(props, p.label, p.value, p.deviance, p.name);
      const send = () => commit({ op: 'set_cell_param', cell: id, param: cellParam(p, v.value, d && d.value) });
      v.onchange = send;
      if (d) d.onchange = send;
    }
    // The growth seed in effect (text: exact above 2^53); a new one is a safe integer.
    const seed = textField(props, 'seed', info.own_seed ?? info.seed);
    seed.id = 'cell-seed';
    button(props, 'Set seed', () => {
      const v = Number(seed.value);
      if (!Number.isSafeInteger(v) || v < 0) log(`seed: give a whole number from 0 to ${Number.MAX_SAFE_INTEGER}`, true);
      else commit({ op: 'set_cell_seed', cell: id, seed: v });
    });
    const stats = document.createElement('div');
    stats.className = 'head';
    stats.textContent = `${info.lots} lots · ${info.buildings} buildings · ${info.streets} streets`;
    props.appendChild(stats);
  } else {
    head(props, 'Nothing selected');
  }
}

function head(el, text) {
  const h = document.createElement('div');
  h.className = 'head';
  h.textContent = text;
  el.appendChild(h);
}
function wrap(el, text, input, cls = 'wide') {
  const l = document.createElement('label');
  l.className = cls;
  const s = document.createElement('span');
  s.textContent = text;
  l.appendChild(s);
  l.appendChild(input);
  el.appendChild(l);
  return input;
}
// A number as the inspector shows it: six significant digits.
function shown(v) {
  return typeof v === 'number' ? +v.toPrecision(6) : v;
}
function field(el, text, value, _d, cls) {
  const i = document.createElement('input');
  i.type = 'number';
  i.step = 'any';
  i.value = shown(value);
  return wrap(el, text, i, cls);
}
function textField(el, text, value) {
  const i = document.createElement('input');
  i.value = value;
  return wrap(el, text, i);
}
function pair(el, text, value, deviance, name) {
  const l = document.createElement('label');
  const s = document.createElement('span');
  s.textContent = text;
  l.appendChild(s);
  const v = document.createElement('input');
  v.type = 'number';
  v.step = 'any';
  v.value = shown(value);
  v.dataset.param = name;
  l.appendChild(v);
  let d = null;
  if (deviance != null) {
    d = document.createElement('input');
    d.type = 'number';
    d.step = 'any';
    d.value = shown(deviance);
    d.dataset.deviance = name;
    l.appendChild(d);
  } else l.appendChild(document.createElement('span'));
  el.appendChild(l);
  return [v, d];
}
function button(el, text, onclick) {
  const b = document.createElement('button');
  b.textContent = text;
  b.onclick = onclick;
  el.appendChild(b);
  return b;
}

// The adaptive-road properties (Kelly §5.4.1): strategy, sampling, width, draw size.
function specInputs(el, spec) {
  const inputs = {};
  const p = spec.params;
  const strat = document.createElement('select');
  for (const s of ['Straight', 'MinimumElevation', 'MinimumElevationDifference', 'EvenElevationDifference']) {
    const o = document.createElement('option');
    o.value = s;
    o.textContent = s;
    o.selected = s === p.strategy;
    strat.appendChild(o);
  }
  inputs.strategy = wrap(el, 'Algorithm', strat);
  inputs.sample_size_m = field(el, 'Sample size (m)', p.sample_size_m, null, 'wide');
  inputs.samples = field(el, 'Samples', p.samples, null, 'wide');
  inputs.deviation_deg = field(el, 'Deviation (°)', p.deviation_deg, null, 'wide');
  inputs.snap_m = field(el, 'Snap size (m)', p.snap_m, null, 'wide');
  inputs.width_m = field(el, 'Road width (m)', spec.width_m, null, 'wide');
  inputs.segment_draw_size_m = field(el, 'Segment draw size (m)', p.segment_draw_size_m, null, 'wide');
  return inputs;
}
function readSpec(spec, inputs) {
  const s = JSON.parse(JSON.stringify(spec));
  s.params.strategy = inputs.strategy.value;
  for (const k of ['sample_size_m', 'deviation_deg', 'snap_m', 'segment_draw_size_m']) s.params[k] = +inputs[k].value;
  s.params.samples = Math.round(+inputs.samples.value);
  s.width_m = +inputs.width_m.value;
  return s;
}

// ---- toolbar ----

for (const b of document.querySelectorAll('#modes button')) b.onclick = () => setMode(b.dataset.mode);
$('undo').onclick = () => run('POST', '/api/undo');
$('redo').onclick = () => run('POST', '/api/redo');
for (const r of document.querySelectorAll('#layers input')) {
  r.onchange = () => {
    state.layer = r.value;
    view.rebuild();
    plan.requestDraw();
  };
}
window.addEventListener('keydown', (e) => {
  if (e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
  if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === 'z') {
    e.preventDefault();
    run('POST', e.shiftKey ? '/api/redo' : '/api/undo');
  } else if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === 'y') {
    e.preventDefault();
    run('POST', '/api/redo');
  } else if (e.key === 'Escape') {
    state.chain = null;
    state.roadFrom = null;
    clearPreview();
  } else if (document.activeElement === canvas && !e.ctrlKey) {
    const m = { v: 'view', n: 'node', r: 'road', c: 'cell' }[e.key.toLowerCase()];
    if (m) setMode(m);
  }
});

// ---- the state object for tests and the console ----

window.polis = {
  state,
  plan,
  view,
  ready: () => state.ready,
  // Canvas-relative CSS pixels of a layout point, for scripted clicks.
  toScreen: (x, y) => plan.toScreen(x, y),
  toWorld: (sx, sy) => plan.toWorld(sx, sy),
  setMode,
  setTool,
  commit,
  // Asks the server whether an action would be accepted, without committing it (what
  // the cursor's preview does): {ok, message, proposed, roads, nodes}.
  preview: async (action) => (await call('POST', '/api/preview', action)).data,
  undo: () => run('POST', '/api/undo'),
  redo: () => run('POST', '/api/redo'),
  summary: () => ({
    revision: state.revision,
    nodes: state.nodes.size,
    roads: state.roads.size,
    cells: state.cells.size,
    blocks: state.blocks.size,
    buildings: [...state.blocks.values()].reduce((s, b) => s + b.buildings.length, 0),
    errors: state.errors,
  }),
};

setMode('view');
loadScene().catch((e) => log(`cannot load the scene: ${e.message}`, true));
