"""The independent side of tests/rosbags.rs: Python `rosbags` (PyPI), which we did not
write, reads ferroc's shipped .msg/.srv files, hashes every type and deserialises and
re-serialises every CDR sample the Rust test sends. Reads a JSON request on stdin, writes
a JSON answer on stdout.

One adaptation, stated: rosidl turns a .msg `char` into IDL `uint8` before hashing
(rosidl_adapter/msg/__init__.py, MSG_TYPE_TO_IDL), rosbags keeps `char` (FieldType 13).
Hashes are compared both ways: `rosbags` as is, and with rosidl's mapping applied."""
import json
import pathlib
import sys

import numpy
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.base import Nodetype


def load(root):
    types = {}
    for path in sorted(pathlib.Path(root).glob('*/*/*')):
        pkg, kind, name = path.parts[-3], path.parts[-2], path.stem
        text = path.read_text()
        if kind == 'msg':
            types.update(get_types_from_msg(text, f'{pkg}/msg/{name}'))
            continue
        lines = text.splitlines()
        cut = lines.index('---')
        req, res = f'{pkg}/srv/{name}_Request', f'{pkg}/srv/{name}_Response'
        # rosbags files a parsed text under `msg`; a service's halves live in `srv`.
        for full, part in ((req, lines[:cut]), (res, lines[cut + 1:])):
            parsed = get_types_from_msg('\n'.join(part), full.replace('/srv/', '/msg/'))
            types[full] = parsed.pop(full.replace('/srv/', '/msg/'))
            types.update(parsed)
        event = f'{pkg}/srv/{name}_Event'
        seq = lambda t: (Nodetype.SEQUENCE, ((Nodetype.NAME, t), 1))
        types[event] = ([], [
            ('info', (Nodetype.NAME, 'service_msgs/msg/ServiceEventInfo')),
            ('request', seq(req)),
            ('response', seq(res)),
        ])
        types[f'{pkg}/srv/{name}'] = ([], [
            ('request_message', (Nodetype.NAME, req)),
            ('response_message', (Nodetype.NAME, res)),
            ('event_message', (Nodetype.NAME, event)),
        ])
    return types


def char_as_uint8(types):
    def fix(desc):
        kind, args = desc
        if kind == Nodetype.BASE and args[0] == 'char':
            return (kind, ('uint8', args[1]))
        if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
            return (kind, (fix(args[0]), args[1]))
        return desc
    return {k: (c, [(n, fix(d)) for n, d in f]) for k, (c, f) in types.items()}


def to_json(value):
    if isinstance(value, numpy.ndarray):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [to_json(v) for v in value]
    if hasattr(value, '__dataclass_fields__'):
        return {k: to_json(getattr(value, k)) for k in value.__dataclass_fields__
                if k not in ('structure_needs_at_least_one_member', '__msgtype__')
                and not k.isupper()}  # constants are class fields too
    if isinstance(value, numpy.generic):
        return value.item()
    return value


def main():
    request = json.load(sys.stdin)
    types = load(request['interfaces'])
    store = get_typestore(Stores.EMPTY)
    store.register(types)
    rosidl = get_typestore(Stores.EMPTY)
    rosidl.register(char_as_uint8(types))
    hashes = {t: [store.hash_rihs01(t), rosidl.hash_rihs01(t)] for t in request['hash']}
    samples = []
    for s in request['samples']:
        msg = store.deserialize_cdr(bytes.fromhex(s['cdr']), s['type'])
        back = bytes(store.serialize_cdr(msg, s['type'], little_endian=True)).hex()
        samples.append({'value': to_json(msg), 'cdr': back})
    json.dump({'hashes': hashes, 'samples': samples}, sys.stdout)


main()
