// Drives the inspector's page for models/nav_behaviours.xml in Debian's headless
// Chromium with playwright-core (run by tests/inspect_web.rs, which starts the program
// and the web server and passes their addresses in FERROC_* variables). Every wait is
// bounded and waits for a condition, never for a duration. Each passed check prints
// one line the Rust test looks for; any failure exits 1 with a screenshot.

import { createRequire } from 'node:module';
import { join } from 'node:path';

const env = (name) => {
  const v = process.env[name];
  if (!v) { console.error(`${name} is not set (tests/inspect_web.rs sets it)`); process.exit(2); }
  return v;
};
const require = createRequire(join(env('FERROC_NODE_MODULES'), 'resolve.js'));
const { chromium } = require('playwright-core');

const url = env('FERROC_PAGE_URL'), token = env('FERROC_TOKEN'), shot = env('FERROC_SCREENSHOT');
const graphShot = shot.replace(/\.png$/, '') + '-graph.png';
const WAIT = 60_000;
const control = 'robot/control';
const modules = ['sim', 'goal', 'operator', 'go_to_goal', 'follow_wall', 'avoid', 'fusion', 'monitor'].map((m) => `${control}/${m}`);
const pass = (text) => console.log('ok: ' + text);

// No background networking: the test machine's network is closed, and Chromium's own
// update, sync and lookup traffic would only add refused connections to the run.
const args = ['--disable-gpu', '--disable-dev-shm-usage', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync'];
if (process.getuid && process.getuid() === 0) args.push('--no-sandbox');
const browser = await chromium.launch({ executablePath: env('FERROC_CHROMIUM'), headless: true, args });
// The size the issue was seen at: the graph must fit it without scrolling.
const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
const problems = [];
page.on('pageerror', (e) => problems.push('page error: ' + e.message));

async function run() {
  await page.goto(url);
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('live'), null, { timeout: WAIT });
  pass('status: ' + await page.textContent('#status'));

  // The graph: every module, the behaviours drawn the iB2C way.
  await page.waitForSelector('#graph g.module', { timeout: WAIT });
  const drawn = await page.$$eval('#graph g.module', (gs) => gs.map((g) => g.dataset.path));
  for (const m of modules) if (!drawn.includes(m)) throw new Error(`the graph lacks ${m}; it has ${drawn}`);
  const count = async (sel) => (await page.$$(sel)).length;
  const behaviours = await count('#graph g.module.behaviour');
  const [inhib, stim, meta] = [await count('#graph .edge.inhib'), await count('#graph .edge.stim'), await count('#graph .edge.meta')];
  // nav_behaviours: 4 inhibitions, 1 stimulation (operator → fusion), 6 meta edges into fusion channels.
  if (inhib !== 4 || stim !== 1 || meta !== 6 || behaviours < 4) {
    throw new Error(`graph edges: ${inhib} inhibition, ${stim} stimulation, ${meta} fusion meta, ${behaviours} behaviours`);
  }
  pass(`graph: ${drawn.length} modules, ${behaviours} behaviours, ${inhib} inhibition, ${stim} stimulation, ${meta} channel edges`);

  // Live values: some numeric port's shown value changes.
  await page.waitForSelector('td[data-number]', { timeout: WAIT });
  const numbers = () => page.$$eval('td[data-number]', (cs) => Object.fromEntries(cs.map((c) => [c.dataset.port, c.dataset.number])));
  const first = await numbers();
  const changed = await page.waitForFunction((before) => {
    for (const c of document.querySelectorAll('td[data-number]')) {
      if (c.dataset.port in before && before[c.dataset.port] !== c.dataset.number) return `${c.dataset.port}: ${before[c.dataset.port]} → ${c.dataset.number}`;
    }
    return false;
  }, first, { timeout: WAIT, polling: 100 });
  pass('a numeric port changed: ' + await changed.jsonValue());
  const cycles = await page.textContent('tr[data-container="robot/control"] .cycles');
  if (!(Number(cycles) > 0)) throw new Error('no cycles shown: ' + cycles);
  pass('container robot/control: ' + cycles + ' cycles');

  await checkDrawing();
  await checkValues();
  // No part of nav_behaviours is a ROS 2 node: no port says it is a topic.
  const ros2 = await count('.ros2');
  if (ros2) throw new Error(`${ros2} ports say they are ROS 2 topics`);
  pass('no ROS 2 lines: no port of nav_behaviours is a topic');
  await page.screenshot({ path: shot });
  await page.locator('#graph-box').screenshot({ path: graphShot });
  pass(`screenshots ${shot} (the window at 1400×900) and ${graphShot}`);

  // The operator's constant activity: 1 until its value parameter changes.
  const activity = `td[data-port="${control}/operator/activity"]`;
  await page.waitForFunction((sel) => document.querySelector(sel)?.dataset.number === '1', activity, { timeout: WAIT });
  const row = `tr[data-param="${control}/operator/value"]`;
  const typeShown = await page.textContent(row);
  if (!typeShown.includes('Activity')) throw new Error('the parameter\'s type is not shown: ' + typeShown);

  // A wrong token: refused, the program's words shown, nothing changes.
  await page.fill('#token', '0'.repeat(32));
  await page.fill(`${row} .param-input`, '0.25');
  await page.click(`${row} .param-set`);
  await page.waitForFunction((sel) => document.querySelector(sel).className.includes('msg-bad'), `${row} .param-msg`, { timeout: WAIT });
  const refusal = await page.textContent(`${row} .param-msg`);
  if (!refusal.includes('not authorised')) throw new Error('the refusal does not say why: ' + refusal);
  pass('wrong token refused: ' + refusal);
  if (await page.getAttribute(activity, 'data-number') !== '1') throw new Error('a refused change changed the activity');

  // The right token: applied, and the next values show it.
  await page.fill('#token', token);
  await page.click(`${row} .param-set`);
  await page.waitForFunction((sel) => document.querySelector(sel).className.includes('msg-ok'), `${row} .param-msg`, { timeout: WAIT });
  pass('change accepted: ' + await page.textContent(`${row} .param-msg`));
  await page.waitForFunction((sel) => document.querySelector(sel)?.dataset.number === '0.25', activity, { timeout: WAIT });
  // The fusion's stimulation input shows its writer's value too.
  await page.waitForFunction((sel) => document.querySelector(sel)?.dataset.number === '0.25',
    `td[data-port="${control}/fusion/stimulation"]`, { timeout: WAIT });
  pass('operator/activity became 0.25 (and fusion/stimulation with it)');

  // A structural change goes to the program, which answers (the answer is shown).
  await page.click('#edit-send');
  await page.waitForFunction(() => { const t = document.getElementById('edit-answer').textContent; return t && t !== 'checking…'; }, null, { timeout: WAIT });
  // The page's own example (setting a parameter to the value it has) is applied.
  const answer = (await page.textContent('#edit-answer')).replace(/\s+/g, ' ').slice(0, 200);
  if (await page.getAttribute('#edit-answer', 'class') !== 'answer') throw new Error(`the example edit ${await page.inputValue('#edit-text')} was refused: ${answer}`);
  pass('edit answered: ' + answer);


  // The program goes away: the page says so and keeps retrying.
  process.kill(Number(env('FERROC_PROGRAM_PID')), 'SIGKILL');
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('cannot reach'), null, { timeout: WAIT });
  pass('unreachable shown: ' + await page.textContent('#status'));
  if (problems.length) throw new Error(problems.join('\n'));
}

