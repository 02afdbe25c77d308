// The 3-D view: WebGL 1, one vertex buffer per city cell (so an edit rebuilds only the
// cells it changed), buildings extruded from their footprints and shaded by kind with a
// window pattern drawn in the fragment shader, roads as flat ribbons.
//
// The camera follows Kelly §5.2: it orbits a target point; translation moves the target
// in the ground plane so that the point under the cursor stays under it (a mouse-ray /
// plane intersection); zoom scales the distance to the target, fast far away and fine
// close by. Keys as in the course report: W/S zoom, A/D swivel, arrows tilt.

import { kindColour } from './plan.js';

const VS = `
attribute vec3 aPos; attribute vec3 aNormal; attribute vec3 aColour; attribute vec2 aUv;
uniform mat4 uViewProj;
varying vec3 vNormal; varying vec3 vColour; varying vec2 vUv;
void main() { vNormal = aNormal; vColour = aColour; vUv = aUv; gl_Position = uViewProj * vec4(aPos, 1.0); }`;

const FS = `
precision mediump float;
varying vec3 vNormal; varying vec3 vColour; varying vec2 vUv;
uniform vec3 uLight;
void main() {
  vec3 n = normalize(vNormal);
  float light = 0.35 + 0.65 * max(dot(n, uLight), 0.0);
  vec3 c = vColour;
  // Walls (uv.y >= 0): windows 1.4 m wide every 3.2 m, 1.6 m tall every 3.2 m storey,
  // above a 1 m plinth. Roofs and roads carry uv.y < 0.
  if (vUv.y >= 1.0) {
    vec2 cell = fract(vec2(vUv.x / 3.2, (vUv.y - 1.0) / 3.2));
    if (cell.x > 0.28 && cell.x < 0.72 && cell.y > 0.25 && cell.y < 0.75) c *= 0.55;
  }
  gl_FragColor = vec4(c * light, 1.0);
}`;

const FLOATS = 11; // pos 3, normal 3, colour 3, uv 2

export class View3d {
  constructor(canvas, state) {
    this.canvas = canvas;
    this.state = state;
    this.gl = canvas.getContext('webgl', { antialias: true }) || canvas.getContext('experimental-webgl');
    this.buffers = new Map(); // key → {vbo, ibo, count}
    this.cam = { tx: 0, ty: 0, yaw: -0.6, pitch: 0.75, dist: 3000 };
    this.pending = false;
    this.drawMs = 0;
    this.ok = !!this.gl;
    if (!this.ok) return;
    const gl = this.gl;
    this.uint = gl.getExtension('OES_element_index_uint');
    this.prog = program(gl, VS, FS);
    this.loc = {
      pos: gl.getAttribLocation(this.prog, 'aPos'),
      normal: gl.getAttribLocation(this.prog, 'aNormal'),
      colour: gl.getAttribLocation(this.prog, 'aColour'),
      uv: gl.getAttribLocation(this.prog, 'aUv'),
      viewProj: gl.getUniformLocation(this.prog, 'uViewProj'),
      light: gl.getUniformLocation(this.prog, 'uLight'),
    };
    new ResizeObserver(() => this.resize()).observe(canvas);
    this.resize();
    this.bindInput();
  }

  resize() {
    const dpr = window.devicePixelRatio || 1;
    const r = this.canvas.getBoundingClientRect();
    this.canvas.width = Math.max(1, Math.round(r.width * dpr));
    this.canvas.height = Math.max(1, Math.round(r.height * dpr));
    this.requestDraw();
  }

  fit(bounds) {
    const [x0, y0, x1, y1] = bounds;
    this.cam.tx = (x0 + x1) / 2;
    this.cam.ty = (y0 + y1) / 2;
    this.cam.dist = 0.9 * Math.max(x1 - x0, y1 - y0);
    this.requestDraw();
  }

