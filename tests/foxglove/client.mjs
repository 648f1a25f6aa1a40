// A Foxglove WebSocket client we did not write (@foxglove/ws-protocol's FoxgloveClient
// over the `ws` package), driven line by line for tests/inspect_foxglove.rs.
//
//   node client.mjs ws://127.0.0.1:PORT
//
// Reads commands, one JSON object a line, on stdin:
//   {"op": "subscribe", "topics": [...]}
//   {"op": "getParameters", "names": [...], "id": "..."}
//   {"op": "setParameters", "parameters": [{"name": ..., "value": ...}], "id": "..."}
//   {"op": "close"}
// and writes what the server sends, one JSON object a line, on stdout:
//   {"ev": "serverInfo", ...} {"ev": "advertise", "channels": [...]}
//   {"ev": "message", "topic": ..., "data": <the message, parsed>}
//   {"ev": "parameterValues", "id": ..., "parameters": [...]}
//   {"ev": "status", "level": ..., "message": ...} {"ev": "error", ...} {"ev": "close"}
//
// The packages come from FERROC_NODE_MODULES (a node_modules folder).
import { createRequire } from "node:module";
import path from "node:path";
import readline from "node:readline";

const modules = process.env.FERROC_NODE_MODULES;
if (!modules) {
  console.error("FERROC_NODE_MODULES is not set");
  process.exit(2);
}
const require = createRequire(path.join(path.resolve(modules), "resolve.js"));
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");

const out = (event) => process.stdout.write(JSON.stringify(event) + "\n");
const url = process.argv[2];
// foxglove.sdk.v1 is the name the Foxglove SDK's server speaks the protocol under
// (the same protocol as foxglove.websocket.v1).
const client = new FoxgloveClient({
  ws: new WebSocket(url, ["foxglove.sdk.v1"]),
});
const channels = new Map(); // id -> channel
const byTopic = new Map(); // topic -> channel
const subscriptions = new Map(); // subscription id -> topic
const decoder = new TextDecoder();

client.on("open", () => out({ ev: "open" }));
client.on("error", (e) => out({ ev: "error", message: String(e?.message ?? e) }));
client.on("close", () => {
  out({ ev: "close" });
  process.exit(0);
});
client.on("serverInfo", (info) => out({ ev: "serverInfo", name: info.name, capabilities: info.capabilities }));
client.on("status", (s) => out({ ev: "status", level: s.level, message: s.message }));
client.on("advertise", (list) => {
  for (const c of list) {
    channels.set(c.id, c);
    byTopic.set(c.topic, c);
  }
  out({
    ev: "advertise",
    channels: list.map((c) => ({
      topic: c.topic,
      encoding: c.encoding,
      schemaName: c.schemaName,
      schemaEncoding: c.schemaEncoding,
      schema: c.schema,
    })),
  });
});
client.on("message", ({ subscriptionId, data }) => {
  const topic = subscriptions.get(subscriptionId);
  const text = decoder.decode(data);
  let parsed;
  try {
    parsed = JSON.parse(text);
  } catch (e) {
    out({ ev: "badMessage", topic, text });
    return;
  }
  out({ ev: "message", topic, data: parsed });
});
client.on("parameterValues", ({ id, parameters }) => out({ ev: "parameterValues", id, parameters }));

const lines = readline.createInterface({ input: process.stdin });
lines.on("line", (line) => {
  let cmd;
  try {
    cmd = JSON.parse(line);
  } catch {
    out({ ev: "error", message: `not a command: ${line}` });
    return;
  }
  switch (cmd.op) {
    case "subscribe":
      for (const topic of cmd.topics) {
        const channel = byTopic.get(topic);
        if (!channel) {
          out({ ev: "error", message: `no channel ${topic}` });
          continue;
        }
        subscriptions.set(client.subscribe(channel.id), topic);
      }
      out({ ev: "subscribed", topics: cmd.topics });
      break;
    case "getParameters":
      client.getParameters(cmd.names, cmd.id);
      break;
    case "setParameters":
      client.setParameters(cmd.parameters, cmd.id);
      break;
    case "close":
      client.close();
      break;
    default:
      out({ ev: "error", message: `unknown op ${cmd.op}` });
  }
});
lines.on("close", () => client.close());
