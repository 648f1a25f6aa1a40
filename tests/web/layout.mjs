// The graph layout of the inspector's page (inspect/src/web/assets/layout.js) checked
// in Node, without a browser (run by tests/inspect_web.rs): on nav_behaviours' graph,
// on cycles and self-loops, on two parts and on a generated graph of 60 modules, no two
// boxes overlap, no edge label overlaps a box or another label, every edge runs from
// its writer's port to its reader's port, no edge passes through a box it does not
// connect, and parts' rectangles are apart. Prints one `ok:` line per graph.

import { pathToFileURL } from 'node:url';
import { layout, samples, overlaps } from '../../inspect/src/web/assets/layout.js';

const fail = (text) => { console.log('FAILED: ' + text); process.exit(1); };

/** A tree as /api/tree gives it, from `FROM/PORT TO/PORT` lines; `kinds` names the
 * behaviours (`name:behaviour`, `name:fusion`) and the modules' order. */
export function tree(kinds, lines, part = 'robot') {
  const mods = new Map();
  const mod = (name) => {
    const [n, kind] = name.split(':');
    if (!mods.has(n)) mods.set(n, { path: `${part}/main/${n}`, type: `lib.${n[0].toUpperCase()}${n.slice(1)}`, kind: kind || 'module', part, ports: [], params: [] });
    return mods.get(n);
  };
  kinds.forEach(mod);
  const meta = (n) => /^(activity|target_rating|stimulation|inhibition)/.test(n) || /^in\/\d+\/(activity|target_rating)$/.test(n);
  for (const line of lines.trim().split('\n')) {
    const [from, to] = line.trim().split(/\s+/);
    const [fm, ...fp] = from.split('/'), [tm, ...tp] = to.split('/');
    const a = mod(fm), b = mod(tm), out = fp.join('/'), inp = tp.join('/');
    if (!a.ports.some((p) => p.dir === 'out' && p.name === out)) a.ports.push({ name: out, dir: 'out', type: 'f64', meta: meta(out), from: [] });
    let q = b.ports.find((p) => p.dir === 'in' && p.name === inp);
    if (!q) b.ports.push(q = { name: inp, dir: 'in', type: 'f64', meta: meta(inp), from: [] });
    q.from.push(`${a.path}/${out}`);
  }
  return [...mods.values()];
}

export const NAV = tree(['sim', 'goal', 'operator', 'go_to_goal:behaviour', 'follow_wall:behaviour', 'avoid:behaviour', 'fusion:fusion', 'monitor'], `
  sim/pose go_to_goal/pose
  goal/goal go_to_goal/goal
  sim/scan follow_wall/scan
  sim/scan avoid/scan
  follow_wall/activity go_to_goal/inhibition/0
  go_to_goal/activity/arrived follow_wall/inhibition/0
  avoid/activity/emergency go_to_goal/inhibition/1
  avoid/activity/emergency follow_wall/inhibition/1
  operator/activity fusion/stimulation
  go_to_goal/activity fusion/in/0/activity
  go_to_goal/target_rating fusion/in/0/target_rating
  go_to_goal/linear fusion/in/0/linear
  go_to_goal/angular fusion/in/0/angular
  follow_wall/activity fusion/in/1/activity
  follow_wall/target_rating fusion/in/1/target_rating
  follow_wall/linear fusion/in/1/linear
  follow_wall/angular fusion/in/1/angular
  avoid/activity fusion/in/2/activity
  avoid/target_rating fusion/in/2/target_rating
  avoid/linear fusion/in/2/linear
  avoid/angular fusion/in/2/angular
  fusion/linear sim/linear
  fusion/angular sim/angular
  sim/pose monitor/pose
  go_to_goal/activity monitor/goal_activity
  go_to_goal/activity/arrived monitor/arrived
  follow_wall/activity monitor/wall_activity
  avoid/activity monitor/avoid_activity
  avoid/activity/emergency monitor/emergency
  fusion/linear monitor/linear
  fusion/angular monitor/angular`);

/** What is wrong with drawing `L`: boxes overlapping, labels overlapping a box or each
 * other or missing, edges not joining their boxes or passing through another, parts
 * overlapping. */
