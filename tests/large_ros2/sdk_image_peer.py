"""The ROS 2 side of tests/large_ros2.rs, written with `zenoh-ros2-sdk` (PyPI: a
pure-Python rmw_zenoh node we did not write; its CDR is `rosbags`'): a viewer of
`ferroc run tests/large_ros2/camera.xml`.

Usage: sdk_image_peer.py PORT INTERFACES SECONDS

Connects to the run at tcp/127.0.0.1:PORT; its message definitions come from INTERFACES
(the `.msg` files ferroc ships, given explicitly: the SDK cannot download them here).
Lists the topics with their types, subscribes to /image (sensor_msgs/msg/Image) and
/points (sensor_msgs/msg/PointCloud2), and once an image arrived publishes a 2 × 2 mono8
Image on /image_in every 100 ms for 3 s, each followed by a big-endian mono16 one (which
ferroc must refuse). Prints one JSON object: the topics, the first
three images and clouds received (every field, data as a list of bytes).
"""

import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '../ros2'))
from sdk_start import start, wait_for_topics  # noqa: E402

sdk, where, deadline = start()

topics = wait_for_topics(where, deadline, {'/image', '/points', '/image_in'})


def header(h):
    return {'sec': int(h.stamp.sec), 'nanosec': int(h.stamp.nanosec), 'frame_id': h.frame_id}


lock = threading.Lock()
images, clouds = [], []


def on_image(m):
    with lock:
        if len(images) < 3:
            images.append({'header': header(m.header), 'height': int(m.height),
                           'width': int(m.width), 'encoding': m.encoding,
                           'is_bigendian': int(m.is_bigendian), 'step': int(m.step),
                           'data': [int(b) for b in m.data]})


def on_cloud(m):
    with lock:
        if len(clouds) < 3:
            clouds.append({'header': header(m.header), 'height': int(m.height),
                           'width': int(m.width),
                           'fields': [[f.name, int(f.offset), int(f.datatype), int(f.count)]
                                      for f in m.fields],
                           'is_bigendian': bool(m.is_bigendian),
                           'point_step': int(m.point_step), 'row_step': int(m.row_step),
                           'data': [int(b) for b in m.data], 'is_dense': bool(m.is_dense)})


subscribers = [
    sdk.ROS2Subscriber(topic='/image', msg_type='sensor_msgs/msg/Image', callback=on_image,
                       **where),
    sdk.ROS2Subscriber(topic='/points', msg_type='sensor_msgs/msg/PointCloud2',
                       callback=on_cloud, **where),
]
publisher = sdk.ROS2Publisher(topic='/image_in', msg_type='sensor_msgs/msg/Image', **where)
Header = sdk.get_message_class('std_msgs/msg/Header')
Time = sdk.get_message_class('builtin_interfaces/msg/Time')
import numpy  # noqa: E402  (rosbags' byte arrays)

started = None
while time.time() < deadline:
    with lock:
        seen = len(images)
    if seen and started is None:
        started = time.time()
    if started is not None:
        publisher.publish(header=Header(stamp=Time(sec=7, nanosec=8), frame_id='viewer'),
                          height=2, width=2, encoding='mono8', is_bigendian=0, step=2,
                          data=numpy.array([11, 22, 33, 44], dtype=numpy.uint8))
        # An image ferroc_std.Image cannot represent: 16-bit, big endian (refused).
        publisher.publish(header=Header(stamp=Time(sec=7, nanosec=8), frame_id='viewer'),
                          height=1, width=2, encoding='mono16', is_bigendian=1, step=4,
                          data=numpy.array([0, 1, 0, 2], dtype=numpy.uint8))
        if time.time() > started + 3 and len(clouds) >= 3 and seen >= 3:
            break
    time.sleep(0.1)
with lock:
    print(json.dumps({'topics': [[name, types] for name, types in topics],
                      'images': images, 'clouds': clouds}))
for s in subscribers:
    s.close()
publisher.close()
sys.stdout.flush()
