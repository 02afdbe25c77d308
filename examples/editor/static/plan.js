// The 2-D plan view: roads, cells, blocks, lots and footprints on a canvas, with pan and
// zoom, hit testing for the edit tools, and the red (proposed) / green (corrected)
// preview of Kelly's Fig. 69. Layout coordinates are metres with y up; the screen's y
// runs down.

const KIND_COLOURS = {
  house: '#c98f6b', midrise: '#b9a27d', office: '#8fa3b8', skyscraper: '#6f86a6',
  industrial: '#a5a08a', apartment: '#c4a58a', default: '#b0a090',
};

const PATTERN_COLOURS = {
  manhattan: 'rgba(120,140,200,0.16)', suburbia: 'rgba(120,190,110,0.18)',
  industrial: 'rgba(190,170,110,0.18)', raster: 'rgba(200,130,160,0.16)',
  downtown: 'rgba(110,120,190,0.18)', residential: 'rgba(150,200,130,0.18)',
};

export function kindColour(kind) {
  return KIND_COLOURS[kind] || KIND_COLOURS.default;
}

export class Plan {
  constructor(canvas, state) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.state = state;
    this.view = { cx: 0, cy: 0, scale: 0.2 };
    this.dpr = window.devicePixelRatio || 1;
    this.pending = false;
    this.drawMs = 0;
    new ResizeObserver(() => this.resize()).observe(canvas);
    this.resize();
  }

  resize() {
    const r = this.canvas.getBoundingClientRect();
    this.canvas.width = Math.max(1, Math.round(r.width * this.dpr));
    this.canvas.height = Math.max(1, Math.round(r.height * this.dpr));
    this.requestDraw();
  }

  // Fits the whole map into the canvas.
  fit(bounds) {
    const r = this.canvas.getBoundingClientRect();
    const [x0, y0, x1, y1] = bounds;
    this.view.cx = (x0 + x1) / 2;
    this.view.cy = (y0 + y1) / 2;
    this.view.scale = 0.95 * Math.min(r.width / Math.max(1, x1 - x0), r.height / Math.max(1, y1 - y0));
    this.requestDraw();
  }

  // CSS pixels relative to the canvas ↔ metres.
  toScreen(x, y) {
    const r = this.canvas.getBoundingClientRect();
    return [r.width / 2 + (x - this.view.cx) * this.view.scale, r.height / 2 - (y - this.view.cy) * this.view.scale];
  }
  toWorld(sx, sy) {
    const r = this.canvas.getBoundingClientRect();
    return [this.view.cx + (sx - r.width / 2) / this.view.scale, this.view.cy - (sy - r.height / 2) / this.view.scale];
  }
  eventWorld(e) {
    const r = this.canvas.getBoundingClientRect();
    return this.toWorld(e.clientX - r.left, e.clientY - r.top);
  }

  pan(dxPx, dyPx) {
    this.view.cx -= dxPx / this.view.scale;
    this.view.cy += dyPx / this.view.scale;
    this.requestDraw();
  }

  // Zooms by `factor` keeping the point under (sx, sy) fixed.
  zoomAt(sx, sy, factor) {
    const [wx, wy] = this.toWorld(sx, sy);
    this.view.scale = Math.min(50, Math.max(0.01, this.view.scale * factor));
    const [nx, ny] = this.toWorld(sx, sy);
    this.view.cx += wx - nx;
    this.view.cy += wy - ny;
    this.requestDraw();
  }

  requestDraw() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.draw();
    });
  }

  // The visible rectangle in metres, for culling.
  visible() {
    const r = this.canvas.getBoundingClientRect();
    const [x0, y1] = this.toWorld(0, 0);
    const [x1, y0] = this.toWorld(r.width, r.height);
    return [x0, y0, x1, y1];
  }

  draw() {
    const t0 = performance.now();
    const s = this.state;
    const ctx = this.ctx;
    const k = this.view.scale;
    const r = this.canvas.getBoundingClientRect();
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    ctx.clearRect(0, 0, r.width, r.height);
    // World transform: metres → CSS pixels.
    ctx.setTransform(this.dpr * k, 0, 0, -this.dpr * k, this.dpr * (r.width / 2 - this.view.cx * k), this.dpr * (r.height / 2 + this.view.cy * k));
    const px = 1 / k; // one CSS pixel in metres
    const [vx0, vy0, vx1, vy1] = this.visible();
    const inView = (b) => b[2] >= vx0 && b[0] <= vx1 && b[3] >= vy0 && b[1] <= vy1;
    const layer = s.layer;
    const cells = [...s.cells.values()].filter((c) => inView(c.bbox));
    const blocks = [...s.blocks.values()].filter((b) => inView(b.bbox));
    // Cells: a tint by pattern.
    for (const c of cells) {
      ctx.fillStyle = PATTERN_COLOURS[c.pattern] || 'rgba(128,128,128,0.12)';
      ringPath(ctx, c.ring);
      ctx.fill();
    }
    if (layer === 'all') {
      ctx.fillStyle = '#d9d4c6';
      ctx.beginPath();
      for (const b of blocks) for (const r of b.rings) addRing(ctx, r);
      ctx.fill('evenodd');
      // Lots and footprints only where they are bigger than a few pixels.
      if (k > 0.6) {
        ctx.strokeStyle = 'rgba(90,80,60,0.35)';
        ctx.lineWidth = px;
        ctx.beginPath();
        for (const b of blocks) for (const l of b.lots) addRing(ctx, l);
        ctx.stroke();
      }
      if (k > 0.2) {
        // One path per kind: a few fills instead of one per building.
        const byKind = new Map();
        for (const c of blocks) {
          for (const b of c.buildings) {
            if (!byKind.has(b.kind)) byKind.set(b.kind, []);
            byKind.get(b.kind).push(b.ring);
          }
        }
        for (const [kind, rings] of byKind) {
          ctx.fillStyle = kindColour(kind);
          ctx.beginPath();
          for (const r of rings) addRing(ctx, r);
          ctx.fill();
        }
      }
    }
    if (layer !== 'primary') {
      ctx.strokeStyle = '#8a8f96';
      ctx.lineCap = 'round';
      ctx.lineJoin = 'round';
      // One path per width.
      const byWidth = new Map();
      for (const c of cells) {
        for (const st of c.streets) {
          const w = Math.max(px, st.w);
          if (!byWidth.has(w)) byWidth.set(w, []);
          byWidth.get(w).push(st.pts);
        }
      }
      for (const [w, lines] of byWidth) {
        ctx.lineWidth = w;
        ctx.beginPath();
        for (const p of lines) {
          ctx.moveTo(p[0], p[1]);
          for (let i = 2; i < p.length; i += 2) ctx.lineTo(p[i], p[i + 1]);
        }
        ctx.stroke();
      }
    }
    // Primary roads.
    for (const [id, road] of s.roads) {
      ctx.strokeStyle = s.selection.road === id ? '#e6c04a' : '#3b3f45';
      ctx.lineWidth = Math.max(2 * px, road.w);
      linePath(ctx, road.pts);
      ctx.stroke();
    }
    // The selected cell's outline.
    const sel = s.selection.cell != null ? s.cells.get(s.selection.cell) : null;
    if (sel) {
      ctx.strokeStyle = '#e6c04a';
      ctx.lineWidth = 3 * px;
      ringPath(ctx, sel.ring);
      ctx.stroke();
    }
    // Nodes: red; highlighted with a yellow disc; selected yellow (Kelly §5.3).
    if (s.mode === 'node' || s.mode === 'road') {
      for (const [id, n] of s.nodes) {
        if (id === s.hover.node) {
          ctx.fillStyle = 'rgba(230,192,74,0.45)';
          disc(ctx, n.x, n.y, 11 * px);
        }
        ctx.fillStyle = id === s.selection.node || id === s.chain ? '#e6c04a' : '#d33';
        disc(ctx, n.x, n.y, 5 * px);
      }
    }
    this.drawPreview(ctx, px);
    this.drawMs = performance.now() - t0;
  }

  // Fig. 69: the corrected network in green, the proposed action over it in red
  // (dashed, so both show where they coincide).
  drawPreview(ctx, px) {
    const p = this.state.preview;
    if (!p) return;
    if (p.ok) {
      ctx.strokeStyle = '#20b040';
      for (const r of p.roads) {
        ctx.lineWidth = Math.max(3 * px, r.w);
        linePath(ctx, r.pts);
        ctx.stroke();
      }
      ctx.fillStyle = '#20b040';
      for (const n of p.nodes) disc(ctx, n.x, n.y, 6 * px);
    }
    ctx.lineWidth = 2.5 * px;
    ctx.setLineDash([8 * px, 6 * px]);
    ctx.strokeStyle = '#e02020';
    for (const seg of p.proposed) {
      linePath(ctx, seg);
      ctx.stroke();
    }
    ctx.setLineDash([]);
  }

  // The nearest node within `radiusPx` CSS pixels of a world point.
  hitNode(x, y, radiusPx = 10) {
    const r = radiusPx / this.view.scale;
    let best = null;
    let bestD = r * r;
    for (const [id, n] of this.state.nodes) {
      const d = (n.x - x) ** 2 + (n.y - y) ** 2;
      if (d <= bestD) {
        bestD = d;
        best = id;
      }
    }
    return best;
  }

  // The nearest primary road within `radiusPx` CSS pixels.
  hitRoad(x, y, radiusPx = 8) {
    const r = radiusPx / this.view.scale;
    let best = null;
    let bestD = r;
    for (const [id, road] of this.state.roads) {
      const p = road.pts;
      for (let i = 0; i + 3 < p.length; i += 2) {
        const d = segDist(x, y, p[i], p[i + 1], p[i + 2], p[i + 3]);
        if (d <= bestD) {
          bestD = d;
          best = id;
        }
      }
    }
    return best;
  }

  // The innermost city cell containing a world point (smallest area wins).
  hitCell(x, y) {
    let best = null;
    let bestA = Infinity;
    for (const [id, c] of this.state.cells) {
      const b = c.bbox;
      if (x < b[0] || x > b[2] || y < b[1] || y > b[3]) continue;
      if (pointInRing(x, y, c.ring) && c.area < bestA) {
        bestA = c.area;
        best = id;
      }
    }
    return best;
  }
}

