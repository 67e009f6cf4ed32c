# Copyright 2026 The hyst_id authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""Typestore messages from plain mappings (for writing bags without rclpy).

:func:`build_message` fills every field a mapping leaves out with its
default (zero, empty, or a nested default message); :func:`at_path` and
:func:`merge` build the nested mapping that puts one value at a field path
such as ``position[0]`` or ``header.stamp``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, TYPE_CHECKING

import numpy as np
from rosbags.interfaces import Nodetype

from hyst_id.errors import ConfigError

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

__all__ = ['at_path', 'build_message', 'merge']

_PRIMITIVE_DTYPES = {
    'bool': np.bool_, 'byte': np.uint8, 'char': np.uint8, 'int8': np.int8, 'uint8': np.uint8,
    'int16': np.int16, 'uint16': np.uint16, 'int32': np.int32, 'uint32': np.uint32,
    'int64': np.int64, 'uint64': np.uint64, 'float32': np.float32, 'float64': np.float64,
}


def build_message(typestore: Typestore, msgtype: str, values: Mapping | None) -> Any:
    """Build a typestore message from a mapping, filling missing fields with defaults."""
    values = dict(values or {})
    _, fields = typestore.fielddefs[msgtype]
    unknown = set(values) - {name for name, _ in fields}
    if unknown:
        raise ConfigError(f'{msgtype} has no field(s) {sorted(unknown)}; '
                          f'fields: {[name for name, _ in fields]}')
    kwargs = {name: _build_value(typestore, node, values.get(name)) for name, node in fields}
    return typestore.types[msgtype](**kwargs)


def _build_value(typestore: Typestore, node: tuple, value: Any) -> Any:
    kind, spec = node
    if kind == Nodetype.BASE:
        typ = spec[0]
        if typ == 'string':
            return '' if value is None else str(value)
        if value is None:
            return False if typ == 'bool' else 0.0 if typ.startswith('float') else 0
        return float(value) if typ.startswith('float') else bool(value) if typ == 'bool' \
            else int(value)
    if kind == Nodetype.NAME:
        if spec == 'builtin_interfaces/msg/Time' and isinstance(value, (int, np.integer)):
            sec, nanosec = divmod(int(value), 10**9)
            return typestore.types[spec](sec=sec, nanosec=nanosec)
        if value is None or isinstance(value, Mapping):
            return build_message(typestore, spec, value)
        return value
    sub, length = spec
    items = [] if value is None else list(value)
    if kind == Nodetype.ARRAY and len(items) < length:
        items += [None] * (length - len(items))
    if sub[0] == Nodetype.BASE and sub[1][0] != 'string':
        dtype = _PRIMITIVE_DTYPES[sub[1][0]]
        return np.asarray([0 if x is None else x for x in items], dtype=dtype)
    return [_build_value(typestore, sub, x) for x in items]


def at_path(tokens: Sequence[str | int], value: float) -> Any:
    """Nested mapping/list that puts ``value`` at a parsed field path."""
    if not tokens:
        return value
    head, rest = tokens[0], at_path(tokens[1:], value)
    if isinstance(head, str) and type(head) is not str:          # topics.NamedIndex
        raise ConfigError(f'a field addressed by name ([{head}]) can be read, not written: '
                          'give the index, e.g. position[0]')
    if isinstance(head, int):
        return [None] * head + [rest]
    return {head: rest}


def merge(a: Any, b: Any) -> Any:
    """``b`` laid over ``a``, nested mappings merged key by key."""
    if isinstance(a, dict) and isinstance(b, dict):
        return {**a, **{k: merge(a[k], v) if k in a else v for k, v in b.items()}}
    return b
