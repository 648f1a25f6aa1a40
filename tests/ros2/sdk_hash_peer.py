"""A ROS 2 node whose definition of std_srvs/srv/SetBool hashes otherwise than ours,
written with `zenoh-ros2-sdk` (PyPI), a pure-Python rmw_zenoh node we did not write,
given another type hash explicitly (as a node built from a changed SetBool.srv would
compute it).

Usage: sdk_hash_peer.py client PORT INTERFACES SECONDS
       sdk_hash_peer.py server PORT INTERFACES SECONDS

Connects to the run at tcp/127.0.0.1:PORT with the definitions ferroc ships under
INTERFACES (the SDK cannot download them here).

`client` (beside `tests/ros2/switch_two.xml`, whose node offers /switch_bot/set_enabled
and /switch_bot/set_enabled/spare): calls both services with the SDK's own hash, then
/switch_bot/set_enabled with another hash through the SDK's client (which fails the
call on an error reply) and through eclipse-zenoh as rmw_zenoh's client sends a call
(to complete queryables only, Z_QUERY_TARGET_ALL_COMPLETE), then both services with the
right hash again. Prints one JSON object: the answers (null for none), what the SDK
logged about the wrong-hash call, and the error reply's text.

`server` (beside `tests/ros2/asker.xml`, whose module calls /switch_bot/set_enabled):
offers the service under another hash for SECONDS and prints the requests it got.
"""

import json
import logging
import sys
import time

mode, port, interfaces, seconds = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4])

import zenoh  # noqa: E402
import zenoh_ros2_sdk as sdk  # noqa: E402

logged = []


class Keep(logging.Handler):
    def emit(self, record):
        logged.append(record.getMessage())


sdk_log = logging.getLogger('zenoh_ros2_sdk')
sdk_log.setLevel(logging.ERROR)
sdk_log.addHandler(Keep())
sdk_log.propagate = False
sdk.get_registry(interfaces)
where = {'router_ip': '127.0.0.1', 'router_port': port}
SERVICE, SPARE, SETBOOL = '/switch_bot/set_enabled', '/switch_bot/set_enabled/spare', \
    'std_srvs/srv/SetBool'
OTHER = 'RIHS01_' + '5a' * 32
deadline = time.time() + seconds

if mode == 'server':
    requests = []

    def serve(request):
        requests.append(bool(request.data))
        return server.response_msg_class(success=True, message='other hash')

    server = sdk.ROS2ServiceServer(SERVICE, SETBOOL, callback=serve, type_hash=OTHER, **where)
    while time.time() < deadline:
        time.sleep(0.1)
    print(json.dumps({'requests': requests}))
    server.close()
    sys.stdout.flush()
    sys.exit(0)

while time.time() < deadline:
    names = {name for name, _ in sdk.get_service_names_and_types(timeout=1.0, **where)}
    if {SERVICE, SPARE} <= names:
        break
    time.sleep(0.2)


def answer(response):
    if response is None:
        return None
    return {'success': bool(response.success), 'message': str(response.message)}


good = sdk.ROS2ServiceClient(SERVICE, SETBOOL, timeout=10.0, **where)
spare = sdk.ROS2ServiceClient(SPARE, SETBOOL, timeout=10.0, **where)
wrong = sdk.ROS2ServiceClient(SERVICE, SETBOOL, timeout=10.0, type_hash=OTHER, **where)
before = [answer(good.call(data=True)), answer(spare.call(data=True))]
logged.clear()
wrong_answer = answer(wrong.call(data=False))
sdk_logged = list(logged)

# The same wrong-hash call as rmw_zenoh's client sends it.
session = wrong.session_mgr.session
request = bytes(wrong.session_mgr.store.serialize_cdr(
    wrong.request_msg_class(data=False), wrong.request_store_type))
attachment = (7).to_bytes(8, 'little') + time.time_ns().to_bytes(8, 'little') \
    + bytes([16]) + bytes(range(16))
errors, oks = [], 0
for reply in session.get(wrong.keyexpr, payload=request, attachment=attachment,
                         target=zenoh.QueryTarget.ALL_COMPLETE, timeout=10.0):
    if reply.ok is not None:
        oks += 1
    else:
        errors.append(reply.err.payload.to_string())
after = [answer(good.call(data=True)), answer(spare.call(data=True))]
print(json.dumps({'before': before, 'after': after, 'wrong_answer': wrong_answer,
                  'sdk_logged': sdk_logged, 'raw_errors': errors, 'raw_oks': oks,
                  'wrong_key': wrong.keyexpr}))
sys.stdout.flush()
