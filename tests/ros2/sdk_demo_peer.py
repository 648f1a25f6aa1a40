"""A ROS 2 node beside `ferroc run models/ros2_demo.xml`, written with `zenoh-ros2-sdk`
(PyPI), a pure-Python rmw_zenoh node we did not write: its own type hashes, keys,
liveliness tokens and attachment, and `rosbags` (which the SDK uses) for the CDR.

Usage: sdk_demo_peer.py PORT INTERFACES SECONDS

Connects to the run at tcp/127.0.0.1:PORT (the SDK's "router"); its message
definitions come from INTERFACES (the `.msg` files ferroc ships, laid out as
PACKAGE/msg/NAME.msg), given explicitly: the SDK cannot download them here.

1. Lists the topics with their types as `ros2 topic list -t` does, and subscribes to
   `/cmd_vel` (geometry_msgs/msg/Twist), `/scan` (sensor_msgs/msg/LaserScan), `/odom`
   (nav_msgs/msg/Odometry) and `/tf` (tf2_msgs/msg/TFMessage: the model's own
   definition, models/interfaces/tf2_msgs, but the key's hash from rosbags' built-in
   ROS 2 Jazzy tf2_msgs, so a sample arrives only if ferroc's hash is Jazzy's).
2. Once the robot moved, publishes `/enable` `data: false` every 100 ms until ten
   commands came more than 0.5 s later (the robot must stand), then `data: true`.
3. Then publishes a `/goal_pose` (geometry_msgs/msg/PoseStamped, frame `odom`) 1.2 m
   from where `/odom` last put the robot, towards the arena's middle, three times
   0.5 s apart, and waits until `/odom` is within 0.15 m of it, or SECONDS pass.

Prints one JSON object: topics; tfs (each message's transforms); twists (each with `disabled`: received between 0.5 s
after the first `false` and the first `true`); scans (every field but the ranges, whose
values only the first 40 scans keep in full: `ranges`, and every scan as `count`, `min`,
`max`); odoms; the goal, when it was sent (`goal_after`: the number of odometry
messages received before it) and whether the robot reached it.
"""

import json
import math
import os
import sys
import threading
import time

from rosbags.typesys import Stores, get_typestore

from sdk_start import start, wait_for_topics  # noqa: E402

sdk, where, deadline = start()
TOPICS = {'/cmd_vel', '/scan', '/odom', '/tf', '/goal_pose', '/enable'}
TF = 'tf2_msgs/msg/TFMessage'
TF_MSG = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                      '../../models/interfaces/tf2_msgs/msg/TFMessage.msg')
TF_HASH = get_typestore(Stores.ROS2_JAZZY).hash_rihs01(TF)

topics = wait_for_topics(where, deadline, TOPICS)

lock = threading.Lock()
twists, scans, odoms, tfs = [], [], [], []
window = {'disabled_at': None, 'enabled_at': None}


def stamp(header):
    return {'sec': int(header.stamp.sec), 'nanosec': int(header.stamp.nanosec)}


def on_twist(msg):
    now = time.time()
    off, on = window['disabled_at'], window['enabled_at']
    with lock:
        twists.append({
            'linear': [msg.linear.x, msg.linear.y, msg.linear.z],
            'angular': [msg.angular.x, msg.angular.y, msg.angular.z],
            # Named as tests/ros2_run.rs's check_enable reads it.
            'after_disable': off is not None and now > off + 0.5 and (on is None or now < on),
        })


def on_scan(msg):
    ranges = [float(r) for r in msg.ranges.tolist()]
    with lock:
        scan = {
            'stamp': stamp(msg.header), 'frame_id': msg.header.frame_id,
            'angle_min': float(msg.angle_min), 'angle_max': float(msg.angle_max),
            'angle_increment': float(msg.angle_increment),
            'time_increment': float(msg.time_increment), 'scan_time': float(msg.scan_time),
            'range_min': float(msg.range_min), 'range_max': float(msg.range_max),
            'count': len(ranges), 'min': min(ranges, default=None),
            'max': max(ranges, default=None), 'intensities': len(msg.intensities),
        }
        if len(scans) < 40:
            scan['ranges'] = ranges
        scans.append(scan)


