"""A recording ferroc did not write, for tests/ros2_record.rs: Python `rosbags` (PyPI)
writes a rosbag2 bag with MCAP storage holding five geometry_msgs/msg/Twist messages on
/cmd_vel, 40 ms apart, with its own schema text and CDR. Prints the messages as JSON."""
import json
import sys

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

store = get_typestore(Stores.ROS2_JAZZY)
Twist = store.types['geometry_msgs/msg/Twist']
Vector3 = store.types['geometry_msgs/msg/Vector3']
sent = []
with Writer(sys.argv[1], version=9, storage_plugin=StoragePlugin.MCAP) as writer:
    conn = writer.add_connection('/cmd_vel', 'geometry_msgs/msg/Twist', typestore=store)
    for k in range(5):
        linear = {'x': 0.125 * (k + 1), 'y': 0.0, 'z': 0.0}
        angular = {'x': 0.0, 'y': 0.0, 'z': -0.25 * k}
        msg = Twist(linear=Vector3(**linear), angular=Vector3(**angular))
        writer.write(conn, 40_000_000 * k, store.serialize_cdr(msg, 'geometry_msgs/msg/Twist'))
        sent.append({'linear': linear, 'angular': angular})
json.dump(sent, sys.stdout)
