"""An independent inspection client (Python `eclipse-zenoh`) on ferroc's documented keys.

Usage: inspect_client.py ENDPOINT APP PART MODULE_PORT MODULE_PARAM

Connects to ENDPOINT with multicast scouting off and asks (docs/inspect.md) for the
part's tree, a port's value, a parameter, and a change of that parameter with a wrong
token. Prints one JSON object with what came back: each answer's key and JSON, or the
error reply's JSON.
"""

import json
import sys
import time

import zenoh

endpoint, app, part, port, param = sys.argv[1:6]
conf = zenoh.Config()
conf.insert_json5("mode", '"peer"')
conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
conf.insert_json5("scouting/multicast/enabled", "false")
session = zenoh.open(conf)
prefix = f"ferroc/{app}/inspect/{part}"


def ask(key, payload=None):
    # The server's queryable may take a moment to be declared to a new peer.
    for _ in range(25):
        answers = []
        for reply in session.get(key, payload=payload):
            if reply.ok is not None:
                answers.append({"key": str(reply.ok.key_expr), "ok": json.loads(reply.ok.payload.to_string())})
            else:
                answers.append({"err": json.loads(reply.err.payload.to_string())})
        if answers:
            return answers
        time.sleep(0.2)
    return []


result = {
    "tree": ask(f"{prefix}/tree"),
    "value": ask(f"{prefix}/value/{port}"),
    "param": ask(f"{prefix}/param/{param}"),
    "refused": ask(f"{prefix}/param/{param}", json.dumps({"set": "1.5", "token": "guess"})),
    "after": ask(f"{prefix}/param/{param}"),
}
print(json.dumps(result))
session.close()
