// Drives the inspector's page for the two part programs of tests/inspect_transport.rs
// (which passes the page's address in FERROC_PAGE_URL) in Debian's headless Chromium
// with playwright-core: the panel "Links to other parts" says the image link travels
// by shared memory, the number's link by network, and shows the pool's use; with
// FERROC_READER_GONE=1 (the viewer killed) the pool's row also says what came back from
// readers that are gone. Every wait is bounded and waits for a condition. Each passed check prints one `ok:` line the
// Rust test looks for; any failure exits 1.

import { createRequire } from 'node:module';
import { join } from 'node:path';

const env = (name) => {
  const v = process.env[name];
  if (!v) { console.error(`${name} is not set (tests/inspect_transport.rs sets it)`); process.exit(2); }
  return v;
};
const require = createRequire(join(env('FERROC_NODE_MODULES'), 'resolve.js'));
const { chromium } = require('playwright-core');

const WAIT = 60_000;
const pass = (text) => console.log('ok: ' + text);
const args = ['--disable-gpu', '--disable-dev-shm-usage', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync'];
if (process.getuid && process.getuid() === 0) args.push('--no-sandbox');
const browser = await chromium.launch({ executablePath: env('FERROC_CHROMIUM'), headless: true, args });
const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
const problems = [];
page.on('pageerror', (e) => problems.push('page error: ' + e.message));

async function run() {
  await page.goto(env('FERROC_PAGE_URL'));
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('live'), null, { timeout: WAIT });
  for (const [output, by, counted] of [['camera/main/frame/out/0', 'shared memory', 'shm'], ['camera/main/rate/value', 'network', 'net']]) {
    const row = `#transport tr[data-link-out="${output}"]`;
    // Shown once values went: the count of the way it travels is above zero.
    await page.waitForFunction((sel) => Number(document.querySelector(sel)?.textContent) > 0, `${row} .${counted}`, { timeout: WAIT });
    const shown = await page.textContent(`${row} .by`);
    if (shown !== by) throw new Error(`${output} travels by ${shown}, wanted ${by}`);
    const to = await page.getAttribute(row, 'data-to');
    pass(`${output} → ${to}: ${shown} (${await page.textContent(`${row} .${counted}`)} values)`);
  }
  const pool = '#transport tr[data-pool="camera"]';
  if (process.env.FERROC_READER_GONE === '1') {
    await page.waitForFunction((sel) => (document.querySelector(sel)?.textContent || '').includes('of readers that are gone'), pool, { timeout: WAIT });
  } else {
    await page.waitForFunction((sel) => Number(document.querySelector(sel)?.dataset.used) > 0, pool, { timeout: WAIT });
  }
  pass('pool of camera: ' + await page.textContent(pool));
  if (problems.length) throw new Error(problems.join('\n'));
}

try {
  await run();
  await browser.close();
} catch (e) {
  console.log('FAILED: ' + e.message);
  await browser.close();
  process.exit(1);
}
