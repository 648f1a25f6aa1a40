"""An independent ROS 2 peer on rmw_zenoh's wire, from clients we did not write: Python
`eclipse-zenoh` for the session and `rosbags` (its built-in ROS 2 Jazzy message
definitions, its own RIHS01 hashes and CDR) for the messages.

Usage: ros2_peer.py ENDPOINT SECONDS

Connects to ENDPOINT (multicast scouting off), lists the ROS 2 liveliness tokens of
domain 0 (`@ros2_lv/0/**`, as `ros2 node list` and `ros2 topic list` read them),
subscribes to every key of the topic `/cmd_vel` and deserialises each sample as a
`geometry_msgs/msg/Twist`, and publishes a Twist with linear.x = 0.75 on the key of
`/cmd_vel_in` built from its own type hash, with rmw_zenoh's 33-byte attachment. After
at most SECONDS prints one JSON object: tokens, samples, its hash.
"""

import json
import struct
import sys
import threading
import time

import zenoh
from rosbags.typesys import Stores, get_typestore

TWIST = 'geometry_msgs/msg/Twist'
endpoint, seconds = sys.argv[1], float(sys.argv[2])
store = get_typestore(Stores.ROS2_JAZZY)
Twist = store.types[TWIST]
Vector3 = store.types['geometry_msgs/msg/Vector3']
twist_hash = store.hash_rihs01(TWIST)

conf = zenoh.Config()
conf.insert_json5('mode', '"peer"')
conf.insert_json5('connect/endpoints', json.dumps([endpoint]))
conf.insert_json5('scouting/multicast/enabled', 'false')
session = zenoh.open(conf)

samples = []
lock = threading.Lock()


def on_sample(sample):
    msg = store.deserialize_cdr(sample.payload.to_bytes(), TWIST)
    attachment = sample.attachment.to_bytes().hex() if sample.attachment is not None else None
    with lock:
        samples.append({
            'key': str(sample.key_expr),
            'attachment': attachment,
            'linear': [msg.linear.x, msg.linear.y, msg.linear.z],
            'angular': [msg.angular.x, msg.angular.y, msg.angular.z],
        })


subscriber = session.declare_subscriber('0/cmd_vel/**', on_sample)
publisher = session.declare_publisher(f'0/cmd_vel_in/geometry_msgs::msg::dds_::Twist_/{twist_hash}')
cdr = bytes(store.serialize_cdr(
    Twist(linear=Vector3(x=0.75, y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=0.0)),
    TWIST, little_endian=True))
gid = bytes(range(16))
deadline = time.time() + seconds
tokens = set()
sent = 0
while time.time() < deadline:
    for reply in session.liveliness().get('@ros2_lv/0/**', timeout=1.0):
        if reply.ok is not None:
            tokens.add(str(reply.ok.key_expr))
    sent += 1
    publisher.put(cdr, attachment=struct.pack('<qq', sent, time.time_ns()) + bytes([16]) + gid)
    with lock:
        done = len(samples) >= 3 and any('%cmd_vel_in/' in t for t in tokens) and sent >= 10
    if done:
        break
    time.sleep(0.1)
with lock:
    print(json.dumps({'tokens': sorted(tokens), 'samples': samples, 'hash': twist_hash, 'sent': sent}))
subscriber.undeclare()
publisher.undeclare()
session.close()