/** Rectangles intersect (touching is not intersecting). */
const meet = (a, b) => a.x < b.x + b.w && b.x < a.x + a.w && a.y < b.y + b.h && b.y < a.y + a.h;

/** The drawing's geometry as the browser lays it out: it fits the window, no two edge
 * labels (nor a label and a box) intersect, every data port has its label, the
 * legend says what each mark means, and each behaviour's bars say what they show. */
async function checkDrawing() {
  await page.evaluate(() => window.scrollTo(0, 0));
  // Activities arrive with the first status: then the bars' values are drawn.
  await page.waitForFunction(() => [...document.querySelectorAll('#graph g.behaviour .meters title')]
    .every((t) => /activity a = \d/.test(t.textContent) && /target rating r = \d/.test(t.textContent)), null, { timeout: WAIT });
  const g = await page.evaluate(() => {
    const rect = (e) => { const b = e.getBoundingClientRect(); return { x: b.x, y: b.y, w: b.width, h: b.height }; };
    const svg = document.getElementById('graph');
    return {
      svg: rect(svg), width: window.innerWidth, height: window.innerHeight, scale: svg.dataset.scale,
      labels: [...svg.querySelectorAll('.edge-label')].map((t) => ({ ...rect(t), text: t.textContent, edge: t.dataset.edge })),
      boxes: [...svg.querySelectorAll('g.module rect.box')].map((r) => ({ ...rect(r), path: r.parentNode.dataset.path })),
      ports: [...new Set([...svg.querySelectorAll('.edge.data')].map((p) => p.dataset.edge))],
      legend: [...document.querySelectorAll('#legend .key[data-key]')].filter((k) => k.querySelector('svg')).map((k) => k.dataset.key),
      bars: [...svg.querySelectorAll('g.behaviour')].map((b) => [b.dataset.path, b.querySelectorAll('.bar.activity').length,
        b.querySelectorAll('.bar.rating').length, [...b.querySelectorAll('.meter-name')].map((t) => t.textContent).join('')]),
    };
  });
  const s = g.svg;
  if (s.x < 0 || s.y < 0 || s.x + s.w > g.width || s.y + s.h > g.height) {
    throw new Error(`the graph (${JSON.stringify(s)}) does not fit the ${g.width}×${g.height} window`);
  }
  pass(`graph fits the window: ${Math.round(s.w)}×${Math.round(s.h)} at (${Math.round(s.x)}, ${Math.round(s.y)}), scale ${g.scale}`);
  g.labels.forEach((a, i) => {
    for (const b of g.labels.slice(i + 1)) if (meet(a, b)) throw new Error(`edge labels ${a.text} (${a.edge}) and ${b.text} (${b.edge}) intersect`);
    for (const b of g.boxes) if (meet(a, b)) throw new Error(`edge label ${a.text} (${a.edge}) covers ${b.path}`);
  });
  const labelled = new Set(g.labels.map((l) => l.edge));
  const bare = g.ports.filter((p) => !labelled.has(p));
  if (bare.length || g.labels.length < 10) throw new Error(`data ports without a label: ${bare}; ${g.labels.length} labels`);
  for (const word of ['linear', 'angular']) {
    if (g.labels.filter((l) => l.text === word).length < 4) throw new Error(`fewer than 4 "${word}" labels: ${g.labels.map((l) => l.text)}`);
  }
  pass(`edge labels apart: ${g.labels.length} labels, none intersecting another or a box`);
  const keys = ['stimulation', 'inhibition', 'meta', 'data', 'back', 'part', 'behaviour'];
  const missing = keys.filter((k) => !g.legend.includes(k));
  if (missing.length) throw new Error('the legend lacks ' + missing.join(', '));
  const legend = await page.textContent('#legend');
  if (!/activity a/.test(legend) || !/target rating r/.test(legend)) throw new Error('the legend does not say what the bars show: ' + legend);
  pass('legend: ' + g.legend.join(', '));
  for (const [path, a, r, names] of g.bars) {
    if (a !== 1 || r !== 1 || names !== 'ar') throw new Error(`${path}: bars ${a} activity, ${r} rating, named ${names}`);
  }
  pass(`behaviour bars labelled a (activity) and r (target rating) in ${g.bars.length} behaviours`);
  // Actual size is the drawing's own size; fitted again, it fits.
  await page.click('#graph-zoom');
  const actual = await page.$eval('#graph', (svg) => [parseFloat(svg.style.width), Number(svg.dataset.width)]);
  if (Math.abs(actual[0] - actual[1]) > 1) throw new Error('actual size is not the drawing\'s size: ' + actual);
  await page.click('#graph-zoom');
  const again = await page.$eval('#graph', (svg) => svg.getBoundingClientRect().bottom);
  if (again > g.height) throw new Error('fitted again, the graph ends at ' + again);
  pass('zoom: actual size and back to fitted');
}

