// The application graph's layout, without the DOM (tests/web/layout.mjs runs it in
// Node): a layered (Sugiyama-style) drawing. Modules are put in layers by longest path
// after breaking cycles; an edge spanning several layers runs through one waypoint per
// layer it crosses, and the edges leaving one port share those waypoints (one bundle per
// port instead of a line per edge); the layers are ordered by barycentre sweeps down and
// up and swaps of neighbours, keeping the order with the fewest crossings, with the lane
// of a side port kept beside its box; x positions pull every box and
// waypoint towards its neighbours (least squares under the minimum gaps). Ports sit
// where iB2C draws them: a behaviour's stimulation, inhibitions and fusion channels on
// top, activities and target rating below, its data inputs left and data outputs
// right; a plain module's inputs on top and outputs below, in the order of the other
// ends. Data edges are labelled with the port's name at a place along the edge where
// the label overlaps neither a box nor another label (labels.js).

import { labels, clusters, samples, overlaps } from './labels.js';

export { samples, overlaps };

export const SLOT = 26, ROW = 16, METER = 22;
/** Font size (px) of a slot's name. */
export const SLOT_PX = 10;
const LAYER_GAP = 46, MARGIN = 12, ROUNDS = 6;
const GAP = { node: 26, mixed: 12, lane: 8, part: 44 };

/** Text width estimate (px) when no canvas measures it: Helvetica's mean advance. */
export const estimate = (text, px) => text.length * px * 0.56;