  // Rebuilds the buffers of the given city cells ('c' + id: streets) and blocks
  // ('b' + id: block plates, buildings) and of the primary roads.
  update(keys, removedKeys) {
    if (!this.ok) return;
    for (const k of removedKeys) this.drop(k);
    const layer = this.state.layer;
    for (const k of keys) {
      const id = k.slice(1);
      if (k[0] === 'c') {
        const c = this.state.cells.get(id);
        if (c && layer !== 'primary') this.upload(k, roadsMesh(c.streets, 0.25, [0.47, 0.49, 0.52]));
        else this.drop(k);
      } else {
        const b = this.state.blocks.get(id);
        if (b && layer === 'all') this.upload(k, blockMesh(b));
        else this.drop(k);
      }
    }
    this.upload('primary', roadsMesh([...this.state.roads.values()], 0.4, [0.24, 0.25, 0.28]));
    this.requestDraw();
  }

  // Rebuilds everything (a new scene, or the view layer changed).
  rebuild() {
    if (!this.ok) return;
    for (const k of [...this.buffers.keys()]) this.drop(k);
    const b = this.state.bounds;
    this.upload('ground', groundMesh(b));
    this.update([...[...this.state.cells.keys()].map((id) => 'c' + id), ...[...this.state.blocks.keys()].map((id) => 'b' + id)], []);
  }

  drop(key) {
    const b = this.buffers.get(key);
    if (!b) return;
    this.gl.deleteBuffer(b.vbo);
    this.gl.deleteBuffer(b.ibo);
    this.buffers.delete(key);
  }

  upload(key, mesh) {
    this.drop(key);
    const gl = this.gl;
    if (mesh.indices.length === 0) return;
    const big = mesh.vertices.length / FLOATS > 65535;
    if (big && !this.uint) return; // cannot index it; skip rather than draw garbage
    const vbo = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, vbo);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(mesh.vertices), gl.STATIC_DRAW);
    const ibo = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibo);
    const idx = big ? new Uint32Array(mesh.indices) : new Uint16Array(mesh.indices);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
    this.buffers.set(key, { vbo, ibo, count: mesh.indices.length, type: big ? gl.UNSIGNED_INT : gl.UNSIGNED_SHORT });
  }

  requestDraw() {
    if (this.pending || !this.ok) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.draw();
    });
  }

  // Eye position in layout metres (x, y) and height z.
  eye() {
    const c = this.cam;
    const h = c.dist * Math.cos(c.pitch);
    return [c.tx + h * Math.cos(c.yaw), c.ty + h * Math.sin(c.yaw), c.dist * Math.sin(c.pitch)];
  }

  viewProj() {
    const aspect = this.canvas.width / Math.max(1, this.canvas.height);
    const proj = perspective(0.9, aspect, Math.max(1, this.cam.dist * 0.01), this.cam.dist * 20 + 10000);
    const view = lookAt(this.eye(), [this.cam.tx, this.cam.ty, 0], [0, 0, 1]);
    return mul(proj, view);
  }

  draw() {
    const t0 = performance.now();
    const gl = this.gl;
    gl.viewport(0, 0, this.canvas.width, this.canvas.height);
    gl.clearColor(0.62, 0.72, 0.82, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(this.prog);
    gl.uniformMatrix4fv(this.loc.viewProj, false, new Float32Array(this.viewProj()));
    const l = [0.45, 0.3, 0.84];
    const n = Math.hypot(...l);
    gl.uniform3f(this.loc.light, l[0] / n, l[1] / n, l[2] / n);
    for (const b of this.buffers.values()) {
      gl.bindBuffer(gl.ARRAY_BUFFER, b.vbo);
      const stride = FLOATS * 4;
      attrib(gl, this.loc.pos, 3, stride, 0);
      attrib(gl, this.loc.normal, 3, stride, 12);
      attrib(gl, this.loc.colour, 3, stride, 24);
      attrib(gl, this.loc.uv, 2, stride, 36);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, b.ibo);
      gl.drawElements(gl.TRIANGLES, b.count, b.type, 0);
    }
    this.drawMs = performance.now() - t0;
  }

  // The ground point (z = 0) under a canvas pixel: the mouse ray meets the plane.
  groundAt(sx, sy) {
    const r = this.canvas.getBoundingClientRect();
    const inv = invert(this.viewProj());
    if (!inv) return null;
    const nx = (2 * sx) / r.width - 1;
    const ny = 1 - (2 * sy) / r.height;
    const a = project(inv, [nx, ny, -1]);
    const b = project(inv, [nx, ny, 1]);
    const dz = b[2] - a[2];
    if (Math.abs(dz) < 1e-9) return null;
    const t = -a[2] / dz;
    if (t < 0) return null;
    return [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
  }

  bindInput() {
    const cv = this.canvas;
    let drag = null;
    cv.addEventListener('contextmenu', (e) => e.preventDefault());
    cv.addEventListener('mousedown', (e) => {
      const r = cv.getBoundingClientRect();
      const sx = e.clientX - r.left;
      const sy = e.clientY - r.top;
      drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey, grab: this.groundAt(sx, sy) };
    });
    window.addEventListener('mouseup', () => (drag = null));
    window.addEventListener('mousemove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x;
      const dy = e.clientY - drag.y;
      drag.x = e.clientX;
      drag.y = e.clientY;
      if (drag.pan && drag.grab) {
        // Keep the grabbed ground point under the cursor.
        const r = cv.getBoundingClientRect();
        const now = this.groundAt(e.clientX - r.left, e.clientY - r.top);
        if (now) {
          this.cam.tx += drag.grab[0] - now[0];
          this.cam.ty += drag.grab[1] - now[1];
        }
      } else {
        this.cam.yaw -= dx * 0.006;
        this.cam.pitch = clamp(this.cam.pitch + dy * 0.006, 0.08, 1.5);
      }
      this.requestDraw();
    });
    cv.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.zoom(Math.exp(e.deltaY * 0.0015));
    }, { passive: false });
    cv.tabIndex = 0;
    cv.addEventListener('keydown', (e) => {
      const k = e.key.toLowerCase();
      if (k === 'w') this.zoom(0.85);
      else if (k === 's') this.zoom(1 / 0.85);
      else if (k === 'a') this.cam.yaw += 0.08;
      else if (k === 'd') this.cam.yaw -= 0.08;
      else if (e.key === 'ArrowUp') this.cam.pitch = clamp(this.cam.pitch + 0.06, 0.08, 1.5);
      else if (e.key === 'ArrowDown') this.cam.pitch = clamp(this.cam.pitch - 0.06, 0.08, 1.5);
      else return;
      e.preventDefault();
      this.requestDraw();
    });
  }

  // Zoom relative to the distance to the target (§5.2).
  zoom(factor) {
    this.cam.dist = clamp(this.cam.dist * factor, 20, 40000);
    this.requestDraw();
  }
}