export function problems(L) {
  const found = [], boxes = L.boxes;
  boxes.forEach((a, i) => {
    for (const b of boxes.slice(i + 1)) if (overlaps(a, b, 4)) found.push(`${a.path} and ${b.path} overlap`);
  });
  L.labels.forEach((l, i) => {
    for (const b of boxes) if (overlaps(l, b)) found.push(`label ${l.text} (${l.edge}) overlaps ${b.path}`);
    for (const k of L.labels.slice(i + 1)) if (overlaps(l, k)) found.push(`labels ${l.text} and ${k.text} overlap`);
  });
  const unlabelled = L.edges.filter((e) => e.label && e.unlabelled);
  if (unlabelled.length) found.push(`no room for the labels of ${unlabelled.map((e) => e.port)}`);
  const byPath = new Map(boxes.map((b) => [b.path, b]));
  const inside = (p, b) => p.x > b.x + 1 && p.x < b.x + b.w - 1 && p.y > b.y + 1 && p.y < b.y + b.h - 1;
  const on = (p, b) => p.x >= b.x - 0.5 && p.x <= b.x + b.w + 0.5 && p.y >= b.y - 0.5 && p.y <= b.y + b.h + 0.5;
  for (const e of L.edges) {
    const first = e.segs[0][0], last = e.segs[e.segs.length - 1][3];
    if (!on(first, byPath.get(e.from)) || !on(last, byPath.get(e.to))) found.push(`${e.from}/${e.port} → ${e.to} does not join its boxes`);
    const through = boxes.find((b) => b.path !== e.from && b.path !== e.to && samples(e.segs, 3).some((p) => inside(p, b)));
    if (through) found.push(`${e.from}/${e.port} → ${e.to}/${e.input} passes through ${through.path}`);
  }
  L.clusters.forEach((a, i) => {
    for (const c of L.clusters.slice(i + 1)) if (overlaps(a, c)) found.push(`parts ${a.part} and ${c.part} overlap`);
  });
  return found;
}

/** Lays out `modules` and fails on any problem; a summary line. */
export function check(name, modules) {
  const L = layout(modules);
  const found = problems(L);
  if (found.length) fail(`${name}: ${found.join('; ')}`);
  console.log(`ok: ${name}: ${L.boxes.length} boxes, ${L.edges.length} edges, ${L.labels.length} labels, ${L.crossings} crossings, ${Math.round(L.view.w)}×${Math.round(L.view.h)}`);
  return L;
}

/** The checks fire: the old drawing's faults, put back into a good layout, are found
 * (labels of parallel edges at one place, an edge through a box, overlapping boxes). */
function checksFire() {
  const L = layout(NAV);
  const linear = L.labels.find((l) => l.text === 'linear'), angular = L.labels.find((l) => l.text === 'angular');
  const fusion = L.boxes.find((b) => b.path.endsWith('/fusion')), monitor = L.boxes.find((b) => b.path.endsWith('/monitor'));
  const scan = L.edges.find((e) => e.port === 'scan');
  const mid = samples(scan.segs)[Math.floor(samples(scan.segs).length / 2)];
  const intruder = { path: 'robot/main/intruder', x: mid.x - 10, y: mid.y - 10, w: 20, h: 20 };
  const broken = { ...L, labels: L.labels.map((l) => (l === angular ? { ...l, x: linear.x + 4, y: linear.y } : l)),
    boxes: [...L.boxes.map((b) => (b === monitor ? { ...b, y: fusion.y + 10 } : b)), intruder] };
  const found = problems(broken).join('\n');
  for (const want of ['labels linear and angular overlap', 'fusion and robot/main/monitor overlap', '/scan passes through robot/main/intruder']) {
    if (!found.includes(want)) fail(`the check misses "${want}" in:\n${found}`);
  }
  console.log('ok: the checks find labels drawn over each other, overlapping boxes and an edge through a box');
}

/** Two parts, each reading an output of the other (links between programs). */
function twoParts() {
  const arm = tree(['source', 'filter:behaviour', 'ctl'], 'source/value filter/input\nfilter/output ctl/x\nctl/cmd source/feedback', 'arm');
  const base = tree(['sensor', 'log', 'fuse'], 'sensor/value log/input\nsensor/value fuse/a\nfuse/out log/fused', 'base');
  const input = (mods, name, writer) => mods.find((m) => m.path.endsWith('/' + name)).ports
    .push({ name: 'remote', dir: 'in', type: 'f64', meta: false, from: [writer] });
  input(base, 'log', 'arm/main/filter/output');
  input(arm, 'ctl', 'base/main/fuse/out');
  return [...arm, ...base];
}

/** A generated graph: `n` modules in a rough pipeline with feedback, seeded. */
export function generated(n, seed) {
  let s = seed;
  const rnd = () => ((s = (s * 1103515245 + 12345) % 2147483648) / 2147483648);
  const names = Array.from({ length: n }, (_, i) => `m${i}` + (i % 5 === 2 ? ':behaviour' : ''));
  const lines = [];
  for (let i = 1; i < n; i++) {
    for (let k = 0; k < 1 + Math.floor(rnd() * 3); k++) {
      const j = Math.floor(rnd() * i);
      lines.push(`m${j}/out${k} m${i}/in${k}_${j}`);
    }
    if (rnd() < 0.1) lines.push(`m${i}/back m${Math.floor(rnd() * i)}/fb${i}`);
  }
  return tree(names, lines.join('\n'));
}

/** Every graph above, checked. */
function main() {
  checksFire();
  check('nav_behaviours', NAV);
  check('mutual inhibition and a self-loop', tree(['a:behaviour', 'b:behaviour', 'c'], `
    a/activity b/inhibition/0
    b/activity a/inhibition/0
    c/out c/in
    a/value c/in2`));
  check('two parts linked both ways', twoParts());
  const started = Date.now();
  check('60 generated modules', generated(60, 7));
  console.log(`ok: 60 modules laid out in ${Date.now() - started} ms`);
}

if (import.meta.url === pathToFileURL(process.argv[1]).href) main();
