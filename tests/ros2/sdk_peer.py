"""A ROS 2 node of `ferroc run models/ros2_crash_course.xml` written with
`zenoh-ros2-sdk` (PyPI), a pure-Python rmw_zenoh node we did not write: its own type
hashes, keys, liveliness tokens and attachment.

Usage: sdk_peer.py PORT INTERFACES SECONDS

Connects to the run at tcp/127.0.0.1:PORT (the SDK's "router"); its message
definitions come from INTERFACES (the `.msg` files ferroc ships, laid out as
PACKAGE/msg/NAME.msg), given explicitly: the SDK cannot download them here. Lists the
topics with their types as `ros2 topic list -t` does, subscribes to `/cmd_vel`
(geometry_msgs/msg/Twist), and once the robot moved publishes `std_msgs/msg/Bool`
`data: false` on `/enable` every 100 ms until the commands stay zero, or SECONDS pass.
Prints one JSON object: topics, samples (each with `after_disable`).
"""

import json
import sys
import threading
import time

from sdk_start import start, wait_for_topics  # noqa: E402

sdk, where, deadline = start()

topics = wait_for_topics(where, deadline, {'/cmd_vel', '/enable', '/ir_front'})

samples = []
lock = threading.Lock()
disabled_at = None


def on_twist(msg):
    with lock:
        samples.append({
            'linear': [msg.linear.x, msg.linear.y, msg.linear.z],
            'angular': [msg.angular.x, msg.angular.y, msg.angular.z],
            'after_disable': disabled_at is not None and time.time() > disabled_at + 0.5,
        })


def moving(s):
    return any(v != 0.0 for v in s['linear'] + s['angular'])


subscriber = sdk.ROS2Subscriber(topic='/cmd_vel', msg_type='geometry_msgs/msg/Twist',
                                callback=on_twist, **where)
publisher = sdk.ROS2Publisher(topic='/enable', msg_type='std_msgs/msg/Bool', **where)
while time.time() < deadline:
    with lock:
        moved = any(moving(s) for s in samples)
        after = [s for s in samples if s['after_disable']]
    if moved:
        if disabled_at is None:
            disabled_at = time.time()
        publisher.publish(data=False)
    if len(after) >= 10:
        break
    time.sleep(0.1)
with lock:
    print(json.dumps({'topics': [[name, types] for name, types in topics],
                      'samples': samples}))
subscriber.close()
publisher.close()
sys.stdout.flush()
