"""A Zenoh router standing in for ROS 2's `rmw_zenohd`, made with Python `eclipse-zenoh`
(a session in mode `router`, the same routing code rmw_zenohd runs), listening on
tcp/127.0.0.1:PORT only, multicast scouting off (as rmw_zenohd's default configuration
has it).

Usage: router.py PORT SECONDS

Prints `ready <zid>` once it listens, then routes until its standard input closes or
SECONDS pass.
"""

import sys
import threading

port, seconds = int(sys.argv[1]), float(sys.argv[2])

import zenoh  # noqa: E402

config = zenoh.Config()
config.insert_json5('mode', '"router"')
config.insert_json5('listen/endpoints', f'["tcp/127.0.0.1:{port}"]')
config.insert_json5('connect/endpoints', '[]')
config.insert_json5('scouting/multicast/enabled', 'false')
session = zenoh.open(config)
print('ready', session.info.zid(), flush=True)

closed = threading.Event()


def watch_stdin():
    sys.stdin.read()
    closed.set()


threading.Thread(target=watch_stdin, daemon=True).start()
closed.wait(seconds)
session.close()
