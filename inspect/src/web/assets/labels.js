// The labels and part rectangles of the graph's layout (layout.js), placed once the
// edges have their paths: a data edge's port name at the first point along the edge
// that overlaps neither a box nor a label placed before it (a grid of 64 px cells keeps
// the overlap tests near), and a dashed rectangle around each part's boxes and edges.
// No DOM: tests/web/layout.mjs runs it in Node through layout.js.

const LABEL_PX = 9;

function bezier(s, t) {
  const u = 1 - t;
  const c = [u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t];
  return { x: s.reduce((a, p, i) => a + c[i] * p.x, 0), y: s.reduce((a, p, i) => a + c[i] * p.y, 0) };
}

/** Points along the path about every `step` px, from its start. */
export function samples(segs, step = 6) {
  const out = [];
  for (const s of segs) {
    const len = Math.hypot(s[3].x - s[0].x, s[3].y - s[0].y) + 1;
    const n = Math.max(2, Math.ceil(len / step));
    for (let i = 0; i < n; i++) out.push(bezier(s, i / n));
  }
  out.push(segs[segs.length - 1][3]);
  return out;
}

export const overlaps = (a, b, pad = 0) =>
  a.x < b.x + b.w + pad && b.x < a.x + a.w + pad && a.y < b.y + b.h + pad && b.y < a.y + a.h + pad;

/** Rectangles by the 64 px cells they touch, so a test for overlap looks only near. */
class Grid {
  constructor() { this.cells = new Map(); }
  *keys(r, pad) {
    for (let i = Math.floor((r.x - pad) / 64); i <= Math.floor((r.x + r.w + pad) / 64); i++) {
      for (let j = Math.floor((r.y - pad) / 64); j <= Math.floor((r.y + r.h + pad) / 64); j++) yield `${i},${j}`;
    }
  }
  add(r) { for (const k of this.keys(r, 0)) (this.cells.get(k) || this.cells.set(k, []).get(k)).push(r); }
  hits(r, pad) {
    for (const k of this.keys(r, pad)) for (const o of this.cells.get(k) || []) if (overlaps(r, o, pad)) return true;
    return false;
  }
}

/** One label per port of a data edge, placed at the first point along the edge (from
 * the writer) where it overlaps no box and no label placed before it. */
export function labels(g, es, measure) {
  const taken = new Grid();
  for (const it of g.items.values()) if (!it.dummy) taken.add(it);
  const placed = [], done = new Set();
  for (const e of es) {
    const key = `${e.from}|${e.exit.key}`;
    if (!e.label || done.has(key)) continue;
    done.add(key);
    const w = measure(e.label, LABEL_PX) + 2, h = LABEL_PX + 3;
    const pts = samples(e.segs).filter((p) => Math.hypot(p.x - e.segs[0][0].x, p.y - e.segs[0][0].y) > 6);
    let spot = null;
    for (const p of pts) {
      for (const r of [{ x: p.x + 3, y: p.y - h / 2, w, h }, { x: p.x - 3 - w, y: p.y - h / 2, w, h }]) {
        if (!taken.hits(r, 2)) { spot = r; break; }
      }
      if (spot) break;
    }
    if (spot) { placed.push({ ...spot, text: e.label, edge: key }); taken.add(spot); }
    else e.unlabelled = true;
  }
  return placed;
}

/** The dashed rectangle of every part: its boxes, lanes and edges, with room for its name. */
export function clusters(g, es) {
  const parts = new Map();
  const grow = (part, x0, y0, x1, y1) => {
    const c = parts.get(part) || { x0: Infinity, y0: Infinity, x1: -Infinity, y1: -Infinity };
    parts.set(part, { x0: Math.min(c.x0, x0), y0: Math.min(c.y0, y0), x1: Math.max(c.x1, x1), y1: Math.max(c.y1, y1) });
  };
  for (const it of g.items.values()) grow(it.part, it.x, it.y, it.x + it.w, it.y + it.h);
  for (const e of es) {
    const part = g.items.get(e.from).part;
    if (part !== g.items.get(e.to).part) continue;
    for (const p of samples(e.segs, 12)) grow(part, p.x, p.y, p.x, p.y);
  }
  return [...parts].map(([rank, c]) => ({ part: g.partNames[rank], x: c.x0 - 10, y: c.y0 - 24, w: c.x1 - c.x0 + 20, h: c.y1 - c.y0 + 34 }));
}