export const isBehaviour = (m) => m.kind === 'behaviour' || m.kind === 'fusion';
const channelOf = (name) => { const x = /^in\/(\d+)\//.exec(name); return x ? x[1] : null; };

/** The module a writer `module/path/port` belongs to (the longest module path). */
export function writerModule(byPath, writer) {
  let best = null;
  for (const path of byPath.keys()) {
    if (writer.startsWith(path + '/') && (!best || path.length > best.length)) best = path;
  }
  return best;
}

/** Top (inputs) and bottom (outputs) slots of a behaviour's box. */
export function slots(m) {
  const top = ['s'], bottom = ['a'], channels = new Set();
  for (const p of m.ports) {
    if (p.dir === 'in') {
      const inh = /^inhibition\/(\d+)$/.exec(p.name);
      if (inh) top.push('i' + inh[1]);
      const ch = channelOf(p.name);
      if (ch !== null) channels.add(ch);
    } else if (p.name.startsWith('activity/')) {
      bottom.push('a/' + p.name.slice('activity/'.length));
    }
  }
  for (const ch of [...channels].sort((a, b) => a - b)) top.push('ch ' + ch);
  bottom.push('r');
  return { top, bottom };
}

/** Where an edge leaves its writer: a behaviour's meta output leaves its slot below,
 * its data outputs the right side; a plain module's outputs leave from below. */
function exitOf(src, port) {
  if (!isBehaviour(src)) return { side: 'bottom', key: port };
  const meta = src.ports.some((q) => q.name === port && q.meta);
  if (meta && port === 'activity') return { side: 'bottom', key: 'a' };
  if (meta && port === 'target_rating') return { side: 'bottom', key: 'r' };
  if (meta && port.startsWith('activity/')) return { side: 'bottom', key: 'a/' + port.slice(9) };
  return { side: 'right', key: port };
}

/** The kind of an edge into input `p` of `m` and where it enters. */
function entryOf(m, p) {
  if (!isBehaviour(m)) return { kind: 'data', side: 'top', key: p.name };
  const ch = channelOf(p.name), inh = /^inhibition\/(\d+)$/.exec(p.name);
  if (p.meta && p.name === 'stimulation') return { kind: 'stim', side: 'top', key: 's' };
  if (p.meta && inh) return { kind: 'inhib', side: 'top', key: 'i' + inh[1] };
  if (ch !== null) return { kind: p.meta ? 'meta' : 'data', side: 'top', key: 'ch ' + ch };
  return { kind: 'data', side: 'left', key: p.name };
}

/** The edges between modules: {from, to, kind, port, input, label, exit, entry}. */
export function edges(modules) {
  const byPath = new Map(modules.map((m) => [m.path, m]));
  const out = [], seen = new Set();
  for (const m of modules) {
    for (const p of m.ports) {
      if (p.dir !== 'in') continue;
      for (const writer of p.from) {
        const from = writerModule(byPath, writer);
        const id = `${writer}→${m.path}/${p.name}`;
        if (!from || seen.has(id)) continue;
        seen.add(id);
        const port = writer.slice(from.length + 1);
        const { kind, side, key } = entryOf(m, p);
        out.push({ from, to: m.path, kind, port, input: p.name, label: kind === 'data' ? port : '',
          exit: exitOf(byPath.get(from), port), entry: { side, key } });
      }
    }
  }
  return out;
}

/** Back edges (closing a cycle, found depth first in model order) and layers by
 * longest path over the rest; a source is pulled down to just above its nearest target. */
function layering(paths, es) {
  const succ = new Map(paths.map((p) => [p, []]));
  for (const e of es) succ.get(e.from).push(e);
  const state = new Map(), back = new Set();
  const visit = (p) => {
    state.set(p, 1);
    for (const e of succ.get(p)) {
      const s = state.get(e.to);
      if (s === 1) back.add(e); else if (!s) visit(e.to);
    }
    state.set(p, 2);
  };
  for (const p of paths) if (!state.get(p)) visit(p);
  const indeg = new Map(paths.map((p) => [p, 0]));
  for (const e of es) if (!back.has(e)) indeg.set(e.to, indeg.get(e.to) + 1);
  const level = new Map(paths.map((p) => [p, 0]));
  const queue = paths.filter((p) => !indeg.get(p));
  for (let i = 0; i < queue.length; i++) {
    for (const e of succ.get(queue[i])) {
      if (back.has(e)) continue;
      level.set(e.to, Math.max(level.get(e.to), level.get(queue[i]) + 1));
      indeg.set(e.to, indeg.get(e.to) - 1);
      if (!indeg.get(e.to)) queue.push(e.to);
    }
  }
  for (const p of paths) {
    const outs = succ.get(p).filter((e) => !back.has(e));
    const fed = es.some((e) => e.to === p && !back.has(e));
    if (!fed && outs.length) level.set(p, Math.min(...outs.map((e) => level.get(e.to))) - 1);
  }
  const used = [...new Set(level.values())].sort((a, b) => a - b);
  const index = new Map(used.map((l, i) => [l, i]));
  for (const p of paths) level.set(p, index.get(level.get(p)));
  return { back, level };
}

/** A box's size and, for a behaviour, its slots. */
function boxOf(m, es, measure) {
  const name = m.path.split('/').pop();
  const text = Math.max(measure(name, 11), measure(m.type, 9)) + 16;
  if (isBehaviour(m)) {
    const s = slots(m);
    const left = [...new Set(es.filter((e) => e.to === m.path && e.entry.side === 'left').map((e) => e.entry.key))];
    const right = [...new Set(es.filter((e) => e.from === m.path && e.exit.side === 'right').map((e) => e.exit.key))];
    const widths = (list) => list.map((t) => Math.max(SLOT, measure(t, SLOT_PX) + 8));
    s.widths = { top: widths(s.top), bottom: widths(s.bottom) };
    const row = (side) => s.widths[side].reduce((a, b) => a + b, 0) + 12;
    const w = Math.max(text, row('top'), row('bottom'), 112);
    return { name, w, h: 2 * ROW + 30 + METER, slots: s, order: { left, right } };
  }
  const top = [...new Set(es.filter((e) => e.to === m.path).map((e) => e.entry.key))];
  const bottom = [...new Set(es.filter((e) => e.from === m.path).map((e) => e.exit.key))];
  const w = Math.max(text, 14 * (Math.max(top.length, bottom.length) + 1), 60);
  return { name, w, h: 36, slots: null, order: { top, bottom } };
}

/** The slots of a behaviour's box on `side` ('top' or 'bottom'): name, x from the
 * box's left edge, width; centred, each as wide as its name needs. */
export function slotRects(box, side) {
  const names = box.slots[side], widths = box.slots.widths[side];
  let x = (box.w - widths.reduce((a, b) => a + b, 0)) / 2;
  return names.map((name, i) => {
    const r = { name, x, w: widths[i] };
    x += widths[i];
    return r;
  });
}

/** An anchor's offset from its box's top left corner and its outward direction. */
export function anchor(box, side, key) {
  if (box.dummy) return { x: 0, y: 0, dx: 0, dy: 0 };
  const spread = (list, length) => {
    const i = Math.max(0, list.indexOf(key));
    return ((i + 1) * length) / (list.length + 1);
  };
  const slotX = (which) => {
    const r = slotRects(box, which).find((x) => x.name === key);
    return r ? r.x + r.w / 2 : box.w / 2;
  };
  if (side === 'top') return { x: box.slots ? slotX('top') : spread(box.order.top, box.w), y: 0, dx: 0, dy: -1 };
  if (side === 'bottom') return { x: box.slots ? slotX('bottom') : spread(box.order.bottom, box.w), y: box.h, dx: 0, dy: 1 };
  const y = ROW + spread(box.order[side], box.h - 2 * ROW);
  return side === 'left' ? { x: 0, y, dx: -1, dy: 0 } : { x: box.w, y, dx: 1, dy: 0 };
}

/** The layered graph: one item per module and per shared waypoint, the links between
 * consecutive items of every edge's chain, and the layers' item lists. */
function proper(modules, es, measure) {
  const { back, level } = layering(modules.map((m) => m.path), es);
  const partRank = new Map([...new Set(modules.map((m) => m.part))].map((p, i) => [p, i]));
  const items = new Map(), layers = [];
  const add = (id, item) => {
    if (!items.has(id)) { items.set(id, item); (layers[item.layer] ||= []).push(id); }
    return id;
  };
  for (const m of modules) {
    add(m.path, { ...boxOf(m, es, measure), m, layer: level.get(m.path), part: partRank.get(m.part) });
  }
  const links = new Map();
  for (const e of es) {
    const lf = level.get(e.from), lt = level.get(e.to), isBack = back.has(e) || lt <= lf;
    const part = partRank.get(items.get(e.from).m.part);
    const through = isBack ? range(lf, lt - 1, -1) : range(lf + 1, lt, 1);
    const lane = (l) => add(`${isBack ? 'B' : 'F'}|${e.from}|${e.exit.key}|${l}`, { dummy: true, w: 0, h: 0, layer: l, part });
    e.back = isBack;
    const lanes = through.map(lane);
    // A side port's edges run down a lane beside its box, one lane per port.
    if (!isBack && e.exit.side === 'right') lanes.unshift(add(`S|${e.from}|${e.exit.key}`, { dummy: true, w: 0, h: 0, layer: lf, part }));
    if (!isBack && e.entry.side === 'left') lanes.push(add(`T|${e.to}|${e.entry.key}`, { dummy: true, w: 0, h: 0, layer: lt, part }));
    e.chain = [e.from, ...lanes, e.to];
    for (let i = 1; i < e.chain.length; i++) {
      const [u, v] = [e.chain[i - 1], e.chain[i]];
      const eu = i === 1 ? e.exit : null, ev = i === e.chain.length - 1 ? e.entry : null;
      const key = `${u}|${eu && eu.side + eu.key}|${v}|${ev && ev.side + ev.key}`;
      if (!links.has(key)) links.set(key, { u, v, eu, ev });
    }
  }
  const all = [...links.values()], linksAt = layers.map(() => []);
  for (const k of all) {
    const ls = new Set([items.get(k.u).layer, items.get(k.v).layer]);
    for (const l of ls) linksAt[l].push(k);
  }
  return { items, layers: layers.map((l) => l || []), links: all, linksAt, partNames: [...partRank.keys()] };
}

function range(from, to, step) {
  const out = [];
  for (let l = from; step > 0 ? l < to : l > to; l += step) out.push(l);
  return out;
}

/** Index plus the port's place in the box (-0.4…0.4), for ordering. */
function rank(g, pos, id, end) {
  const it = g.items.get(id);
  if (it.dummy || !end) return pos.get(id);
  return pos.get(id) + 0.8 * (anchor(it, end.side, end.key).x / it.w - 0.5);
}

function positions(g) {
  const pos = new Map();
  for (const l of g.layers) l.forEach((id, i) => pos.set(id, i));
  return pos;
}

/** Crossings between adjacent layers of the current order, plus the items between a
 * box and a lane of its own layer (`near`: only those at that layer). */
export function crossings(g, near, pos = positions(g)) {
  const byLayer = new Map();
  let flat = 0;
  for (const k of near === undefined ? g.links : g.linksAt[near]) {
    const [a, b] = [g.items.get(k.u).layer, g.items.get(k.v).layer];
    // A lane kept apart from its box in the box's layer: every item between them counts.
    if (a === b) { flat += 2 * Math.max(0, Math.abs(pos.get(k.u) - pos.get(k.v)) - 1); continue; }
    const [top, lo] = a < b ? [[k.u, k.eu], [k.v, k.ev]] : [[k.v, k.ev], [k.u, k.eu]];
    const l = Math.min(a, b);
    (byLayer.get(l) || byLayer.set(l, []).get(l)).push([rank(g, pos, ...top), rank(g, pos, ...lo)]);
  }
  let n = flat;
  for (const segs of byLayer.values()) {
    for (let i = 0; i < segs.length; i++) {
      for (let j = i + 1; j < segs.length; j++) {
        if ((segs[i][0] - segs[j][0]) * (segs[i][1] - segs[j][1]) < 0) n++;
      }
    }
  }
  return n;
}

/** The neighbours of every item: [{id, end (its own anchor), other (theirs)}]. */
function neighbours(g) {
  const nb = new Map([...g.items.keys()].map((id) => [id, []]));
  for (const k of g.links) {
    nb.get(k.u).push({ id: k.v, end: k.eu, other: k.ev });
    nb.get(k.v).push({ id: k.u, end: k.ev, other: k.eu });
  }
  return nb;
}

/** The side of its box a lane in the box's layer keeps to: left of a left port, else right. */
const beside = (n) => (n.other && n.other.side === 'left' ? -1 : 1);

/** Barycentre sweeps down and up; the order with the fewest crossings is kept. */
function order(g) {
  const nb = neighbours(g);
  let best = g.layers.map((l) => [...l]), fewest = crossings(g);
  const sweep = (l, dir) => {
    const pos = positions(g), layer = g.layers[l];
    const bary = (id) => {
      const it = g.items.get(id);
      const near = nb.get(id).filter((n) => {
        const nl = g.items.get(n.id).layer;
        return nl === l + dir || (it.dummy && nl === l);
      });
      if (!near.length) return pos.get(id);
      const sum = near.reduce((s, n) => s + rank(g, pos, n.id, n.other) + (g.items.get(n.id).layer === l ? beside(n) / 2 : 0), 0);
      return sum / near.length;
    };
    const keyed = layer.map((id) => [g.items.get(id).part, bary(id), pos.get(id), id]);
    keyed.sort((a, b) => a[0] - b[0] || a[1] - b[1] || a[2] - b[2]);
    g.layers[l] = keyed.map((k) => k[3]);
  };
  const rounds = g.links.length > 3000 ? 1 : ROUNDS;
  for (let r = 0; r < rounds; r++) {
    for (let l = 1; l < g.layers.length; l++) sweep(l, -1);
    for (let l = g.layers.length - 2; l >= 0; l--) sweep(l, 1);
    const n = g.links.length > 400 ? crossings(g) : transpose(g);
    if (n < fewest) { fewest = n; best = g.layers.map((l) => [...l]); }
  }
  g.layers = best;
  return fewest;
}

/** Puts every lane that starts or ends at a box of its own layer right beside that box
 * (left of a left port, else right), so no other box stands between them. */
function attachLanes(g) {
  const nb = neighbours(g);
  g.layers = g.layers.map((layer, l) => {
    const groups = new Map();
    for (const id of layer) {
      const it = g.items.get(id);
      const n = it.dummy && nb.get(id).find((x) => !g.items.get(x.id).dummy && g.items.get(x.id).layer === l);
      if (!n) continue;
      const sides = groups.get(n.id) || groups.set(n.id, { left: [], right: [] }).get(n.id);
      sides[beside(n) < 0 ? 'left' : 'right'].push(id);
    }
    const attached = new Set([...groups.values()].flatMap((x) => [...x.left, ...x.right]));
    return layer.filter((id) => !attached.has(id)).flatMap((id) => {
      const x = groups.get(id);
      return x ? [...x.left, id, ...x.right] : [id];
    });
  });
}

/** Swaps neighbours of a layer (of one part) while that removes crossings; the
 * crossings after. Quadratic in the links, so only for graphs of a few hundred. */
function transpose(g) {
  const pos = positions(g);
  const swap = (layer, i) => {
    [layer[i], layer[i + 1]] = [layer[i + 1], layer[i]];
    pos.set(layer[i], i); pos.set(layer[i + 1], i + 1);
  };
  let n = crossings(g, undefined, pos);
  for (let better = true; better;) {
    better = false;
    g.layers.forEach((layer, l) => {
      for (let i = 0; i + 1 < layer.length; i++) {
        if (g.items.get(layer[i]).part !== g.items.get(layer[i + 1]).part) continue;
        const before = crossings(g, l, pos);
        swap(layer, i);
        const after = crossings(g, l, pos);
        if (after < before) { n -= before - after; better = true; } else swap(layer, i);
      }
    });
  }
  return n;
}

/** Least-squares positions under minimum gaps (pool adjacent violators): x[i+1] ≥
 * x[i] + sep[i], as close to `want` as possible. */
export function place(want, sep) {
  const off = [0];
  for (let i = 0; i < sep.length; i++) off.push(off[i] + sep[i]);
  const blocks = [];
  want.forEach((w, i) => {
    let b = { start: i, end: i, sum: w - off[i], n: 1 };
    while (blocks.length && blocks[blocks.length - 1].sum / blocks[blocks.length - 1].n > b.sum / b.n) {
      const a = blocks.pop();
      b = { start: a.start, end: b.end, sum: a.sum + b.sum, n: a.n + b.n };
    }
    blocks.push(b);
  });
  const x = [];
  for (const b of blocks) for (let i = b.start; i <= b.end; i++) x[i] = b.sum / b.n + off[i];
  return x;
}

function gapBetween(a, b) {
  if (a.part !== b.part) return GAP.part;
  if (a.dummy && b.dummy) return GAP.lane;
  return a.dummy || b.dummy ? GAP.mixed : GAP.node;
}

/** x of every item's centre (`cx`): packed, then pulled towards its neighbours. */
function assignX(g, pack) {
  const nb = neighbours(g);
  const off = (id, end) => {
    const it = g.items.get(id);
    return it.dummy || !end ? 0 : anchor(it, end.side, end.key).x - it.w / 2;
  };
  if (pack) {
    for (const layer of g.layers) {
      let x = 0;
      layer.forEach((id, i) => {
        const it = g.items.get(id);
        if (i) x += gapBetween(g.items.get(layer[i - 1]), it);
        it.cx = x + it.w / 2;
        x += it.w;
      });
    }
  }
  const relax = (l, dirs) => {
    const layer = g.layers[l];
    const want = layer.map((id) => {
      const it = g.items.get(id);
      let sum = 0, weight = 0;
      for (const n of nb.get(id)) {
        const o = g.items.get(n.id);
        if (!dirs.includes(o.layer - l) && !(it.dummy && o.layer === l)) continue;
        const wgt = it.dummy && o.dummy ? 4 : 1;
        const at = o.layer !== l ? o.cx + off(n.id, n.other) - off(id, n.end) : o.dummy ? o.cx : o.cx + beside(n) * (o.w / 2 + GAP.mixed);
        sum += wgt * at;
        weight += wgt;
      }
      return weight ? sum / weight : it.cx;
    });
    const sep = layer.slice(1).map((id, i) => {
      const [a, b] = [g.items.get(layer[i]), g.items.get(id)];
      return a.w / 2 + b.w / 2 + gapBetween(a, b);
    });
    place(want, sep).forEach((x, i) => { g.items.get(layer[i]).cx = x; });
  };
  for (let r = 0; r < ROUNDS; r++) {
    for (let l = 1; l < g.layers.length; l++) relax(l, [-1]);
    for (let l = g.layers.length - 2; l >= 0; l--) relax(l, [1]);
  }
  for (let l = 0; l < g.layers.length; l++) relax(l, [-1, 1]);
}

/** A plain module's ports in the order of the boxes at their other ends. */
function orderPorts(g, es) {
  for (const it of g.items.values()) {
    if (it.dummy || it.slots) continue;
    const otherX = (side) => (key) => {
      const xs = es.filter((e) => (side === 'top' ? e.to === it.m.path && e.entry.key === key : e.from === it.m.path && e.exit.key === key))
        .map((e) => g.items.get(side === 'top' ? e.chain[e.chain.length - 2] : e.chain[1]).cx);
      return xs.reduce((a, b) => a + b, 0) / xs.length;
    };
    for (const side of ['top', 'bottom']) {
      const at = otherX(side);
      it.order[side] = it.order[side].map((k) => [at(k), k]).sort((a, b) => a[0] - b[0]).map((x) => x[1]);
    }
  }
}

/** y of every layer; boxes centred in their layer; a waypoint spans its layer. */
function assignY(g) {
  let y = 0;
  for (const layer of g.layers) {
    const h = Math.max(0, ...layer.map((id) => g.items.get(id).h));
    for (const id of layer) {
      const it = g.items.get(id);
      it.x = it.cx - it.w / 2;
      it.band = [y, y + h];
      if (it.dummy) { it.y = y; it.h = h; } else it.y = y + (h - it.h) / 2;
    }
    y += h + LAYER_GAP;
  }
}

/** A cubic from `p` (leaving in direction p.dx, p.dy) to `q` (arriving against
 * q.dx, q.dy, its outward direction). */
function cubic(p, q) {
  const dist = Math.hypot(q.x - p.x, q.y - p.y);
  const k = Math.max(6, Math.min(48, dist / 2));
  return [p, { x: p.x + p.dx * k, y: p.y + p.dy * k }, { x: q.x + q.dx * k, y: q.y + q.dy * k }, q];
}

/** Where the edge enters and leaves lane `d`: a lane spans its layer, except where it
 * starts level with a side exit or ends level with a side entry (a short hook). */
function laneEnds(d, e, start, end, first, last) {
  const up = e.back, hook = 8;
  let enter = up ? d.y + d.h : d.y, leave = up ? d.y : d.y + d.h;
  if (first && start.dx !== 0) enter = start.y + (up ? -hook : hook);
  if (last && end.dx !== 0) leave = end.y + (up ? hook : -hook);
  return [{ x: d.cx, y: enter, dx: 0, dy: up ? 1 : -1 }, { x: d.cx, y: leave, dx: 0, dy: up ? -1 : 1 }];
}

/** The edge's path as segments (each 4 points; a straight one repeats its ends). */
function route(g, e) {
  const at = (id, end) => {
    const it = g.items.get(id), a = anchor(it, end.side, end.key);
    return { x: it.x + a.x, y: it.y + a.y, dx: a.dx, dy: a.dy };
  };
  const start = at(e.from, e.exit), end = at(e.to, e.entry);
  const lanes = e.chain.slice(1, -1), segs = [];
  // A box lower than its layer: a straight stub to the layer's edge first (and last), so
  // no curve runs through the taller boxes beside it.
  const stub = (p, band) => ({ ...p, y: p.dy > 0 ? band[1] : p.dy < 0 ? band[0] : p.y });
  let cur = stub(start, g.items.get(e.from).band);
  if (cur.y !== start.y) segs.push([start, start, cur, cur]);
  const last = stub(end, g.items.get(e.to).band);
  lanes.forEach((id, i) => {
    const [enter, leave] = laneEnds(g.items.get(id), e, start, end, i === 0, i === lanes.length - 1);
    segs.push(cubic(cur, enter), [enter, enter, leave, leave]);
    cur = leave;
  });
  segs.push(cubic(cur, last));
  if (last.y !== end.y) segs.push([last, last, end, end]);
  return segs;
}

export function pathText(segs) {
  const f = (p) => `${+p.x.toFixed(1)},${+p.y.toFixed(1)}`;
  const straight = (s) => s[1] === s[0] && s[2] === s[3];
  return `M${f(segs[0][0])}` + segs.map((s) => (straight(s) ? ` L${f(s[3])}` : ` C${f(s[1])} ${f(s[2])} ${f(s[3])}`)).join('');
}

/** The whole drawing of `modules`: boxes, edges with their paths, labels, part
 * clusters, the view box, and the crossings of the layer order (a measure of it). */
export function layout(modules, measure = estimate) {
  if (!modules.length) return { boxes: [], edges: [], labels: [], clusters: [], view: { x: 0, y: 0, w: 200, h: 40 }, crossings: 0 };
  const es = edges(modules);
  const g = proper(modules, es, measure);
  order(g);
  attachLanes(g);
  const crossed = crossings(g);
  assignX(g, true);
  orderPorts(g, es);
  assignX(g, false);
  assignY(g);
  for (const e of es) { e.segs = route(g, e); e.d = pathText(e.segs); }
  const placed = labels(g, es, measure);
  const parts = clusters(g, es);
  const all = [...parts, ...placed, ...[...g.items.values()].filter((it) => !it.dummy)];
  const x0 = Math.min(...all.map((r) => r.x)) - MARGIN, y0 = Math.min(...all.map((r) => r.y)) - MARGIN;
  const x1 = Math.max(...all.map((r) => r.x + r.w)) + MARGIN, y1 = Math.max(...all.map((r) => r.y + r.h)) + MARGIN;
  const boxes = [...g.items.entries()].filter(([, it]) => !it.dummy)
    .map(([path, it]) => ({ path, m: it.m, name: it.name, x: it.x, y: it.y, w: it.w, h: it.h, slots: it.slots, order: it.order }));
  return { boxes, edges: es, labels: placed, clusters: parts, view: { x: x0, y: y0, w: x1 - x0, h: y1 - y0 }, crossings: crossed };
}
