"""A late-joining ROS 2 peer for transient-local durability, from clients we did not
write: Python `eclipse-zenoh` (its zenoh-ext AdvancedSubscriber and AdvancedPublisher,
the API rmw_zenoh's transient-local ends are made of), `zenoh-ros2-sdk` (a pure-Python
rmw_zenoh node: its transient-local subscriber asks publishers' caches itself) and
`rosbags` (its own Jazzy definitions, RIHS01 hashes and CDR).

Usage: ros2_durable.py PORT INTERFACES SECONDS

Started after the ferroc node listening on tcp/127.0.0.1:PORT published, as Twists
with linear.x = 1, 2, 3, 4, 5: `/latched` (reliable, transient local, depth 3),
`/latched_be` (best effort, transient local, depth 1) and `/volatile` (volatile).

1. Late subscribers: an AdvancedSubscriber with history (depth 3, detecting late
   publishers) on each of the three topics, and a zenoh-ros2-sdk subscriber with a
   transient-local QoS of depth 3 on `/latched` and `/volatile` (INTERFACES: the
   `.msg` files ferroc ships, as the SDK cannot download definitions here). Waits until
   the latched topics' history arrived (or SECONDS).
2. A cached publisher: an AdvancedPublisher (cache of 1, publisher detection) on the key
   of `/from_py` publishes linear.x = 7.5 with rmw_zenoh's attachment, and a plain
   publisher on `/from_py_volatile` publishes linear.x = 8.5; then prints `ready` and
   waits for a line on standard input (ferroc's late subscribers are done).

Prints one JSON object: what each subscriber received (linear.x values, in order).
"""

import json
import logging
import struct
import sys
import threading
import time

port, interfaces, seconds = int(sys.argv[1]), sys.argv[2], float(sys.argv[3])

import zenoh  # noqa: E402
import zenoh.ext  # noqa: E402
import zenoh_ros2_sdk as sdk  # noqa: E402
from zenoh_ros2_sdk.qos import QosDurability, QosProfile  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

logging.getLogger('zenoh_ros2_sdk').setLevel(logging.ERROR)
TWIST = 'geometry_msgs/msg/Twist'
DDS = 'geometry_msgs::msg::dds_::Twist_'
store = get_typestore(Stores.ROS2_JAZZY)
Twist = store.types[TWIST]
Vector3 = store.types['geometry_msgs/msg/Vector3']
twist_hash = store.hash_rihs01(TWIST)

conf = zenoh.Config()
conf.insert_json5('mode', '"peer"')
conf.insert_json5('connect/endpoints', json.dumps([f'tcp/127.0.0.1:{port}']))
conf.insert_json5('listen/endpoints', '["tcp/127.0.0.1:0"]')
conf.insert_json5('scouting/multicast/enabled', 'false')
conf.insert_json5('timestamping/enabled', 'true')
session = zenoh.open(conf)

received = {}
lock = threading.Lock()


def collect(name):
    with lock:
        received[name] = []

    def on_sample(sample):
        msg = store.deserialize_cdr(sample.payload.to_bytes(), TWIST)
        with lock:
            received[name].append(msg.linear.x)
    return on_sample


def collect_sdk(name):
    with lock:
        received[name] = []

    def on_msg(msg):
        with lock:
            received[name].append(msg.linear.x)
    return on_msg


history = zenoh.ext.HistoryConfig(detect_late_publishers=True, max_samples=3)
late = [zenoh.ext.declare_advanced_subscriber(session, f'0/{topic}/{DDS}/{twist_hash}',
                                              collect(topic), history=history)
        for topic in ('latched', 'latched_be', 'volatile')]

sdk.get_registry(interfaces)
where = {'router_ip': '127.0.0.1', 'router_port': port}
durable = QosProfile(durability=QosDurability.TRANSIENT_LOCAL, history_depth=3)
sdk_late = [sdk.ROS2Subscriber(topic=f'/{topic}', msg_type=TWIST, qos=durable,
                               callback=collect_sdk(f'sdk_{topic}'), **where)
            for topic in ('latched', 'volatile')]

deadline = time.time() + seconds
while time.time() < deadline:
    with lock:
        if (len(received['latched']) >= 3 and received['latched_be']
                and received['sdk_latched']):
            break
    time.sleep(0.05)


def twist(x):
    return bytes(store.serialize_cdr(
        Twist(linear=Vector3(x=x, y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=0.0)),
        TWIST, little_endian=True))


def attachment(sequence):
    return struct.pack('<qq', sequence, time.time_ns()) + bytes([16]) + bytes(range(16))


cached = zenoh.ext.declare_advanced_publisher(
    session, f'0/from_py/{DDS}/{twist_hash}',
    cache=zenoh.ext.CacheConfig(max_samples=1), publisher_detection=True)
cached.put(twist(7.5), attachment=attachment(1))
plain = session.declare_publisher(f'0/from_py_volatile/{DDS}/{twist_hash}')
plain.put(twist(8.5), attachment=attachment(1))
print('ready', flush=True)
sys.stdin.readline()

with lock:
    print(json.dumps(received), flush=True)
for s in late:
    s.undeclare()
for s in sdk_late:
    s.close()
cached.undeclare()
plain.undeclare()
session.close()