function clamp(v, lo, hi) {
  return Math.min(hi, Math.max(lo, v));
}

function attrib(gl, loc, size, stride, offset) {
  if (loc < 0) return;
  gl.enableVertexAttribArray(loc);
  gl.vertexAttribPointer(loc, size, gl.FLOAT, false, stride, offset);
}

function program(gl, vs, fs) {
  const p = gl.createProgram();
  for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    gl.attachShader(p, s);
  }
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}

// ---- meshes (layout x, y; z up) ----

function hexColour(h) {
  const v = parseInt(h.slice(1), 16);
  return [((v >> 16) & 255) / 255, ((v >> 8) & 255) / 255, (v & 255) / 255];
}

class MeshBuilder {
  constructor() {
    this.vertices = [];
    this.indices = [];
  }
  vertex(x, y, z, n, c, u, v) {
    this.vertices.push(x, y, z, n[0], n[1], n[2], c[0], c[1], c[2], u, v);
    return this.vertices.length / FLOATS - 1;
  }
}

// A block's plate and its buildings extruded from their footprints (flat roofs).
export function blockMesh(block) {
  const m = new MeshBuilder();
  const plate = [0.78, 0.76, 0.7];
  for (const ring of block.rings) {
    if (ringSignedArea(ring) > 0) polygonInto(m, ring, 0.15, plate);
  }
  for (const b of block.buildings) buildingInto(m, b);
  return m;
}

