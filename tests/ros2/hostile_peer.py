"""A hostile foreign ROS 2 node beside `ferroc run models/ros2_crash_course.xml`, made
with Python `eclipse-zenoh` (session) and `rosbags` (its own hashes and CDR).

Usage: hostile_peer.py LISTEN SECONDS

Listens on LISTEN (the run connects to it; multicast scouting off) and subscribes to
`/cmd_vel`. Once the robot moves and the node's `/enable` subscription is announced,
floods `/enable` (std_msgs/msg/Bool) with 120,000 bad samples (or for FLOOD seconds at
most), as fast as Zenoh takes them (blocking congestion control, so every sample
reaches the run), with a mix of:
  - `bad_header`: rmw_zenoh's attachment, a CDR header of random bytes (not 00 01);
  - `no_attachment`: a good sample without an attachment;
  - `short_attachment`: an attachment of a random length other than 33;
  - `bad_bool`: a good header and attachment, a bool of random value 2..255;
  - `truncated`: the header only;
  - `valid_true`: good `data: true` samples (the robot stays enabled);
  - `other_hash`: a good `data: false` sample on the key of another type hash (a
    publisher with another definition of std_msgs/msg/Bool): it must not reach the
    part, whose robot keeps moving.
Then publishes a good `data: false` every 100 ms until the commands stay zero. Prints
one JSON object: what was sent of each kind, the flood's length, the /cmd_vel samples
(each with its phase: before, flood, after, disabled).
"""

import json
import os
import random
import struct
import sys
import threading
import time

import zenoh
from rosbags.typesys import Stores, get_typestore

FLOOD = 10.0
TWIST, BOOL = 'geometry_msgs/msg/Twist', 'std_msgs/msg/Bool'
listen, seconds = sys.argv[1], float(sys.argv[2])
store = get_typestore(Stores.ROS2_JAZZY)
bool_hash = store.hash_rihs01(BOOL)

conf = zenoh.Config()
conf.insert_json5('mode', '"peer"')
conf.insert_json5('listen/endpoints', json.dumps([listen]))
conf.insert_json5('scouting/multicast/enabled', 'false')
session = zenoh.open(conf)

lock = threading.Lock()
samples = []
phase = 'before'


def on_twist(sample):
    msg = store.deserialize_cdr(sample.payload.to_bytes(), TWIST)
    with lock:
        samples.append({'phase': phase,
                        'linear': [msg.linear.x, msg.linear.y, msg.linear.z],
                        'angular': [msg.angular.x, msg.angular.y, msg.angular.z]})


def moving(s):
    return any(v != 0.0 for v in s['linear'] + s['angular'])


subscriber = session.declare_subscriber('0/cmd_vel/**', on_twist)
block = zenoh.CongestionControl.BLOCK
key = f'0/enable/std_msgs::msg::dds_::Bool_/{bool_hash}'
publisher = session.declare_publisher(key, congestion_control=block)
other_hash = 'RIHS01_' + '5a' * 32
stray = session.declare_publisher(f'0/enable/std_msgs::msg::dds_::Bool_/{other_hash}',
                                  congestion_control=block)
Bool = store.types[BOOL]


def cdr(data):
    return bytes(store.serialize_cdr(Bool(data=data), BOOL, little_endian=True))


false, true = cdr(False), cdr(True)
gid = bytes(range(16))
sequence = 0


def attachment():
    global sequence
    sequence += 1
    return struct.pack('<qq', sequence, time.time_ns()) + bytes([16]) + gid


deadline = time.time() + seconds
# Wait for the robot to move and the node's /enable subscription to be there.
while time.time() < deadline:
    announced = any('%enable/' in str(r.ok.key_expr)
                    for r in session.liveliness().get('@ros2_lv/0/**', timeout=1.0)
                    if r.ok is not None)
    with lock:
        moved = any(moving(s) for s in samples)
    if announced and moved:
        break
    time.sleep(0.1)

rng = random.Random(29)
sent = {k: 0 for k in ('bad_header', 'no_attachment', 'short_attachment', 'bad_bool',
                       'truncated', 'valid_true', 'other_hash')}
with lock:
    phase = 'flood'
started = time.time()
# Until 120,000 bad samples went out (six per round), or FLOOD seconds at most.
while time.time() < started + FLOOD and sent['bad_header'] * 6 < 120_000:
    for _ in range(100):
        a, b = rng.choice([(0, 0), (0, 2), (1, 0), (0xff, 0xff), (rng.randrange(2, 256), 7)])
        publisher.put(bytes([a, b, 0, 0, 1]), attachment=attachment())
        publisher.put(true)
        n = rng.choice([0, 1, 20, 32, 34, rng.randrange(35, 200)])
        publisher.put(true, attachment=os.urandom(n))
        publisher.put(true[:4] + bytes([rng.randrange(2, 256)]), attachment=attachment())
        publisher.put(true[:4], attachment=attachment())
        publisher.put(true, attachment=attachment())
        stray.put(false, attachment=attachment())
        for k in sent:
            sent[k] += 1
flood_seconds = time.time() - started
with lock:
    phase = 'after'
time.sleep(1.0)

# The part still reads its input: a good `false` stops the robot.
disabled_at = None
while time.time() < deadline:
    with lock:
        after = [s for s in samples if s['phase'] == 'disabled']
    if len(after) >= 10:
        break
    publisher.put(false, attachment=attachment())
    if disabled_at is None:
        disabled_at = time.time()
    elif time.time() > disabled_at + 0.5:
        with lock:
            phase = 'disabled'
    time.sleep(0.1)

with lock:
    print(json.dumps({'sent': sent, 'flood_seconds': flood_seconds, 'samples': samples}))
subscriber.undeclare()
publisher.undeclare()
stray.undeclare()
session.close()
