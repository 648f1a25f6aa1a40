"""A recording whose ROS 2 channel has an empty schema (what a tool writes when it finds
no definition of the type), for tests/ros2_record_topics.rs: Python `mcap` (Foxglove's
writer) writes /motion, schema `team_msgs/msg/Motion` of encoding ros2msg with no text,
four messages 40 ms apart, their CDR made by Python `rosbags` from the team's .msg files
(tests/ros2/team_msgs). Prints the messages as JSON. With a second argument `zstd`, the
chunks are compressed (Python mcap's default), which ferroc refuses to read."""
import json
import sys
from pathlib import Path

from mcap.writer import CompressionType, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

folder = Path(__file__).parent / 'team_msgs' / 'msg'
store = get_typestore(Stores.ROS2_JAZZY)
types = {}
for name in ('Velocity', 'Motion'):
    types.update(get_types_from_msg((folder / f'{name}.msg').read_text(), f'team_msgs/msg/{name}'))
store.register(types)
Motion = store.types['team_msgs/msg/Motion']
Velocity = store.types['team_msgs/msg/Velocity']
Vector3 = store.types['geometry_msgs/msg/Vector3']
sent = []
with open(sys.argv[1], 'wb') as f:
    # Uncompressed: ferroc reads no compressed chunks (its mcap crate is built without).
    zstd = sys.argv[2:] == ['zstd']
    writer = Writer(f, compression=CompressionType.ZSTD if zstd else CompressionType.NONE)
    writer.start(profile='ros2', library='write_schemaless_bag.py')
    schema = writer.register_schema(name='team_msgs/msg/Motion', encoding='ros2msg', data=b'')
    channel = writer.register_channel(topic='/motion', message_encoding='cdr', schema_id=schema)
    for k in range(4):
        linear = {'x': 0.25 * (k + 1), 'y': 0.5, 'z': 0.0}
        angular = {'x': 0.0, 'y': 0.0, 'z': -0.5 * k}
        msg = Motion(linear=Velocity(**linear), angular=Vector3(**angular))
        data = store.serialize_cdr(msg, 'team_msgs/msg/Motion')
        writer.add_message(channel, log_time=40_000_000 * k, data=data, publish_time=40_000_000 * k)
        sent.append({'linear': linear, 'angular': angular})
    writer.finish()
json.dump(sent, sys.stdout)
