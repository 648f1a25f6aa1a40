"""The independent side of tests/mcap_schema.rs: Python `rosbags` (PyPI), which we did
not write, parses each `ros2msg` schema text ferroc writes into MCAP recordings (the
type's definition and its dependencies after `MSG:` lines) with its own .msg reader, on
its own (a fresh type store per text, so every dependency comes from the text), and
hashes the type (RIHS01). Reads a JSON request on stdin, writes a JSON answer on stdout.

As in rosbags_check.py: rosidl hashes a .msg `char` as IDL `uint8`, rosbags keeps
`char`; the hash is given both ways."""
import json
import sys

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.base import Nodetype


def char_as_uint8(types):
    def fix(desc):
        kind, args = desc
        if kind == Nodetype.BASE and args[0] == 'char':
            return (kind, ('uint8', args[1]))
        if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
            return (kind, (fix(args[0]), args[1]))
        return desc
    return {k: (c, [(n, fix(d)) for n, d in f]) for k, (c, f) in types.items()}


def main():
    request = json.load(sys.stdin)
    hashes = {}
    for name, text in request['schemas'].items():
        types = get_types_from_msg(text, name)
        store = get_typestore(Stores.EMPTY)
        store.register(types)
        rosidl = get_typestore(Stores.EMPTY)
        rosidl.register(char_as_uint8(types))
        hashes[name] = [store.hash_rihs01(name), rosidl.hash_rihs01(name), sorted(types)]
    json.dump({'hashes': hashes}, sys.stdout)


main()
