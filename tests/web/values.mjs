// How the inspector's page shows values (inspect/src/web/assets/panels.js), checked in
// Node (run by tests/inspect_web.rs): numbers as people write them, other values as
// short JSON that still parses. Prints one `ok:` line per check.

import { shortNumber, shortJson } from '../../inspect/src/web/assets/panels.js';

const fail = (text) => { console.log('FAILED: ' + text); process.exit(1); };
const same = (got, want, what) => {
  if (JSON.stringify(got) !== JSON.stringify(want)) fail(`${what}: ${JSON.stringify(got)}, wanted ${JSON.stringify(want)}`);
};

// Shortened: 4 significant digits in shortest form, more only for the integer part.
for (const [x, want] of [[0.7000000000000001, 0.7], [1.2345678901234567, 1.235], [-0.30000000000000004, -0.3],
  [12345.678, 12346], [0.000123456, 0.0001235], [-2.5e-7, -2.5e-7]]) same(shortNumber(x), want, `shortNumber(${x})`);
// Left alone: integers (counters) and numbers already short.
for (const x of [0, 1, 123456789, 0.25, -3.5, 1e21]) same(shortNumber(x), x, `shortNumber(${x})`);
console.log('ok: numbers shortened to 4 significant digits, integers and short numbers kept');

const pose = shortJson({ x: -2.9876543210987654, y: 0.7000000000000001, theta: 0.7 });
same(pose, '{"x": -2.988, "y": 0.7, "theta": 0.7}', 'a pose');
const scan = shortJson({ ranges: Array.from({ length: 20 }, (_, i) => i / 3), frame: 'laser' });
same(JSON.parse(scan), { ranges: [0, 0.3333, 0.6667, 1, 1.333, 1.667, 2, 2.333, '… 12 more'], frame: 'laser' }, 'a scan');
same(shortJson([1, 2, 3]), '[1, 2, 3]', 'a short array');
same(shortJson('Pose2D { x: 1.2345678901234567, y: 2.0 }'), '"Pose2D { x: 1.235, y: 2.0 }"', 'the text of a type without serde');
same(shortJson(null), 'null', 'null');
for (const v of [pose, scan]) JSON.parse(v);
console.log(`ok: short JSON: ${pose} and ${scan}`);
