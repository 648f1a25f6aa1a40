"""A ROS 2 peer for a team's own message package, from clients we did not write: Python
`eclipse-zenoh` for the session and `rosbags` for the messages, with the team's `.msg`
files registered in its type store (`get_types_from_msg`), so its RIHS01 hash and CDR
are its own.

Usage: ros2_team.py ENDPOINT PACKAGE_FOLDER SECONDS

Registers every PACKAGE_FOLDER/msg/*.msg as `<package>/msg/<Name>` (the package is the
folder's name), subscribes to every key of `/drive` and deserialises each sample as
`robot_msgs/msg/Drive`, and publishes a Drive (two wheels, mode 0) on the key of
`/drive_in` built from its own hash, with rmw_zenoh's attachment, until one sample
arrived (or SECONDS pass). Prints one JSON object: its hash, the samples.
"""

import json
import pathlib
import struct
import sys
import time

import zenoh
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

endpoint, folder, seconds = sys.argv[1], pathlib.Path(sys.argv[2]), float(sys.argv[3])
store = get_typestore(Stores.ROS2_JAZZY)
types = {}
for path in sorted((folder / 'msg').glob('*.msg')):
    types.update(get_types_from_msg(path.read_text(), f'{folder.name}/msg/{path.stem}'))
store.register(types)
DRIVE = 'robot_msgs/msg/Drive'
drive_hash = store.hash_rihs01(DRIVE)
Drive = store.types[DRIVE]
Wheel = store.types['robot_msgs/msg/Wheel']
Vector3 = store.types['geometry_msgs/msg/Vector3']

conf = zenoh.Config()
conf.insert_json5('mode', '"peer"')
conf.insert_json5('connect/endpoints', json.dumps([endpoint]))
conf.insert_json5('scouting/multicast/enabled', 'false')
session = zenoh.open(conf)
samples = []


def on_sample(sample):
    msg = store.deserialize_cdr(sample.payload.to_bytes(), DRIVE)
    samples.append({
        'key': str(sample.key_expr),
        'wheels': [[w.speed, w.torque] for w in msg.wheels],
        'direction': [msg.direction.x, msg.direction.y, msg.direction.z],
        'mode': msg.mode,
    })


subscriber = session.declare_subscriber('0/drive/**', on_sample)
publisher = session.declare_publisher(f'0/drive_in/robot_msgs::msg::dds_::Drive_/{drive_hash}')
cdr = bytes(store.serialize_cdr(
    Drive(wheels=[Wheel(speed=0.25, torque=1.0), Wheel(speed=-0.25, torque=2.0)],
          direction=Vector3(x=0.0, y=1.0, z=0.0), mode=0),
    DRIVE, little_endian=True))
deadline = time.time() + seconds
sent = 0
while time.time() < deadline and (not samples or sent < 10):
    sent += 1
    publisher.put(cdr, attachment=struct.pack('<qq', sent, time.time_ns()) + bytes([16]) + bytes(16))
    time.sleep(0.1)
print(json.dumps({'hash': drive_hash, 'samples': samples[:3], 'sent': sent}))
subscriber.undeclare()
publisher.undeclare()
session.close()