def on_odom(msg):
    p, q, t = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist
    with lock:
        odoms.append({
            'stamp': stamp(msg.header), 'frame_id': msg.header.frame_id,
            'child_frame_id': msg.child_frame_id,
            'position': [p.x, p.y, p.z], 'orientation': [q.x, q.y, q.z, q.w],
            'linear': [t.linear.x, t.linear.y, t.linear.z],
            'angular': [t.angular.x, t.angular.y, t.angular.z],
            'covariance': [len(msg.pose.covariance), len(msg.twist.covariance)],
        })


def on_tf(msg):
    with lock:
        tfs.append([{
            'stamp': stamp(t.header), 'frame_id': t.header.frame_id, 'child_frame_id': t.child_frame_id,
            'translation': [t.transform.translation.x, t.transform.translation.y,
                            t.transform.translation.z],
            'rotation': [t.transform.rotation.x, t.transform.rotation.y,
                         t.transform.rotation.z, t.transform.rotation.w],
        } for t in msg.transforms])


def moving(s):
    return any(v != 0.0 for v in s['linear'] + s['angular'])


subscribers = [
    sdk.ROS2Subscriber(topic='/cmd_vel', msg_type='geometry_msgs/msg/Twist',
                       callback=on_twist, **where),
    sdk.ROS2Subscriber(topic='/scan', msg_type='sensor_msgs/msg/LaserScan',
                       callback=on_scan, **where),
    sdk.ROS2Subscriber(topic='/odom', msg_type='nav_msgs/msg/Odometry',
                       callback=on_odom, **where),
]
# The SDK reads a definition given as text without its nested types: load them first.
sdk.get_message_class('geometry_msgs/msg/TransformStamped')
with open(TF_MSG) as f:
    subscribers.append(sdk.ROS2Subscriber(topic='/tf', msg_type=TF, msg_definition=f.read(),
                                          type_hash=TF_HASH, callback=on_tf, **where))
enable = sdk.ROS2Publisher(topic='/enable', msg_type='std_msgs/msg/Bool', **where)
goal_pose = sdk.ROS2Publisher(topic='/goal_pose', msg_type='geometry_msgs/msg/PoseStamped',
                              **where)
Header = sdk.get_message_class('std_msgs/msg/Header')
Time = sdk.get_message_class('builtin_interfaces/msg/Time')
Pose = sdk.get_message_class('geometry_msgs/msg/Pose')
Point = sdk.get_message_class('geometry_msgs/msg/Point')
Quaternion = sdk.get_message_class('geometry_msgs/msg/Quaternion')

# 2. /enable false until the robot stands, then true.
while time.time() < deadline:
    with lock:
        moved = any(moving(s) for s in twists)
        still = [s for s in twists if s['after_disable']]
    if len(still) >= 10:
        break
    if moved:
        if window['disabled_at'] is None:
            window['disabled_at'] = time.time()
        enable.publish(data=False)
    time.sleep(0.1)
window['enabled_at'] = time.time()
for _ in range(3):
    enable.publish(data=True)
    time.sleep(0.1)

# 3. A goal 1.2 m towards the middle from where the robot is.
goal, goal_after, reached = None, None, False
while time.time() < deadline and goal is None:
    with lock:
        last = odoms[-1] if odoms else None
        goal_after = len(odoms)
    if last is not None:
        x, y = last['position'][:2]
        towards = math.atan2(-y, -x) if math.hypot(x, y) > 0.5 else 0.0
        goal = [x + 1.2 * math.cos(towards), y + 1.2 * math.sin(towards)]
    else:
        time.sleep(0.1)
sent = 0
while goal is not None and time.time() < deadline:
    if sent < 3:
        now = time.time_ns()
        goal_pose.publish(
            header=Header(stamp=Time(sec=now // 10**9, nanosec=now % 10**9), frame_id='odom'),
            pose=Pose(position=Point(x=goal[0], y=goal[1], z=0.0),
                      orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)))
        sent += 1
    with lock:
        last = odoms[-1]
    if math.hypot(last['position'][0] - goal[0], last['position'][1] - goal[1]) < 0.15:
        reached = True
        break
    time.sleep(0.5)

with lock:
    print(json.dumps({'topics': [[name, types] for name, types in topics],
                      'samples': twists, 'scans': scans, 'odoms': odoms, 'tfs': tfs,
                      'tf_hash': TF_HASH,
                      'goal': goal, 'goal_after': goal_after, 'goal_sent': sent,
                      'reached': reached}))
sys.stdout.flush()
for s in subscribers:
    s.close()
enable.close()
goal_pose.close()