function buildingInto(m, b) {
  const ring = b.ring;
  const n = ring.length / 2;
  if (n < 3 || !(b.h > 0)) return;
  const c = hexColour(kindColour(b.kind));
  const ccw = ringSignedArea(ring) > 0;
  let u = 0;
  for (let i = 0; i < n; i++) {
    const j = (i + 1) % n;
    const [ax, ay, bx, by] = ccw
      ? [ring[2 * i], ring[2 * i + 1], ring[2 * j], ring[2 * j + 1]]
      : [ring[2 * j], ring[2 * j + 1], ring[2 * i], ring[2 * i + 1]];
    const len = Math.hypot(bx - ax, by - ay);
    if (len < 1e-6) continue;
    const nrm = [(by - ay) / len, -(bx - ax) / len, 0];
    const base = 0.15;
    const a0 = m.vertex(ax, ay, base, nrm, c, u, 0);
    const b0 = m.vertex(bx, by, base, nrm, c, u + len, 0);
    const b1 = m.vertex(bx, by, b.h, nrm, c, u + len, b.h);
    const a1 = m.vertex(ax, ay, b.h, nrm, c, u, b.h);
    m.indices.push(a0, b0, b1, a0, b1, a1);
    u += len;
  }
  polygonInto(m, ring, b.h, c.map((x) => x * 0.85));
}

// A flat polygon at height z, ear-clipped.
function polygonInto(m, ring, z, colour) {
  const tris = earClip(ring);
  const base = m.vertices.length / FLOATS;
  for (let i = 0; i < ring.length; i += 2) m.vertex(ring[i], ring[i + 1], z, [0, 0, 1], colour, 0, -1);
  for (const t of tris) m.indices.push(base + t);
}

function roadsMesh(roads, z, colour) {
  const m = new MeshBuilder();
  roadsInto(m, roads, z, colour);
  return m;
}

// Each polyline as a ribbon of its width (quads per segment; joins overlap).
function roadsInto(m, roads, z, colour) {
  for (const r of roads) {
    const p = r.pts;
    const hw = Math.max(1, r.w) / 2;
    for (let i = 0; i + 3 < p.length; i += 2) {
      const dx = p[i + 2] - p[i];
      const dy = p[i + 3] - p[i + 1];
      const l = Math.hypot(dx, dy);
      if (l < 1e-9) continue;
      const ox = (-dy / l) * hw;
      const oy = (dx / l) * hw;
      const up = [0, 0, 1];
      const a = m.vertex(p[i] + ox, p[i + 1] + oy, z, up, colour, 0, -1);
      const b = m.vertex(p[i] - ox, p[i + 1] - oy, z, up, colour, 0, -1);
      const c = m.vertex(p[i + 2] - ox, p[i + 3] - oy, z, up, colour, 0, -1);
      const d = m.vertex(p[i + 2] + ox, p[i + 3] + oy, z, up, colour, 0, -1);
      m.indices.push(a, b, c, a, c, d);
    }
  }
}

function groundMesh(b) {
  const m = new MeshBuilder();
  const g = [0.55, 0.62, 0.45];
  const up = [0, 0, 1];
  const pad = 0.05 * Math.max(b[2] - b[0], b[3] - b[1]);
  const v = [
    m.vertex(b[0] - pad, b[1] - pad, 0, up, g, 0, -1),
    m.vertex(b[2] + pad, b[1] - pad, 0, up, g, 0, -1),
    m.vertex(b[2] + pad, b[3] + pad, 0, up, g, 0, -1),
    m.vertex(b[0] - pad, b[3] + pad, 0, up, g, 0, -1),
  ];
  m.indices.push(v[0], v[1], v[2], v[0], v[2], v[3]);
  return m;
}

export function ringSignedArea(ring) {
  let a = 0;
  const n = ring.length / 2;
  for (let i = 0, j = n - 1; i < n; j = i++) a += ring[2 * j] * ring[2 * i + 1] - ring[2 * i] * ring[2 * j + 1];
  return a / 2;
}

