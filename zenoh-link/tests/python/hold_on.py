"""A reader that is not a ferroc part (Python `eclipse-zenoh`, no shared memory).

Usage: hold_on.py ENDPOINT APP

Connects to ENDPOINT (a part's `tcp/HOST:PORT`) with multicast scouting off,
subscribes to `ferroc/APP/data/**` and prints `sample SIZE` per sample it receives,
until its standard input closes. It cannot say which of a writer's shared-memory
buffers it holds (zenoh-link/src/shm/asking.rs), so a writer must keep what it sent
while it lives.
"""

import json
import sys

import zenoh

endpoint, app = sys.argv[1], sys.argv[2]
conf = zenoh.Config()
conf.insert_json5("mode", '"peer"')
conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
conf.insert_json5("scouting/multicast/enabled", "false")
session = zenoh.open(conf)


def on_sample(sample):
    print("sample", len(sample.payload.to_bytes()), flush=True)


subscriber = session.declare_subscriber(f"ferroc/{app}/data/**", on_sample)
sys.stdin.read()
subscriber.undeclare()
session.close()
