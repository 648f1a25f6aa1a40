"""A ROS 2 client of the service `ferroc run tests/ros2/switch.xml` offers, written with
`zenoh-ros2-sdk` (PyPI), a pure-Python rmw_zenoh node we did not write: its own service
type hash (from the service's request, response and event descriptions), key,
liveliness tokens, attachment and CDR.

Usage: sdk_service_peer.py PORT INTERFACES SECONDS

Connects to the run at tcp/127.0.0.1:PORT (the SDK's "router"), with the message and
service definitions ferroc ships under INTERFACES given explicitly (the SDK cannot
download them here). Lists the services with their types as `ros2 service list -t`
does, subscribes to `/enabled` (std_msgs/msg/Bool), and calls
`/switch_bot/set_enabled` (std_srvs/srv/SetBool) with `data: false`, then, once
`/enabled` says false, with `data: true`. Then, on the key the SDK's client built,
one more request with eclipse-zenoh directly, to read the reply's attachment. Prints
one JSON object: services, the responses, the /enabled values in order, the raw
reply's attachment (hex).
"""

import json
import logging
import struct
import sys
import threading
import time

port, interfaces, seconds = int(sys.argv[1]), sys.argv[2], float(sys.argv[3])

import zenoh  # noqa: E402
import zenoh_ros2_sdk as sdk  # noqa: E402

logging.getLogger('zenoh_ros2_sdk').setLevel(logging.ERROR)
sdk.get_registry(interfaces)
where = {'router_ip': '127.0.0.1', 'router_port': port}
SERVICE, SETBOOL = '/switch_bot/set_enabled', 'std_srvs/srv/SetBool'

deadline = time.time() + seconds
services = []
while time.time() < deadline:
    services = sdk.get_service_names_and_types(timeout=1.0, **where)
    if SERVICE in {name for name, _ in services}:
        break
    time.sleep(0.2)

enabled = []
lock = threading.Lock()


def on_enabled(msg):
    with lock:
        enabled.append(bool(msg.data))


subscriber = sdk.ROS2Subscriber(topic='/enabled', msg_type='std_msgs/msg/Bool',
                                callback=on_enabled, **where)
client = sdk.ROS2ServiceClient(SERVICE, SETBOOL, timeout=10.0, **where)


def answer(response):
    if response is None:
        return None
    return {'success': bool(response.success), 'message': str(response.message)}


responses = [answer(client.call(data=False))]
while time.time() < deadline:
    with lock:
        if enabled and not enabled[-1]:
            break
    time.sleep(0.05)
responses.append(answer(client.call(data=True)))
while time.time() < deadline:
    with lock:
        if enabled and enabled[-1]:
            break
    time.sleep(0.05)

# The same request through eclipse-zenoh, to see the reply's attachment: rmw_zenoh's
# server echoes the request's sequence number and the client's GID.
session = client.session_mgr.session
request = bytes(client.session_mgr.store.serialize_cdr(
    client.request_msg_class(data=True), client.request_store_type))
gid = bytes(range(16))
attachment = struct.pack('<qq', 41, time.time_ns()) + bytes([16]) + gid
raw = None
for reply in session.get(client.keyexpr, payload=request, attachment=attachment, timeout=10.0):
    if reply.ok is not None and reply.ok.attachment is not None:
        raw = {'key': str(reply.ok.key_expr), 'attachment': reply.ok.attachment.to_bytes().hex()}
with lock:
    print(json.dumps({'services': [[name, types] for name, types in services],
                      'responses': responses, 'enabled': enabled, 'raw': raw,
                      'key': client.keyexpr}))
subscriber.close()
sys.stdout.flush()
