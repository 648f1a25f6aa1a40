// The panels beside and below the graph: thread containers, links, activities, and
// each module's ports (live values, plots of numbers) and parameters (editable).
// Everything the programs send is shown as text (textContent), never as HTML.

export function h(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === 'class') e.className = v; else if (k.startsWith('on')) e.addEventListener(k.slice(2), v); else e.setAttribute(k, v);
  }
  for (const c of children) if (c !== null && c !== undefined) e.append(c);
  return e;
}

const fixed = (x, n) => (typeof x === 'number' && isFinite(x) ? x.toFixed(n) : '–');

export function containers(table, list) {
  table.replaceChildren(h('tr', {}, h('th', {}, 'container'), h('th', {}, 'load'), h('th', {}, 'cycles'),
    h('th', {}, 'overruns'), h('th', {}, 'mean cycle')));
  for (const c of list) {
    const load = Math.max(0, Math.min(1, c.load || 0));
    const bar = h('span', { class: 'load' }, h('span', { style: `width:${(load * 100).toFixed(1)}%` }));
    const steps = (c.steps || []).map((s) => `${s.name}: ${s.runs} runs, mean ${fixed(s.mean_us, 1)} µs, max ${fixed(s.max_us, 1)} µs`);
    table.append(h('tr', { 'data-container': c.path, title: steps.join('\n') },
      h('td', {}, c.path, c.panics && c.panics.length ? h('div', { class: 'msg-bad' }, 'panicked: ' + c.panics.join('; ')) : null),
      h('td', {}, bar, fixed(c.load * 100, 1) + ' %'),
      h('td', { class: 'num cycles' }, String(c.cycles)),
      h('td', { class: 'num' + (c.overruns ? ' msg-bad' : '') }, String(c.overruns)),
      h('td', { class: 'num' }, fixed(c.mean_cycle_us, 0) + ' µs')));
  }
}

export function links(table, list) {
  if (!list.length) {
    table.replaceChildren(h('tr', {}, h('td', {}, 'no inputs fed from other parts')));
    return;
  }
  table.replaceChildren(h('tr', {}, h('th', {}, 'input'), h('th', {}, 'state'), h('th', {}, 'latest value')));
  for (const l of list) {
    table.append(h('tr', { 'data-link': l.input }, h('td', {}, l.input),
      h('td', { class: 'state-' + l.state }, l.state),
      h('td', { class: 'num' }, l.age_ms === null || l.age_ms === undefined ? '–' : fixed(l.age_ms, 0) + ' ms ago')));
  }
}

/** A number of bytes as people read it. */
const bytes = (n) => (n < 1024 ? `${n} bytes` : n < 1048576 ? `${(n / 1024).toFixed(1)} KiB` : `${(n / 1048576).toFixed(1)} MiB`);

/** How the links each part sends to other parts travel (`parts`: each part's
 * `transport` answer with its name): per link, shared memory or network and the
 * counts; per part, its shared-memory pool's use. */
export function transport(table, parts) {
  const links = parts.flatMap((p) => p.links || []);
  if (!links.length) {
    table.replaceChildren(h('tr', {}, h('td', {}, 'no links to other parts')));
    return;
  }
  table.replaceChildren(h('tr', {}, h('th', {}, 'output → part'), h('th', {}, 'travels by'),
    h('th', {}, 'shared memory'), h('th', {}, 'network'), h('th', {}, 'dropped')));
  for (const l of links) {
    const by = l.by === 'shared memory' ? 'shm' : l.by === 'network' ? 'network' : 'mixed';
    table.append(h('tr', { 'data-link-out': l.output, 'data-to': l.to_part },
      h('td', {}, `${l.output} → ${l.to_part}`),
      h('td', { class: 'by by-' + by }, l.by),
      h('td', { class: 'num shm' }, String(l.shared_memory)),
      h('td', { class: 'num net' }, String(l.network)),
      h('td', { class: 'num' + (l.dropped ? ' msg-bad' : '') }, String(l.dropped))));
  }
  for (const p of parts.filter((x) => x.pool)) {
    const share = p.pool.size ? p.pool.used / p.pool.size : 0;
    const bar = h('span', { class: 'load' }, h('span', { style: `width:${(Math.min(1, share) * 100).toFixed(1)}%` }));
    const back = p.pool.reclaimed || 0;
    const notYet = p.pool.gone_held || 0;
    const gone = back || notYet ? `; of readers that are gone: ${back} back, ${notYet} not yet` : '';
    table.append(h('tr', { 'data-pool': p.part, 'data-used': String(p.pool.used), 'data-size': String(p.pool.size) },
      h('td', {}, `shared memory pool of ${p.part}`),
      h('td', { colspan: '4' }, bar, `${bytes(p.pool.used)} of ${bytes(p.pool.size)} in use (values of ${bytes(p.pool.threshold)} and more)${gone}`)));
  }
}

