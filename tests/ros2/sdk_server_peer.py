"""A ROS 2 server of the service `ferroc run tests/ros2/asker.xml` calls, written with
`zenoh-ros2-sdk` (PyPI), a pure-Python rmw_zenoh node we did not write: its own service
type hash and key, and its strict reading of a request's attachment (sequence number and
client GID, which it echoes).

Usage: sdk_server_peer.py PORT INTERFACES SECONDS

Connects to the run at tcp/127.0.0.1:PORT with the definitions ferroc ships under
INTERFACES (the SDK cannot download them here), offers `/switch_bot/set_enabled`
(std_srvs/srv/SetBool), answering `success: true`, `message: "python saw <data>"`, and
subscribes to `/answer` (std_msgs/msg/String), where the run publishes the message of
each answer it got. After answers to both `true` and `false` came back, or SECONDS,
prints one JSON object: the requests' data in order, the answers the run published.
"""

import json
import logging
import sys
import threading
import time

port, interfaces, seconds = int(sys.argv[1]), sys.argv[2], float(sys.argv[3])

import zenoh_ros2_sdk as sdk  # noqa: E402

logging.getLogger('zenoh_ros2_sdk').setLevel(logging.ERROR)
sdk.get_registry(interfaces)
where = {'router_ip': '127.0.0.1', 'router_port': port}
lock = threading.Lock()
requests, answers = [], []


def serve(request):
    with lock:
        requests.append(bool(request.data))
    return server.response_msg_class(success=True, message=f'python saw {bool(request.data)}')


def on_answer(msg):
    with lock:
        answers.append(str(msg.data))


server = sdk.ROS2ServiceServer('/switch_bot/set_enabled', 'std_srvs/srv/SetBool',
                               callback=serve, **where)
subscriber = sdk.ROS2Subscriber(topic='/answer', msg_type='std_msgs/msg/String',
                                callback=on_answer, **where)
deadline = time.time() + seconds
while time.time() < deadline:
    with lock:
        if {'python saw True', 'python saw False'} <= set(answers):
            break
    time.sleep(0.1)
with lock:
    print(json.dumps({'requests': requests, 'answers': answers}))
subscriber.close()
server.close()
sys.stdout.flush()
