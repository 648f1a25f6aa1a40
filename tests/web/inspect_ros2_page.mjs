// Drives the inspector's page for models/ros2_crash_course.xml (run inspected by
// tests/inspect_ros2.rs, which passes the page's address in FERROC_PAGE_URL) in
// Debian's headless Chromium with playwright-core: each port the part's ROS 2 node
// publishes or subscribes says so under its name (topic, type, QoS, node), and no
// other port does. Every wait is bounded and waits for a condition. Each passed check
// prints one `ok:` line the Rust test looks for; any failure exits 1.

import { createRequire } from 'node:module';
import { join } from 'node:path';

const env = (name) => {
  const v = process.env[name];
  if (!v) { console.error(`${name} is not set (tests/inspect_ros2.rs sets it)`); process.exit(2); }
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

/** The ROS 2 line under the port `module/port`, once the module's section is drawn. */
async function line(port, topic) {
  const module = port.slice(0, port.lastIndexOf('/'));
  const sel = `details[data-module="${module}"] td[data-port="${port}"]`;
  await page.waitForSelector(sel, { timeout: WAIT });
  // The line sits in the port's row, in the cell of its name.
  return page.$eval(sel, (cell, name) => {
    const found = cell.parentNode.querySelector(`.ros2[data-ros2="${name}"]`);
    return found ? found.textContent : null;
  }, topic);
}

async function run() {
  await page.goto(env('FERROC_PAGE_URL'));
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('live'), null, { timeout: WAIT });
  const want = [
    ['fragile_bot/main/control/twist_out/twist', '/cmd_vel', 'ROS 2 publish /cmd_vel (geometry_msgs/msg/Twist; reliable, volatile, depth 10)'],
    ['fragile_bot/main/simulation/add_noise_front/output', '/ir_front', 'ROS 2 publish /ir_front (std_msgs/msg/Float64.data; best-effort, volatile, depth 10)'],
    ['fragile_bot/main/control/controller/enable', '/enable', 'ROS 2 subscribe /enable (std_msgs/msg/Bool.data; reliable, volatile, depth 10)'],
  ];
  for (const [port, topic, text] of want) {
    const shown = await line(port, topic);
    if (shown !== text) throw new Error(`${port}: ${JSON.stringify(shown)}, wanted ${JSON.stringify(text)}`);
    pass(`${port}: ${shown}`);
  }
  const all = await page.$$eval('.ros2', (es) => es.map((e) => e.textContent));
  if (all.length !== want.length) throw new Error(`ROS 2 lines on other ports too: ${JSON.stringify(all)}`);
  const node = await page.getAttribute('.ros2[data-ros2="/cmd_vel"]', 'title');
  if (node !== 'ROS 2 node /fragile_bot, domain 0') throw new Error('the node is not named: ' + node);
  pass(`only the node's 3 ports say ROS 2; ${node}`);
  // The published Twist's value is live, as any port's.
  const twist = 'td[data-port="fragile_bot/main/control/twist_out/twist"]';
  await page.waitForFunction((sel) => document.querySelector(sel)?.textContent.includes('"linear"'), twist, { timeout: WAIT });
  pass('twist value: ' + await page.textContent(twist));
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
