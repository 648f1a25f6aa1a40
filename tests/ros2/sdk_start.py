"""What every zenoh-ros2-sdk peer of the tests begins with.

Its arguments (the port of the node's listening endpoint, ferroc's interface folder,
seconds), the SDK quiet but for errors with ferroc's definitions registered before any
entity asks for one, and a bounded wait until the topics it needs are listed.
"""

import logging
import sys
import time

import zenoh_ros2_sdk as sdk


def start():
    """The SDK, where to reach the node (`**where` for the SDK's calls), the deadline."""
    port, interfaces, seconds = int(sys.argv[1]), sys.argv[2], float(sys.argv[3])
    logging.getLogger('zenoh_ros2_sdk').setLevel(logging.ERROR)
    sdk.get_registry(interfaces)
    return sdk, {'router_ip': '127.0.0.1', 'router_port': port}, time.time() + seconds


def wait_for_topics(where, deadline, names):
    """The topic listing once it holds `names`, or the last one at `deadline`."""
    topics = []
    while time.time() < deadline:
        topics = sdk.get_topic_names_and_types(timeout=1.0, **where)
        if set(names) <= {name for name, _ in topics}:
            break
        time.sleep(0.2)
    return topics