/** The fractions in `text` with more than 4 significant digits (more only where the
 * integer part has them). */
const longNumbers = (text) => (text.match(/-?\d+\.\d+(?:e[-+]?\d+)?/gi) || []).filter((t) => {
  const x = Number(t), whole = Math.floor(Math.log10(Math.abs(x))) + 1;
  return Number(x.toPrecision(Math.max(4, whole))) !== x;
});

/** Every shown value is short JSON (a number with its unit, or JSON text with at most
 * 4 significant digits in a fraction); the pose is an object of numbers. */
async function checkValues() {
  const pose = `td[data-port="${control}/sim/pose"]`;
  await page.waitForFunction((sel) => document.querySelector(sel)?.textContent.startsWith('{'), pose, { timeout: WAIT });
  const cells = await page.$$eval('td.value[data-shows]', (cs) => cs.filter((c) => c.textContent !== '…' && !c.classList.contains('msg-bad'))
    .map((c) => ({ port: c.dataset.port, text: c.textContent, number: c.dataset.number ?? null })));
  for (const c of cells) {
    const json = c.number === null ? c.text : c.text.split(' ')[0];
    try { JSON.parse(json); } catch { throw new Error(`${c.port} shows ${c.text}, not JSON`); }
    if (longNumbers(json).length) throw new Error(`${c.port} shows long numbers: ${c.text}`);
  }
  const shown = JSON.parse(await page.textContent(pose));
  const numbers = Object.values(shown).filter((x) => typeof x === 'number');
  if (!numbers.length) throw new Error('the pose is not an object of numbers: ' + JSON.stringify(shown));
  pass(`values as short JSON: ${cells.length} cells; pose ${JSON.stringify(shown)}`);
}

try {
  await run();
  await browser.close();
} catch (e) {
  console.log('FAILED: ' + e.message);
  await page.screenshot({ path: shot.replace(/\.png$/, '') + '-failed.png', fullPage: true }).catch(() => {});
  await browser.close();
  process.exit(1);
}
