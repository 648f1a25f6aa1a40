// The inspector's page: asks the web server's JSON API (docs/inspect.md) for the
// element tree, then polls figures and values at a bounded rate (one request at a
// time, a pause after each) and retries while the program cannot be reached.

import { draw, fit } from './graph.js';
import * as P from './panels.js';

const POLL_MS = 500, RETRY_MS = 2000, TREE_EVERY_MS = 5000, HISTORY = 240, CHUNK = 200;
const $ = (id) => document.getElementById(id);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const enc = encodeURIComponent;

let parts = [];          // [{app, part, tree}] of the answering parts
let structure = '';      // the drawn structure, to redraw only when it changes
let showActivities = () => {};
const history = new Map(); // output path → latest numbers

async function api(url, options) {
  const r = await fetch(url, options);
  let body;
  try { body = await r.json(); } catch { body = { error: `HTTP ${r.status} without a JSON answer` }; }
  if (!r.ok) throw new Error(body.error || `HTTP ${r.status}`);
  return body;
}

function status(kind, text) {
  const s = $('status');
  s.className = 'status ' + kind;
  s.textContent = text;
}

function select(path) {
  for (const e of document.querySelectorAll('.selected')) e.classList.remove('selected');
  for (const e of document.querySelectorAll(`[data-path="${CSS.escape(path)}"], [data-module="${CSS.escape(path)}"]`)) e.classList.add('selected');
  const d = document.querySelector(`details[data-module="${CSS.escape(path)}"]`);
  if (d) { d.open = true; d.scrollIntoView({ block: 'nearest' }); }
}

function render() {
  $('app-name').textContent = [...new Set(parts.map((p) => p.app))].join(', ');
  const modules = parts.flatMap((p) => p.tree.modules);
  showActivities = draw($('graph'), modules, select);
  const box = $('modules');
  box.replaceChildren();
  for (const p of parts) {
    for (const m of p.tree.modules) {
      box.append(P.moduleSection(m, (param, text, current, msg) => setParam(p.app, param, text, current, msg)));
    }
  }
  $('edit-part').replaceChildren(...parts.map((p) => P.h('option', { value: JSON.stringify([p.app, p.part]) }, `${p.app} / ${p.part}`)));
  example(parts[0].tree.modules);
}

/** Puts an edit that works as written into the edit box (until the user changes it):
 * setting the first parameter of the first part (the one selected) to the value it has
 * (docs/inspect.md, "Structural edits"). */
function example(modules) {
  const text = $('edit-text');
  if (text.dataset.example && text.value !== text.dataset.example) return;
  const m = modules.find((x) => x.params.length);
  if (!m) return;
  const q = m.params[0];
  const ops = [{ op: 'set', param: `${m.path}/${q.name}`, value: q.value + (q.unit ? ' ' + q.unit : '') }];
  text.value = text.dataset.example = JSON.stringify({ ops }, null, 1).replace(/\n\s*/g, ' ');
}

function updateParams() {
  for (const p of parts) {
    for (const m of p.tree.modules) {
      for (const q of m.params) {
        const cell = document.querySelector(`tr[data-param="${CSS.escape(`${m.path}/${q.name}`)}"] .param-value`);
        if (cell) cell.textContent = q.value + (q.unit ? ' ' + q.unit : '');
      }
    }
  }
}

async function loadTree() {
  const answer = await api('/api/tree');
  const good = answer.parts.filter((p) => p.tree);
  if (!good.length) throw new Error(answer.parts.map((p) => p.error).join('; ') || 'no part answered');
  parts = good;
  const shape = JSON.stringify(good.map((p) => [p.app, p.part, p.tree.modules.map((m) => [m.path, m.type, m.ports])]));
  if (shape !== structure) { structure = shape; render(); } else updateParams();
}

