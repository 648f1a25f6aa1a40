"""The independent side of tests/ros2_record.rs: Python `mcap` (Foxglove's reader) reads
a recording ferroc wrote, and Python `rosbags` decodes every message of its ROS 2
channels (message encoding `cdr`, schema encoding `ros2msg`) with a type store built
only from the schema text in the file. Prints one JSON object: every channel (topic,
encodings, schema name, metadata), the decoded ROS 2 messages by topic, and the values
of the JSON display channels by topic, in file order. JSON has no NaN or infinity: a
decoded float that is not finite is printed as the string "nan", "inf" or "-inf"."""
import json
import math
import sys

import numpy
from mcap.reader import make_reader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore


def plain(value):
    if isinstance(value, numpy.ndarray):
        return [plain(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if hasattr(value, '__dataclass_fields__'):
        return {k: plain(getattr(value, k)) for k in value.__dataclass_fields__
                if k != '__msgtype__' and not k.isupper()}
    if isinstance(value, numpy.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return 'nan' if math.isnan(value) else ('inf' if value > 0 else '-inf')
    return value


def main():
    stores = {}
    channels = {}
    ros2 = {}
    shown = {}
    with open(sys.argv[1], 'rb') as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            channels[channel.id] = {
                'topic': channel.topic,
                'message_encoding': channel.message_encoding,
                'schema_name': schema.name if schema else '',
                'schema_encoding': schema.encoding if schema else '',
                'metadata': dict(channel.metadata),
            }
            if channel.message_encoding == 'cdr' and schema.encoding == 'ros2msg':
                if schema.id not in stores:
                    store = get_typestore(Stores.EMPTY)
                    store.register(get_types_from_msg(schema.data.decode(), schema.name))
                    stores[schema.id] = store
                msg = stores[schema.id].deserialize_cdr(message.data, schema.name)
                ros2.setdefault(channel.topic, []).append(plain(msg))
            elif channel.message_encoding == 'json':
                shown.setdefault(channel.topic, []).append(json.loads(message.data))
    json.dump({'channels': list(channels.values()), 'ros2': ros2, 'json': shown}, sys.stdout)


main()
