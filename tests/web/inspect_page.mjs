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
const page = await browser.newPage({ viewport: { width: 1600, height: 1000 } });
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
  pass('edit answered: ' + (await page.textContent('#edit-answer')).slice(0, 200));

  await page.screenshot({ path: shot, fullPage: true });
  pass('screenshot ' + shot);

  // The program goes away: the page says so and keeps retrying.
  process.kill(Number(env('FERROC_PROGRAM_PID')), 'SIGKILL');
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('cannot reach'), null, { timeout: WAIT });
  pass('unreachable shown: ' + await page.textContent('#status'));
  if (problems.length) throw new Error(problems.join('\n'));
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
