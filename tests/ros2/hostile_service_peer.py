"""A hostile foreign ROS 2 client of the service `ferroc run tests/ros2/switch.xml`
offers (/switch_bot/set_enabled, std_srvs/srv/SetBool), made with Python
`eclipse-zenoh` alone.

Usage: hostile_service_peer.py LISTEN SECONDS

Listens on LISTEN (the run connects to it; multicast scouting off), finds the
service's key in its liveliness token (`SS`), then sends at once BURST good requests
(rmw_zenoh's attachment, the request's CDR) and BAD malformed ones (no attachment; a
CDR header of 00 00; a bool of 7), collects every reply, and afterwards sends one good
request more. Prints one JSON object: how many replies of each kind each group got
(`ok`; `refused`: 64 requests already wait; `busy`: the module's request queue is
full; other errors; none), the error texts seen, and the last request's reply.
"""

import json
import struct
import sys
import time

import zenoh

BURST, BAD = 1000, 60
listen, seconds = sys.argv[1], float(sys.argv[2])

conf = zenoh.Config()
conf.insert_json5('mode', '"peer"')
conf.insert_json5('listen/endpoints', json.dumps([listen]))
conf.insert_json5('scouting/multicast/enabled', 'false')
session = zenoh.open(conf)

deadline = time.time() + seconds
key = None
while key is None and time.time() < deadline:
    for reply in session.liveliness().get('@ros2_lv/0/**', timeout=1.0):
        token = str(reply.ok.key_expr) if reply.ok is not None else ''
        parts = token.split('/')
        if '/SS/' in token and '%switch_bot%set_enabled' in token:
            # .../SS/<enclave>/<namespace>/<node>/<service>/<type>/<hash>/<qos>
            i = parts.index('SS')
            service, ty, hash_ = parts[i + 4], parts[i + 5], parts[i + 6]
            key = f"0/{service.strip('%').replace('%', '/')}/{ty}/{hash_}"
    time.sleep(0.2)
if key is None:
    print(json.dumps({'error': 'no service token'}))
    sys.exit(0)

gid = bytes(range(16))
sequence = 0


def attachment():
    global sequence
    sequence += 1
    return struct.pack('<qq', sequence, time.time_ns()) + bytes([16]) + gid


HEADER = bytes([0, 1, 0, 0])
good = HEADER + bytes([1])
bad = [(good, None), (bytes([0, 0, 0, 0, 1]), 'a'), (HEADER + bytes([7]), 'a')]

pending = []
for _ in range(BURST):
    pending.append(('good', session.get(key, payload=good, attachment=attachment(),
                                        timeout=20.0)))
for n in range(BAD):
    payload, with_attachment = bad[n % len(bad)]
    extra = {'attachment': attachment()} if with_attachment else {}
    pending.append(('bad', session.get(key, payload=payload, timeout=20.0, **extra)))

counts = {g: {'ok': 0, 'refused': 0, 'busy': 0, 'error': 0, 'none': 0}
          for g in ('good', 'bad')}
errors = set()
for group, replies in pending:
    got = list(replies)
    if not got:
        counts[group]['none'] += 1
        continue
    reply = got[0]
    if reply.ok is not None:
        counts[group]['ok'] += 1
    else:
        text = reply.err.payload.to_string()
        errors.add(text)
        if 'already wait' in text:
            counts[group]['refused'] += 1
        elif 'queue is full' in text:
            counts[group]['busy'] += 1
        else:
            counts[group]['error'] += 1

last = None
for reply in session.get(key, payload=good, attachment=attachment(), timeout=20.0):
    if reply.ok is not None:
        last = reply.ok.payload.to_bytes().hex()
    else:
        last = 'error: ' + reply.err.payload.to_string()
print(json.dumps({'key': key, 'counts': counts, 'errors': sorted(errors), 'last': last}))
session.close()