export function activities(box, list) {
  box.replaceChildren();
  for (const a of list) {
    const meter = h('div', { class: 'meter', title: 'activity (top), target rating (bottom)' },
      h('div', { class: 'a', style: `width:${Math.max(0, Math.min(1, a.activity || 0)) * 100}%` }),
      h('div', { class: 'r', style: `width:${Math.max(0, Math.min(1, a.target_rating || 0)) * 100}%` }));
    box.append(h('div', { class: 'activity-row', 'data-behaviour': a.module }, h('span', {}, a.module), meter,
      h('span', { class: 'num' }, `a ${fixed(a.activity, 2)} r ${fixed(a.target_rating, 2)}`)));
  }
  if (!list.length) box.append('no iB2C behaviours');
}

/** A parameter's type, unit and limits as a short text. */
export function limits(p) {
  const parts = [p.type];
  if (p.min !== null || p.max !== null) parts.push(`${p.min ?? ''}..=${p.max ?? ''}`);
  if (p.choices && p.choices.length) parts.push('one of ' + p.choices.join(', '));
  return parts.join(', ');
}

/** Roles of a port published or subscribed as a ROS 2 topic (the others are services
 * and clients). */
const TOPIC = new Set(['publish', 'subscribe']);

/** The line under a port (or service) saying which ROS 2 topic (or service) its part's
 * node makes of it: name, type, QoS, node. */
export function ros2Line(e) {
  const qos = e.qos ? `; ${e.qos.reliability}, ${e.qos.durability}, depth ${e.qos.depth}` : '';
  const field = e.field ? `.${e.field}` : '';
  return h('div', { class: 'ros2', 'data-ros2': e.name, title: `ROS 2 node ${e.node}, domain ${e.domain}` },
    `ROS 2 ${e.role} ${e.name} (${e.type}${field}${qos})`);
}

/** One module's section: its ports (value cells keyed by the path whose value they
 * show) and parameters (`onSet(param, text, messageCell)` on Set). */
export function moduleSection(m, onSet) {
  const ros2 = m.ros2 || [];
  const ports = h('table', { class: 'grid' }, h('tr', {}, h('th', {}, 'port'), h('th', {}, 'type'),
    h('th', {}, 'value'), h('th', {}, 'over time')));
  for (const p of m.ports) {
    const shown = p.dir === 'out' ? `${m.path}/${p.name}` : (p.from.length === 1 ? p.from[0] : null);
    const value = h('td', { class: 'value', 'data-port': `${m.path}/${p.name}` }, shown ? '…' : (p.from.length ? 'several writers' : 'not connected'));
    if (shown) value.dataset.shows = shown;
    const plot = h('canvas', { class: 'plot', width: 180, height: 32 });
    if (shown) plot.dataset.shows = shown;
    const topics = ros2.filter((e) => TOPIC.has(e.role) && e.port === p.name).map(ros2Line);
    ports.append(h('tr', {},
      h('td', {}, `${p.dir === 'in' ? '▸' : '◂'} ${p.name}`, p.from.length ? h('div', { class: 'type' }, '← ' + p.from.join(', ')) : null, ...topics),
      h('td', {}, p.type + (p.unit ? ` [${p.unit}]` : '') + (p.meta ? ' (meta)' : '')),
      value, h('td', {}, plot)));
  }
  for (const e of ros2.filter((e) => !TOPIC.has(e.role))) {
    ports.append(h('tr', {}, h('td', {}, `⇄ ${e.port}`, ros2Line(e)), h('td', {}, e.role), h('td', {}), h('td', {})));
  }
  const params = h('table', { class: 'grid' });
  if (m.params.length) params.append(h('tr', {}, h('th', {}, 'parameter'), h('th', {}, 'value'), h('th', {}, 'type, range'), h('th', {}, 'new value'), h('th', {}, '')));
  for (const p of m.params) {
    const path = `${m.path}/${p.name}`;
    const current = h('td', { class: 'value param-value' }, p.value + (p.unit ? ' ' + p.unit : ''));
    const input = p.choices && p.choices.length
      ? h('select', { class: 'param-input' }, ...p.choices.map((c) => h('option', c === p.value ? { selected: '' } : {}, c)))
      : h('input', { class: 'param-input', type: 'text', value: p.value, 'aria-label': `new value of ${path}` });
    const msg = h('td', { class: 'param-msg' });
    const set = () => onSet(p, input.value, current, msg);
    input.addEventListener('keydown', (e) => { if (e.key === 'Enter') set(); });
    params.append(h('tr', { 'data-param': path }, h('td', {}, p.name), current,
      h('td', {}, limits(p)), h('td', {}, input, p.unit ? ' ' + p.unit : ''),
      h('td', {}, h('button', { type: 'button', class: 'param-set', onclick: set }, 'Set')), msg));
  }
  return h('details', { class: 'module', 'data-module': m.path, open: '' },
    h('summary', {}, h('strong', {}, m.path), ' ', h('span', { class: 'kind' }, `${m.type} (${m.kind})${m.container ? ', in ' + m.container : ''}${m.source ? ', ' + m.source : ''}`)),
    ports, params);
}

