// The application drawn as `ferroc graph` draws it (compiler/src/graph.rs), laid out by
// layout.js: behaviours are boxes with their meta inputs on top (s stimulation, i0…
// inhibition, ch k fusion channels) and meta outputs below (a activity, a/… derived
// activities, r target rating), two bars inside showing their activity (a) and target
// rating (r); stimulation edges are green arrows, inhibition edges red bars, activities
// and target ratings into a fusion channel blue dashed, data grey with the port's name;
// an edge feeding an earlier layer (closing a cycle) is dotted. Parts are dashed
// clusters. The drawing is scaled to fit the window (the button shows it actual size).

import { layout, slotRects, ROW } from './layout.js';

const NS = 'http://www.w3.org/2000/svg';
const FONT = 'Helvetica, Arial, sans-serif';
/** Smallest scale the drawing is fitted at; a larger graph scrolls. */
const MIN_SCALE = 0.45;

function el(name, attrs, parent) {
  const e = document.createElementNS(NS, name);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

let ctx = null;
/** The width of `text` at `px` in the drawing's font, as the browser measures it. */
function measure(text, px) {
  ctx ||= document.createElement('canvas').getContext('2d');
  ctx.font = `${px}px ${FONT}`;
  return ctx.measureText(text).width;
}

const SLOT_NAMES = { s: 'stimulation', i: 'inhibition', c: 'fusion channel', a: 'activity', r: 'target rating' };
const MARKERS = { stim: 'url(#arrow-stim)', inhib: 'url(#tee-inhib)', meta: 'url(#arrow-meta)', data: 'url(#arrow-data)' };

/** Scales the drawing to the room left in the window (or shows it actual size). */
export function fit(svg) {
  const box = svg.parentElement, w = Number(svg.dataset.width), h = Number(svg.dataset.height);
  if (!box || !w || !h) return;
  const top = box.getBoundingClientRect().top + window.scrollY;
  const roomW = box.clientWidth, roomH = Math.max(240, window.innerHeight - top - 14);
  const scale = svg.dataset.zoom === 'actual' ? 1 : Math.max(MIN_SCALE, Math.min(1, roomW / w, roomH / h));
  svg.style.width = `${w * scale}px`;
  svg.style.height = `${h * scale}px`;
  svg.dataset.scale = scale.toFixed(3);
}

function drawEdges(svg, L) {
  const g = el('g', { class: 'edges' }, svg);
  for (const e of L.edges) {
    const line = el('path', { d: e.d, class: `edge ${e.kind}${e.back ? ' back' : ''}`, 'marker-end': MARKERS[e.kind], 'data-from': e.from, 'data-to': e.to }, g);
    // The data edges of one port share its label (layout.js places one per port).
    if (e.label) line.dataset.edge = `${e.from}|${e.exit.key}`;
    el('title', {}, line).textContent = `${e.from}/${e.port} → ${e.to}/${e.input}`;
  }
  const labels = el('g', { class: 'labels' }, svg);
  for (const l of L.labels) {
    el('text', { x: l.x + 1, y: l.y + l.h - 3, class: 'edge-label', 'data-edge': l.edge }, labels).textContent = l.text;
  }
}

/** A behaviour's slots and its two bars; returns the bars' parts to update. */
function drawBehaviour(g, b) {
  for (const [side, yy] of [['top', b.y], ['bottom', b.y + b.h - ROW]]) {
    for (const { name: s, x: dx, w } of slotRects(b, side)) {
      const x = b.x + dx;
      el('title', {}, el('rect', { class: 'slot', x, y: yy, width: w, height: ROW }, g)).textContent = SLOT_NAMES[s[0]] ? `${SLOT_NAMES[s[0]]} ${s}` : s;
      el('text', { x: x + w / 2, y: yy + 12, 'text-anchor': 'middle', class: 'slot-name' }, g).textContent = s;
    }
  }
  const meters = el('g', { class: 'meters' }, g);
  const tip = el('title', {}, meters);
  const x0 = b.x + 16, x1 = b.x + b.w - 30;
  const bars = ['a', 'r'].map((which, i) => {
    const y = b.y + b.h - ROW - 20 + i * 9;
    el('text', { x: b.x + 6, y: y + 5, class: 'meter-name' }, meters).textContent = which;
    el('rect', { class: 'track', x: x0, y, width: x1 - x0, height: 5 }, meters);
    const bar = el('rect', { class: `bar ${which === 'a' ? 'activity' : 'rating'}`, x: x0, y, width: 0, height: 5 }, meters);
    const value = el('text', { x: b.x + b.w - 5, y: y + 5, 'text-anchor': 'end', class: 'meter-value' }, meters);
    return { bar, value, width: x1 - x0 };
  });
  return { tip, bars };
}

/** Draws `modules` into `svg`; `onSelect(path)` when a module is clicked. Returns the
 * function that shows iB2C figures: update(Map path → {activity, target_rating}). */
export function draw(svg, modules, onSelect) {
  svg.replaceChildren();
  const L = layout(modules, measure);
  svg.setAttribute('viewBox', `${L.view.x} ${L.view.y} ${L.view.w} ${L.view.h}`);
  svg.dataset.width = L.view.w;
  svg.dataset.height = L.view.h;
  svg.dataset.crossings = L.crossings;
  for (const c of L.clusters) {
    el('rect', { class: 'cluster', x: c.x, y: c.y, width: c.w, height: c.h, rx: 6 }, svg);
    el('text', { x: c.x + 6, y: c.y + 14, class: 'cluster-name' }, svg).textContent = 'part ' + c.part;
  }
  drawEdges(svg, L);
  const meters = new Map();
  for (const b of L.boxes) {
    const g = el('g', { class: 'module' + (b.slots ? ' behaviour' : ''), 'data-path': b.path }, svg);
    g.addEventListener('click', () => onSelect(b.path));
    el('title', {}, g).textContent = `${b.path}\n${b.m.type} (${b.m.kind})${b.m.source ? '\n' + b.m.source : ''}`;
    el('rect', { class: 'box', x: b.x, y: b.y, width: b.w, height: b.h, rx: b.slots ? 2 : 8 }, g);
    const ty = b.slots ? b.y + ROW + 13 : b.y + 15;
    el('text', { x: b.x + b.w / 2, y: ty, 'text-anchor': 'middle' }, g).textContent = b.name;
    el('text', { x: b.x + b.w / 2, y: ty + 11, 'text-anchor': 'middle', class: 'type' }, g).textContent = b.m.type;
    if (b.slots) meters.set(b.path, drawBehaviour(g, b));
  }
  fit(svg);
  return (figures) => {
    for (const [p, m] of meters) {
      const f = figures.get(p) || {};
      const shown = [f.activity, f.target_rating];
      m.bars.forEach((b, i) => {
        const x = shown[i], ok = typeof x === 'number' && isFinite(x);
        b.bar.setAttribute('width', ok ? Math.max(0, Math.min(1, x)) * b.width : 0);
        b.value.textContent = ok ? x.toFixed(2) : '–';
      });
      m.tip.textContent = `activity a = ${m.bars[0].value.textContent}, target rating r = ${m.bars[1].value.textContent}`;
    }
  };
}
