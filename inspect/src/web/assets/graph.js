// The application drawn as `ferroc graph` draws it (compiler/src/graph.rs): behaviours
// are boxes with their meta inputs on top (s stimulation, i0… inhibition, ch k fusion
// channels) and meta outputs below (a activity, a/… derived activities, r target
// rating); stimulation edges are green arrows, inhibition edges red bars, activities
// and target ratings into a fusion channel blue dashed, data grey with the port's
// name. Parts are dashed clusters. Layout: layers by longest path after breaking
// cycles (back edges dotted), ordered by the barycentre of their predecessors.

const NS = 'http://www.w3.org/2000/svg';
const SLOT = 26, ROW = 16, LAYER_GAP = 70, NODE_GAP = 28, MARGIN = 24;

function el(name, attrs, parent) {
  const e = document.createElementNS(NS, name);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

const isBehaviour = (m) => m.kind === 'behaviour' || m.kind === 'fusion';
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
function slots(m) {
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

/** The edges between modules: {from, to, kind, fromSlot, toSlot, label}. */
export function edges(modules) {
  const byPath = new Map(modules.map((m) => [m.path, m]));
  const out = [], seen = new Set();
  for (const m of modules) {
    for (const p of m.ports) {
      if (p.dir !== 'in') continue;
      for (const writer of p.from) {
        const from = writerModule(byPath, writer);
        if (!from) continue;
        const port = writer.slice(from.length + 1);
        const src = byPath.get(from);
        const srcMeta = src.ports.some((q) => q.name === port && q.meta);
        let kind = 'data', toSlot = null, fromSlot = null;
        if (isBehaviour(m)) {
          const ch = channelOf(p.name), inh = /^inhibition\/(\d+)$/.exec(p.name);
          if (p.meta && p.name === 'stimulation') { kind = 'stim'; toSlot = 's'; }
          else if (p.meta && inh) { kind = 'inhib'; toSlot = 'i' + inh[1]; }
          else if (ch !== null) { kind = p.meta ? 'meta' : 'data'; toSlot = 'ch ' + ch; }
        }
        if (isBehaviour(src) && srcMeta) {
          fromSlot = port === 'activity' ? 'a' : port === 'target_rating' ? 'r'
            : port.startsWith('activity/') ? 'a/' + port.slice(9) : null;
        }
        const id = `${writer}→${m.path}/${p.name}`;
        if (seen.has(id)) continue;
        seen.add(id);
        out.push({ from, to: m.path, kind, fromSlot, toSlot, port, input: p.name, label: kind === 'data' ? port : '' });
      }
    }
  }
  return out;
}

/** Layers (arrays of module paths) by longest path over the edges without back edges. */
function layers(modules, es) {
  const order = modules.map((m) => m.path);
  const succ = new Map(order.map((p) => [p, []]));
  for (const e of es) if (e.from !== e.to) succ.get(e.from).push(e);
  const state = new Map(), back = new Set();
  const visit = (p) => {
    state.set(p, 1);
    for (const e of succ.get(p)) {
      const s = state.get(e.to);
      if (s === 1) back.add(e); else if (!s) visit(e.to);
    }
    state.set(p, 2);
  };
  for (const p of order) if (!state.get(p)) visit(p);
  const level = new Map(order.map((p) => [p, 0]));
  for (let changed = true, n = 0; changed && n < order.length + 1; n++) {
    changed = false;
    for (const e of es) {
      if (back.has(e) || e.from === e.to) continue;
      if (level.get(e.to) < level.get(e.from) + 1) { level.set(e.to, level.get(e.from) + 1); changed = true; }
    }
  }
  const rows = [];
  for (const p of order) (rows[level.get(p)] ||= []).push(p);
  // Barycentre ordering, twice down: fewer crossings for little code.
  for (let pass = 0; pass < 2; pass++) {
    for (let i = 1; i < rows.length; i++) {
      const pos = new Map(rows[i - 1].map((p, j) => [p, j]));
      const bary = (p) => {
        const xs = es.filter((e) => e.to === p && pos.has(e.from)).map((e) => pos.get(e.from));
        return xs.length ? xs.reduce((a, b) => a + b, 0) / xs.length : Infinity;
      };
      rows[i] = rows[i].map((p, j) => [bary(p), j, p]).sort((a, b) => a[0] - b[0] || a[1] - b[1]).map((x) => x[2]);
    }
  }
  return { rows: rows.filter(Boolean), back };
}

const textWidth = (s, px) => s.length * px;
const SLOT_NAMES = { s: 'stimulation', i: 'inhibition', c: 'fusion channel', a: 'activity', r: 'target rating' };

/** Draws `modules` into `svg`; `onSelect(path)` when a module is clicked. Returns the
 * function that shows activities: update(Map path → activity). */
export function draw(svg, modules, onSelect) {
  svg.replaceChildren();
  const es = edges(modules);
  const { rows } = layers(modules, es);
  const byPath = new Map(modules.map((m) => [m.path, m]));
  const box = new Map();
  // Edges spanning several layers run down lanes right of the boxes, edges closing a
  // cycle up lanes left of them; one lane per source module.
  const layerOf = new Map();
  rows.forEach((row, i) => row.forEach((p) => layerOf.set(p, i)));
  const backSources = new Set(), longSources = new Set();
  for (const e of es) {
    const span = layerOf.get(e.to) - layerOf.get(e.from);
    if (span <= 0) backSources.add(e.from); else if (span > 1) longSources.add(e.from);
  }
  const left = MARGIN + 12 * backSources.size;
  let y = MARGIN + 14, width = 0;
  for (const [layer, row] of rows.entries()) {
    let x = left, h = 0;
    for (const p of row) {
      const m = byPath.get(p), name = p.split('/').pop();
      const s = isBehaviour(m) ? slots(m) : null;
      const w = Math.max(textWidth(name, 7), textWidth(m.type, 5.2), s ? Math.max(s.top.length, s.bottom.length) * SLOT : 0) + 16;
      const hh = s ? 2 * ROW + 34 : 36;
      box.set(p, { x, y, w, h: hh, slots: s, m, name, layer });
      x += w + NODE_GAP; h = Math.max(h, hh);
    }
    width = Math.max(width, x - NODE_GAP);
    y += h + LAYER_GAP;
  }
  // Rows centred under the widest.
  for (const row of rows) {
    const last = box.get(row[row.length - 1]);
    const shift = (width - (last.x + last.w)) / 2;
    for (const p of row) box.get(p).x += shift;
  }
  const lanesFrom = width + 16;
  width = lanesFrom + 12 * longSources.size;
  const height = y - LAYER_GAP + MARGIN;
  svg.setAttribute('width', width + MARGIN);
  svg.setAttribute('height', height);
  svg.setAttribute('viewBox', `0 0 ${width + MARGIN} ${height}`);
  const defs = el('defs', {}, svg);
  for (const [id, color, shape] of [['arrow-stim', '#2e7d32', 'M0,0 L8,4 L0,8 z'], ['arrow-data', '#757575', 'M0,0 L8,4 L0,8 z'],
    ['arrow-meta', '#1565c0', 'M0,0 L8,4 L0,8 z'], ['tee-inhib', '#c62828', 'M7,0 L7,8 L9,8 L9,0 z']]) {
    const mk = el('marker', { id, viewBox: '0 0 10 8', refX: 8, refY: 4, markerWidth: 10, markerHeight: 8, orient: 'auto-start-reverse' }, defs);
    el('path', { d: shape, fill: id === 'arrow-meta' ? '#fff' : color, stroke: color }, mk);
  }
  // Part clusters.
  const parts = new Map();
  for (const b of box.values()) {
    const c = parts.get(b.m.part) || { x0: Infinity, y0: Infinity, x1: 0, y1: 0 };
    c.x0 = Math.min(c.x0, b.x); c.y0 = Math.min(c.y0, b.y); c.x1 = Math.max(c.x1, b.x + b.w); c.y1 = Math.max(c.y1, b.y + b.h);
    parts.set(b.m.part, c);
  }
  for (const [part, c] of parts) {
    // Wide enough for the lanes beside the boxes.
    const x0 = Math.min(c.x0, left) - 12 * backSources.size - 8, x1 = width + 6;
    el('rect', { class: 'cluster', x: x0, y: c.y0 - 22, width: x1 - x0, height: c.y1 - c.y0 + 34, rx: 6 }, svg);
    el('text', { x: x0 + 4, y: c.y0 - 8, fill: '#757575' }, svg).textContent = 'part ' + part;
  }
  const slotX = (b, list, name) => {
    const i = list ? list.indexOf(name) : -1;
    if (i < 0) return b.x + b.w / 2;
    const start = b.x + (b.w - list.length * SLOT) / 2;
    return start + i * SLOT + SLOT / 2;
  };
  const edgeLayer = el('g', {}, svg);
  const lane = new Map();
  const laneOf = (key, base, step) => {
    if (!lane.has(key)) lane.set(key, base + step * [...lane.keys()].filter((k) => k[0] === key[0]).length);
    return lane.get(key);
  };
  for (const e of es) {
    const a = box.get(e.from), b = box.get(e.to);
    const x1 = slotX(a, a.slots && a.slots.bottom, e.fromSlot), y1 = a.y + a.h;
    const x2 = slotX(b, b.slots && b.slots.top, e.toSlot), y2 = b.y;
    const span = b.layer - a.layer;
    let d, cls = '';
    if (span === 1) {
      const bend = (y2 - y1) / 2;
      d = `M${x1},${y1} C${x1},${y1 + bend} ${x2},${y2 - bend} ${x2},${y2}`;
    } else if (span > 1) {
      const x = laneOf('R' + e.from, lanesFrom, 12);
      d = `M${x1},${y1} C${x1},${y1 + 30} ${x},${y1 + 5} ${x},${y1 + 35} L${x},${y2 - 35} C${x},${y2 - 5} ${x2},${y2 - 30} ${x2},${y2}`;
    } else {
      const x = laneOf('L' + e.from, left - 12, -12);
      cls = ' back';
      d = `M${x1},${y1} C${x1},${y1 + 30} ${x},${y1 + 30} ${x},${y1} L${x},${y2} C${x},${y2 - 30} ${x2},${y2 - 30} ${x2},${y2}`;
    }
    const marker = { stim: 'url(#arrow-stim)', inhib: 'url(#tee-inhib)', meta: 'url(#arrow-meta)', data: 'url(#arrow-data)' }[e.kind];
    const line = el('path', { d, class: `edge ${e.kind}${cls}`, 'marker-end': marker, 'data-from': e.from, 'data-to': e.to }, edgeLayer);
    el('title', {}, line).textContent = `${e.from}/${e.port} → ${e.to}/${e.input}`;
    if (e.label && span === 1) el('text', { x: (x1 + x2) / 2 + 3, y: (y1 + y2) / 2, class: 'edge-label' }, edgeLayer).textContent = e.label;
  }
  const bars = new Map();
  for (const [p, b] of box) {
    const g = el('g', { class: 'module' + (b.slots ? ' behaviour' : ''), 'data-path': p }, svg);
    g.addEventListener('click', () => onSelect(p));
    el('title', {}, g).textContent = `${p}\n${b.m.type} (${b.m.kind})${b.m.source ? '\n' + b.m.source : ''}`;
    el('rect', { class: 'box', x: b.x, y: b.y, width: b.w, height: b.h, rx: b.slots ? 2 : 8 }, g);
    let ty = b.y + 15;
    if (b.slots) {
      for (const [list, yy] of [[b.slots.top, b.y], [b.slots.bottom, b.y + b.h - ROW]]) {
        list.forEach((s, i) => {
          const x = b.x + (b.w - list.length * SLOT) / 2 + i * SLOT;
          el('title', {}, el('rect', { class: 'slot', x, y: yy, width: SLOT, height: ROW }, g)).textContent = SLOT_NAMES[s[0]] ? `${SLOT_NAMES[s[0]]} ${s}` : s;
          el('text', { x: x + SLOT / 2, y: yy + 12, 'text-anchor': 'middle' }, g).textContent = s.length > 4 ? s.slice(0, 4) : s;
        });
      }
      ty = b.y + ROW + 14;
      bars.set(p, el('rect', { class: 'bar', x: b.x + 1, y: b.y + b.h - ROW - 5, width: 0, height: 4 }, g));
    }
    el('text', { x: b.x + b.w / 2, y: ty, 'text-anchor': 'middle' }, g).textContent = b.name;
    el('text', { x: b.x + b.w / 2, y: ty + 12, 'text-anchor': 'middle', class: 'type' }, g).textContent = b.m.type;
  }
  return (activities) => {
    for (const [p, bar] of bars) {
      const a = activities.get(p);
      const w = box.get(p).w - 2;
      bar.setAttribute('width', typeof a === 'number' && isFinite(a) ? Math.max(0, Math.min(1, a)) * w : 0);
    }
  };
}