/** A number as people read it: integers exact, others to 4 significant digits (more
 * where the integer part needs them), in shortest round-trip form (0.7, not
 * 0.7000000000000001). */
export function shortNumber(x) {
  if (!Number.isFinite(x) || Number.isInteger(x)) return x;
  const digits = Math.min(15, Math.max(4, Math.floor(Math.log10(Math.abs(x))) + 1));
  return Number(x.toPrecision(digits));
}

/** Elements of an array shown before the count of the rest. */
const ITEMS = 8;
/** Decimals long enough to shorten in a text (a value whose library gave no serde
 * form arrives as its Rust text: `Pose2D { x: 1.2345678901234567, … }`). */
const LONG_DECIMAL = /-?\d+\.\d{5,}(?:e[+-]?\d+)?/gi;

/** A value as short JSON: numbers shortened, a long array cut to its first elements and
 * a count of the rest (still JSON); text of a type without serde with its long decimals
 * shortened. The exact value is the cell's tooltip. */
export function shortJson(value) {
  const walk = (v) => {
    if (typeof v === 'number') return shortNumber(v);
    if (typeof v === 'string') return v.replace(LONG_DECIMAL, (n) => String(shortNumber(Number(n))));
    if (Array.isArray(v)) {
      const head = v.slice(0, ITEMS).map(walk);
      return v.length > ITEMS ? [...head, `… ${v.length - ITEMS} more`] : head;
    }
    if (v && typeof v === 'object') return Object.fromEntries(Object.entries(v).map(([k, x]) => [k, walk(x)]));
    return v;
  };
  return spaced(walk(value));
}

/** JSON with a space after each comma and colon, as people write it. */
const spaced = (v) => (Array.isArray(v) ? `[${v.map(spaced).join(', ')}]`
  : v && typeof v === 'object' ? `{${Object.entries(v).map(([k, x]) => `${JSON.stringify(k)}: ${spaced(x)}`).join(', ')}}`
    : JSON.stringify(v));

/** Shows a value in a cell: numbers short (the exact number in data-number for
 * scripts and in the tooltip), others as short JSON. A value nothing has published yet
 * is greyed (class `unpublished`), its text still the value's JSON. */
export function showValue(cell, v) {
  if (v && v.error) {
    cell.textContent = v.error; cell.className = 'value msg-bad'; delete cell.dataset.number; return;
  }
  cell.className = 'value' + (v.published ? '' : ' unpublished');
  const value = v.value;
  if (typeof value === 'number') {
    cell.textContent = JSON.stringify(shortNumber(value)) + (v.unit ? ' ' + v.unit : '');
    cell.dataset.number = String(value);
    cell.title = String(value) + (v.unit ? ' ' + v.unit : '');
  } else {
    const text = typeof value === 'string' && /^(String|str|string)$/.test(v.type || '') ? JSON.stringify(value) : shortJson(value);
    cell.textContent = text;
    const exact = JSON.stringify(value);
    cell.title = exact.length > 4000 ? exact.slice(0, 4000) + '…' : exact;
    delete cell.dataset.number;
  }
  if (!v.published) cell.title = 'nothing published yet (the initial value): ' + cell.title;
}

/** A line of the latest numbers, scaled to their range. */
export function plot(canvas, series) {
  const g = canvas.getContext('2d'), w = canvas.width, ht = canvas.height;
  g.clearRect(0, 0, w, ht);
  if (series.length < 2) return;
  let lo = Math.min(...series), hi = Math.max(...series);
  if (hi === lo) { hi += 0.5; lo -= 0.5; }
  g.strokeStyle = '#1565c0'; g.lineWidth = 1.2; g.beginPath();
  series.forEach((x, i) => {
    const px = (i / (series.length - 1)) * (w - 2) + 1, py = ht - 2 - ((x - lo) / (hi - lo)) * (ht - 4);
    if (i) g.lineTo(px, py); else g.moveTo(px, py);
  });
  g.stroke();
  canvas.title = `min ${lo.toPrecision(4)}, max ${hi.toPrecision(4)}, ${series.length} values`;
}
