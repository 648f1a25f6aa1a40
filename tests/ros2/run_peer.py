"""A ROS 2 peer of `ferroc run models/ros2_crash_course.xml`, from clients we did not
write: Python `eclipse-zenoh` for the session and `rosbags` (its built-in ROS 2 Jazzy
definitions, its own RIHS01 hashes and CDR) for the messages.

Usage: run_peer.py LISTEN SECONDS

Listens on LISTEN (the run connects to it, as a node connects to rmw_zenohd; multicast
scouting off), lists the ROS 2 liveliness tokens of domain 0, and decodes every sample
of `/cmd_vel` as a `geometry_msgs/msg/Twist` and of `/ir_front` as a
`std_msgs/msg/Float64`. Once it has seen the robot move (a
non-zero command), it publishes `std_msgs/msg/Bool` `data: false` on `/enable`, on the
key built from its own hash with rmw_zenoh's attachment, every 100 ms, and waits for
the commands to stay zero. After that, or SECONDS, prints one JSON object: tokens,
samples (each with `after_disable`), the hashes.
"""

import json
import struct
import sys
import threading
import time

import zenoh
from rosbags.typesys import Stores, get_typestore

TWIST = 'geometry_msgs/msg/Twist'
BOOL = 'std_msgs/msg/Bool'
listen, seconds = sys.argv[1], float(sys.argv[2])
store = get_typestore(Stores.ROS2_JAZZY)
hashes = {t: store.hash_rihs01(t) for t in (TWIST, BOOL, 'std_msgs/msg/Float64')}

conf = zenoh.Config()
conf.insert_json5('mode', '"peer"')
conf.insert_json5('listen/endpoints', json.dumps([listen]))
conf.insert_json5('scouting/multicast/enabled', 'false')
session = zenoh.open(conf)

samples = []
lock = threading.Lock()
disabled_at = None


def on_sample(sample):
    msg = store.deserialize_cdr(sample.payload.to_bytes(), TWIST)
    attachment = sample.attachment.to_bytes().hex() if sample.attachment is not None else None
    with lock:
        samples.append({
            'key': str(sample.key_expr),
            'attachment': attachment,
            'linear': [msg.linear.x, msg.linear.y, msg.linear.z],
            'angular': [msg.angular.x, msg.angular.y, msg.angular.z],
            'after_disable': disabled_at is not None and time.time() > disabled_at + 0.5,
        })


ir_front = []


def on_ir(sample):
    msg = store.deserialize_cdr(sample.payload.to_bytes(), 'std_msgs/msg/Float64')
    with lock:
        ir_front.append({'key': str(sample.key_expr), 'data': msg.data})


subscriber = session.declare_subscriber('0/cmd_vel/**', on_sample)
ir_subscriber = session.declare_subscriber('0/ir_front/**', on_ir)
publisher = session.declare_publisher(f'0/enable/std_msgs::msg::dds_::Bool_/{hashes[BOOL]}')
Bool = store.types[BOOL]
cdr = bytes(store.serialize_cdr(Bool(data=False), BOOL, little_endian=True))
gid = bytes(range(16))
deadline = time.time() + seconds
tokens = set()
sent = 0


def moving(s):
    return any(v != 0.0 for v in s['linear'] + s['angular'])


while time.time() < deadline:
    for reply in session.liveliness().get('@ros2_lv/0/**', timeout=1.0):
        if reply.ok is not None:
            tokens.add(str(reply.ok.key_expr))
    with lock:
        moved = any(moving(s) for s in samples)
        after = [s for s in samples if s['after_disable']]
    if moved:
        if disabled_at is None:
            disabled_at = time.time()
        sent += 1
        publisher.put(cdr, attachment=struct.pack('<qq', sent, time.time_ns()) + bytes([16]) + gid)
    if len(after) >= 10 and any('%enable/' in t for t in tokens):
        break
    time.sleep(0.1)
with lock:
    print(json.dumps({'tokens': sorted(tokens), 'samples': samples, 'hashes': hashes,
                      'sent': sent, 'ir_front': ir_front}))
subscriber.undeclare()
ir_subscriber.undeclare()
publisher.undeclare()
session.close()