async function poll() {
  const cs = [], ls = [], as = [], ts = [], values = {};
  for (const p of parts) {
    const s = await api(`/api/status?app=${enc(p.app)}&part=${enc(p.part)}`);
    cs.push(...s.containers); ls.push(...s.links); as.push(...s.activities);
    if (s.transport) ts.push({ part: p.part, ...s.transport });
    const outputs = p.tree.modules.flatMap((m) => m.ports.filter((q) => q.dir === 'out').map((q) => `${m.path}/${q.name}`));
    for (let i = 0; i < outputs.length; i += CHUNK) {
      const v = await api(`/api/values?app=${enc(p.app)}&paths=${outputs.slice(i, i + CHUNK).map(enc).join(',')}`);
      Object.assign(values, v.values);
    }
  }
  P.containers($('containers'), cs);
  P.links($('links'), ls);
  P.transport($('transport'), ts);
  P.activities($('activities'), as);
  showActivities(new Map(as.map((a) => [a.module, a])));
  for (const [path, v] of Object.entries(values)) {
    if (v && typeof v.value === 'number') {
      const h = history.get(path) || [];
      h.push(v.value);
      if (h.length > HISTORY) h.shift();
      history.set(path, h);
    }
  }
  for (const cell of document.querySelectorAll('td[data-shows]')) {
    const v = values[cell.dataset.shows];
    if (v) P.showValue(cell, v);
  }
  for (const c of document.querySelectorAll('canvas[data-shows]')) P.plot(c, history.get(c.dataset.shows) || []);
}

async function setParam(app, param, text, current, msg) {
  msg.className = 'param-msg';
  msg.textContent = 'asking…';
  const path = `${param.module}/${param.name}`.split('/').map(enc).join('/');
  try {
    const after = await api(`/api/param/${path}?app=${enc(app)}`, {
      method: 'POST',
      headers: { 'content-type': 'application/json' },
      body: JSON.stringify({ set: String(text), token: $('token').value.trim() }),
    });
    const shown = after.value + (after.unit ? ' ' + after.unit : '');
    current.textContent = shown;
    msg.className = 'param-msg msg-ok';
    msg.textContent = 'set to ' + shown;
  } catch (e) {
    msg.className = 'param-msg msg-bad';
    msg.textContent = e.message;
  }
}

async function sendEdit() {
  const answer = $('edit-answer');
  const target = $('edit-part').value;
  if (!target) { answer.className = 'answer bad'; answer.textContent = 'no part to send it to yet'; return; }
  const [app, part] = JSON.parse(target);
  let body = $('edit-text').value;
  try {
    const o = JSON.parse(body);
    if (o && typeof o === 'object' && !Array.isArray(o) && !('token' in o)) {
      o.token = $('token').value.trim();
      body = JSON.stringify(o);
    }
  } catch { /* sent as written: the server says what is wrong with it */ }
  answer.className = 'answer';
  answer.textContent = 'checking…';
  try {
    const r = await api(`/api/edit?app=${enc(app)}&part=${enc(part)}`, {
      method: 'POST', headers: { 'content-type': 'application/json' }, body,
    });
    answer.textContent = JSON.stringify(r, null, 2);
  } catch (e) {
    answer.className = 'answer bad';
    answer.textContent = e.message;
  }
}

async function loop() {
  let treeAt = 0;
  for (;;) {
    try {
      if (!parts.length || Date.now() - treeAt > TREE_EVERY_MS) {
        await loadTree();
        treeAt = Date.now();
      }
      await poll();
      status('ok', 'live: ' + parts.map((p) => `${p.app} / ${p.part}`).join(', '));
      await sleep(POLL_MS);
    } catch (e) {
      status('bad', `cannot reach the program: ${e.message} (retrying every ${RETRY_MS / 1000} s)`);
      treeAt = 0;
      await sleep(RETRY_MS);
    }
  }
}

$('edit-send').addEventListener('click', sendEdit);
window.addEventListener('resize', () => fit($('graph')));
$('graph-zoom').addEventListener('click', () => {
  const svg = $('graph'), actual = svg.dataset.zoom !== 'actual';
  svg.dataset.zoom = actual ? 'actual' : 'fit';
  $('graph-zoom').textContent = actual ? 'fit to window' : 'actual size';
  fit(svg);
});
loop();
