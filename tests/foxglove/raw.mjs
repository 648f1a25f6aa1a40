// A raw WebSocket client (the `ws` package, no Foxglove protocol) for
// tests/inspect_foxglove.rs: it asks for the upgrade the way a web page of another
// site would, and says what the server answered.
//
//   node raw.mjs URL [ORIGIN]
//
// Writes one JSON line: {"status": 403, "body": "..."} when the upgrade was refused,
// {"open": true, "protocol": "..."} when it was taken (then it closes), or
// {"error": "..."}.
import { createRequire } from "node:module";
import path from "node:path";

const require = createRequire(path.join(path.resolve(process.env.FERROC_NODE_MODULES), "resolve.js"));
const WebSocket = require("ws");

const [url, origin] = process.argv.slice(2);
const out = (o) => {
  process.stdout.write(JSON.stringify(o) + "\n");
  process.exit(0);
};
const options = origin ? { origin } : {};
const ws = new WebSocket(url, ["foxglove.sdk.v1"], options);
ws.on("open", () => {
  const protocol = ws.protocol;
  ws.close();
  out({ open: true, protocol });
});
ws.on("unexpected-response", (_req, res) => {
  let body = "";
  res.on("data", (d) => (body += d));
  res.on("end", () => out({ status: res.statusCode, body }));
});
ws.on("error", (e) => out({ error: String(e?.message ?? e) }));
