"""The independent side of tests/serde_cdr.rs's non-finite floats: Python `rosbags`
(PyPI), with its own ROS 2 Jazzy definitions, reads the LaserScan ferroc wrote (hex on
stdin) and prints its ranges as Python writes floats (`inf`, `nan`), and writes a
LaserScan of its own with +inf, -inf and NaN ranges as a ROS 2 publisher would. Writes a
JSON answer on stdout."""
import json
import sys

import numpy
from rosbags.typesys import Stores, get_typestore


def main():
    request = json.load(sys.stdin)
    store = get_typestore(Stores.ROS2_JAZZY)
    name = 'sensor_msgs/msg/LaserScan'
    ours = store.deserialize_cdr(bytes.fromhex(request['cdr']), name)
    Time = store.types['builtin_interfaces/msg/Time']
    Header = store.types['std_msgs/msg/Header']
    LaserScan = store.types[name]
    theirs = LaserScan(
        header=Header(stamp=Time(sec=12, nanosec=500), frame_id='their_laser'),
        angle_min=-1.0, angle_max=1.0, angle_increment=0.5, time_increment=0.0,
        scan_time=0.1, range_min=0.1, range_max=10.0,
        ranges=numpy.array([numpy.inf, -numpy.inf, numpy.nan, 2.5], dtype=numpy.float32),
        intensities=numpy.array([], dtype=numpy.float32),
    )
    json.dump({
        'ranges': [repr(float(r)) for r in ours.ranges],
        'frame_id': ours.header.frame_id,
        'stamp': [int(ours.header.stamp.sec), int(ours.header.stamp.nanosec)],
        'theirs': bytes(store.serialize_cdr(theirs, name, little_endian=True)).hex(),
    }, sys.stdout)


main()
