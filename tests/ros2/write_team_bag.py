"""A recording ferroc did not write, with a team's own message types, for
tests/ros2_record.rs: Python `rosbags` (PyPI) registers team_msgs/msg/Motion (a nested
team_msgs/msg/Velocity and a geometry_msgs/msg/Vector3) from .msg text and writes a
rosbag2 bag with MCAP storage holding four Motion messages on /motion, 40 ms apart,
with the schema text rosbags generates and its CDR. Prints the messages as JSON."""
import json
import sys

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

store = get_typestore(Stores.ROS2_JAZZY)
types = {}
types.update(get_types_from_msg('float64 x\nfloat64 y\nfloat64 z\n', 'team_msgs/msg/Velocity'))
types.update(get_types_from_msg(
    '# what the base is told\nteam_msgs/Velocity linear\ngeometry_msgs/Vector3 angular\n',
    'team_msgs/msg/Motion'))
store.register(types)
Motion = store.types['team_msgs/msg/Motion']
Velocity = store.types['team_msgs/msg/Velocity']
Vector3 = store.types['geometry_msgs/msg/Vector3']
sent = []
with Writer(sys.argv[1], version=9, storage_plugin=StoragePlugin.MCAP) as writer:
    conn = writer.add_connection('/motion', 'team_msgs/msg/Motion', typestore=store)
    for k in range(4):
        linear = {'x': 0.5 * (k + 1), 'y': -0.125 * k, 'z': 0.0}
        angular = {'x': 0.0, 'y': 0.0, 'z': 0.75 * k}
        msg = Motion(linear=Velocity(**linear), angular=Vector3(**angular))
        writer.write(conn, 40_000_000 * k, store.serialize_cdr(msg, 'team_msgs/msg/Motion'))
        sent.append({'linear': linear, 'angular': angular})
json.dump(sent, sys.stdout)