// Ear clipping of a simple ring (either orientation): triangles as vertex indices.
export function earClip(ring) {
  const n = ring.length / 2;
  if (n < 3) return [];
  const ccw = ringSignedArea(ring) > 0;
  const idx = [];
  for (let i = 0; i < n; i++) idx.push(ccw ? i : n - 1 - i);
  const out = [];
  const x = (i) => ring[2 * i];
  const y = (i) => ring[2 * i + 1];
  const cross = (a, b, c) => (x(b) - x(a)) * (y(c) - y(a)) - (y(b) - y(a)) * (x(c) - x(a));
  let guard = 0;
  while (idx.length > 3 && guard++ < 10 * n) {
    let clipped = false;
    for (let k = 0; k < idx.length; k++) {
      const a = idx[(k + idx.length - 1) % idx.length];
      const b = idx[k];
      const c = idx[(k + 1) % idx.length];
      if (cross(a, b, c) <= 0) continue;
      let inside = false;
      for (const p of idx) {
        if (p === a || p === b || p === c) continue;
        if (cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0) {
          inside = true;
          break;
        }
      }
      if (inside) continue;
      out.push(a, b, c);
      idx.splice(k, 1);
      clipped = true;
      break;
    }
    if (!clipped) break; // degenerate ring: keep what was clipped
  }
  if (idx.length === 3) out.push(idx[0], idx[1], idx[2]);
  return out;
}

// ---- 4×4 matrices, column-major ----

function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2);
  const nf = 1 / (near - far);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
}

function lookAt(eye, at, up) {
  let zx = eye[0] - at[0], zy = eye[1] - at[1], zz = eye[2] - at[2];
  let l = Math.hypot(zx, zy, zz) || 1;
  zx /= l; zy /= l; zz /= l;
  let xx = up[1] * zz - up[2] * zy, xy = up[2] * zx - up[0] * zz, xz = up[0] * zy - up[1] * zx;
  l = Math.hypot(xx, xy, xz) || 1;
  xx /= l; xy /= l; xz /= l;
  const yx = zy * xz - zz * xy, yy = zz * xx - zx * xz, yz = zx * xy - zy * xx;
  return [
    xx, yx, zx, 0, xy, yy, zy, 0, xz, yz, zz, 0,
    -(xx * eye[0] + xy * eye[1] + xz * eye[2]),
    -(yx * eye[0] + yy * eye[1] + yz * eye[2]),
    -(zx * eye[0] + zy * eye[1] + zz * eye[2]), 1,
  ];
}

function mul(a, b) {
  const o = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) o[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return o;
}

function project(m, p) {
  const x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
  const y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
  const z = m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14];
  const w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
  return [x / w, y / w, z / w];
}

// General 4×4 inverse (cofactors); null when singular.
function invert(m) {
  const inv = new Array(16);
  inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] + m[9] * m[7] * m[14] + m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
  inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] - m[8] * m[7] * m[14] - m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
  inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] + m[8] * m[7] * m[13] + m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
  inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] - m[8] * m[6] * m[13] - m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
  inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] - m[9] * m[3] * m[14] - m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
  inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] + m[8] * m[3] * m[14] + m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
  inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] - m[8] * m[3] * m[13] - m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
  inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] + m[8] * m[2] * m[13] + m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
  inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] + m[5] * m[3] * m[14] + m[13] * m[2] * m[7] - m[13] * m[3] * m[6];
  inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] - m[4] * m[3] * m[14] - m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
  inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] + m[4] * m[3] * m[13] + m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
  inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] - m[4] * m[2] * m[13] - m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
  inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] - m[5] * m[3] * m[10] - m[9] * m[2] * m[7] + m[9] * m[3] * m[6];
  inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] + m[4] * m[3] * m[10] + m[8] * m[2] * m[7] - m[8] * m[3] * m[6];
  inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] - m[4] * m[3] * m[9] - m[8] * m[1] * m[7] + m[8] * m[3] * m[5];
  inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] + m[4] * m[2] * m[9] + m[8] * m[1] * m[6] - m[8] * m[2] * m[5];
  const det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
  if (Math.abs(det) < 1e-30) return null;
  return inv.map((v) => v / det);
}
