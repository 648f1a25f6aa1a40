"""An independent Zenoh client (Python `eclipse-zenoh`) on ferroc's documented keys.

Usage: subscribe.py ENDPOINT APP SECONDS

Connects to ENDPOINT (a part's `tcp/HOST:PORT`) with multicast scouting off, subscribes
to `ferroc/APP/data/**`, asks for the liveliness tokens `ferroc/APP/alive/*`, and after
SECONDS prints one JSON object: the samples (key, encoding, attachment and payload in
hex) and the tokens.
"""

import json
import sys
import threading
import time

import zenoh

endpoint, app, seconds = sys.argv[1], sys.argv[2], float(sys.argv[3])
conf = zenoh.Config()
conf.insert_json5("mode", '"peer"')
conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
conf.insert_json5("scouting/multicast/enabled", "false")
session = zenoh.open(conf)

samples = []
lock = threading.Lock()


def on_sample(sample):
    attachment = sample.attachment.to_bytes().hex() if sample.attachment is not None else None
    with lock:
        samples.append(
            {
                "key": str(sample.key_expr),
                "encoding": str(sample.encoding),
                "attachment": attachment,
                "payload": sample.payload.to_bytes().hex(),
            }
        )


subscriber = session.declare_subscriber(f"ferroc/{app}/data/**", on_sample)
deadline = time.time() + seconds
tokens = set()
while time.time() < deadline:
    for reply in session.liveliness().get(f"ferroc/{app}/alive/*", timeout=1.0):
        if reply.ok is not None:
            tokens.add(str(reply.ok.key_expr))
    with lock:
        if tokens and len(samples) >= 5:
            break
    time.sleep(0.1)
with lock:
    print(json.dumps({"samples": samples, "tokens": sorted(tokens)}))
subscriber.undeclare()
session.close()