function addRing(ctx, ring) {
  if (ring.length < 6) return;
  ctx.moveTo(ring[0], ring[1]);
  for (let i = 2; i < ring.length; i += 2) ctx.lineTo(ring[i], ring[i + 1]);
  ctx.closePath();
}
function ringPath(ctx, ring) {
  ctx.beginPath();
  addRing(ctx, ring);
}
function linePath(ctx, pts) {
  ctx.beginPath();
  if (pts.length < 4) return;
  ctx.moveTo(pts[0], pts[1]);
  for (let i = 2; i < pts.length; i += 2) ctx.lineTo(pts[i], pts[i + 1]);
}
function disc(ctx, x, y, r) {
  ctx.beginPath();
  ctx.arc(x, y, r, 0, 2 * Math.PI);
  ctx.fill();
}

export function segDist(px, py, ax, ay, bx, by) {
  const dx = bx - ax;
  const dy = by - ay;
  const l2 = dx * dx + dy * dy;
  let t = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0;
  t = Math.max(0, Math.min(1, t));
  return Math.hypot(px - ax - t * dx, py - ay - t * dy);
}

export function pointInRing(x, y, ring) {
  let inside = false;
  const n = ring.length / 2;
  for (let i = 0, j = n - 1; i < n; j = i++) {
    const xi = ring[2 * i], yi = ring[2 * i + 1], xj = ring[2 * j], yj = ring[2 * j + 1];
    if ((yi > y) !== (yj > y) && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}

export function ringBBox(ring) {
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  for (let i = 0; i < ring.length; i += 2) {
    x0 = Math.min(x0, ring[i]);
    x1 = Math.max(x1, ring[i]);
    y0 = Math.min(y0, ring[i + 1]);
    y1 = Math.max(y1, ring[i + 1]);
  }
  return [x0, y0, x1, y1];
}

export function ringArea(ring) {
  let a = 0;
  const n = ring.length / 2;
  for (let i = 0, j = n - 1; i < n; j = i++) a += ring[2 * j] * ring[2 * i + 1] - ring[2 * i] * ring[2 * j + 1];
  return Math.abs(a) / 2;
}
