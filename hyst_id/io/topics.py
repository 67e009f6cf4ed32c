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

"""Which topics, message types and fields hold a channel, and how to read a field path.

:class:`TopicConfig` (defaults in ``params/topics.yaml``, overridable per
channel), :func:`parse_field_path` / :func:`get_field` for paths such as
``position[0]`` or ``header.stamp.sec``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from pathlib import Path
import re
from typing import Any

from hyst_id.errors import ConfigError
from hyst_id.io.interface_types import STAMPED_VALUE_TYPE
from hyst_id.io.params_file import read_yaml
from hyst_id.io.recording import CHANNELS

__all__ = ['NamedIndex', 'NODE_STREAM_KEYS', 'NODE_TOPIC_KEYS', 'TOPIC_FILE_KEYS',
           'TopicConfig', 'get_field', 'load_topic_config', 'load_topic_file',
           'node_parameters_in', 'parse_field_path', 'value_field']

#: Per channel: topic, message type, field path, unit.
_COMMAND_DEFAULTS = ('/hyst_id/command', 'std_msgs/msg/Float64', 'data', 'mA')
_CHANNEL_DEFAULTS = {
    'position': ('/hyst_id/position', 'sensor_msgs/msg/JointState', 'position[0]', ''),
    'pressure': ('/hyst_id/pressure', 'sensor_msgs/msg/FluidPressure', 'fluid_pressure', 'Pa'),
    'flow': ('/hyst_id/flow', 'std_msgs/msg/Float64', 'data', 'g/s'),
}
_SUFFIXES = ('topic', 'type', 'field', 'unit')
_KEYS = frozenset([f'command_{s}' for s in _SUFFIXES] + ['stamp_source']
                  + [f'{ch}_{s}' for ch in CHANNELS for s in _SUFFIXES])
#: Every key ``params/topics.yaml`` may hold (shared by all nodes through ``/**``).
TOPIC_FILE_KEYS = _KEYS
#: Keys of a ``/**`` topics mapping that only nodes read (``params/stamped.yaml``: the
#: compensator's desired stream and the excitation's output); recordings ignore them.
NODE_STREAM_KEYS = frozenset({'desired_type', 'output_type'})
#: The nodes' own topic names under ``topics:`` (the compensator's desired value, the
#: excitation's output, the identifier's results): a params file may hold them, a recording's
#: reader leaves them alone; any other key there is a typo (``test_wiring.py`` checks that
#: every node's ``topics.*`` parameter is known here).
NODE_TOPIC_KEYS = frozenset({'desired_topic', 'output_topic', 'identified_params_topic',
                             'identified_typed_topic'})
_INDEX = r'\[(\d+|[A-Za-z_][\w.-]*)\]'
_FIELD_RE = re.compile(rf'[A-Za-z_]\w*({_INDEX})*(\.[A-Za-z_]\w*({_INDEX})*)*')


class NamedIndex(str):
    """A field-path index given by name: ``position[valve]`` is ``position[name.index('valve')]``.

    The label is looked up in the ``name`` array of the message that holds
    the indexed field (``sensor_msgs/JointState``'s joint names), so a
    recording reads the right joint whatever the order the driver publishes.
    """


def value_field(type_name: str, field: str) -> str:
    """``field``, or ``value`` for a ``StampedValue`` left at Float64's default ``data``."""
    return 'value' if type_name == STAMPED_VALUE_TYPE and field == 'data' else field


def parse_field_path(path: str) -> tuple[str | int, ...]:
    """Split a field path such as ``'position[0]'`` or ``'a.b[2].c'`` into tokens.

    An index may be a name, ``position[valve]`` (a :class:`NamedIndex`:
    the entry whose ``name`` is ``valve``).

    Raises
    ------
    ConfigError
        The path is not dotted attribute names with optional ``[i]`` indices.
    """
    if not isinstance(path, str) or not _FIELD_RE.fullmatch(path):
        raise ConfigError(f'bad field path {path!r}: expected names with optional [i] or '
                          f'[name] indices, e.g. position[0], position[valve] or '
                          f'header.stamp.sec')
    out: list[str | int] = []
    for tok in re.findall(r'\[[^\]]+\]|[A-Za-z_]\w*', path):
        if tok.startswith('['):
            label = tok[1:-1]
            out.append(int(label) if label.isdigit() else NamedIndex(label))
        else:
            out.append(tok)
    return tuple(out)


def get_field(msg: Any, tokens: Sequence[str | int]) -> Any:
    """Follow parsed field-path ``tokens`` into a message.

    Raises AttributeError / IndexError when a field or index is absent, and
    KeyError when a :class:`NamedIndex` is not among the holder's ``name`` entries.
    """
    value, holder = msg, msg
    for tok in tokens:
        if isinstance(tok, NamedIndex):
            names = list(getattr(holder, 'name'))
            if tok not in names:
                raise KeyError(f'no entry named {str(tok)!r} (names: {names})')
            value = value[names.index(tok)]
        elif isinstance(tok, int):
            value = value[tok]
        else:
            holder, value = value, getattr(value, tok)
    return value


@dataclass(frozen=True)
class TopicConfig:
    """Where a recording's command and measurement live in a bag.

    Attributes
    ----------
    command_topic, measurement_topic : str
        Topic names, fully qualified: a relative name (``hyst_id/command``,
        as the nodes' params files give them) is taken in the root
        namespace, ``/hyst_id/command``.
    command_field, measurement_field : str
        Field paths in the messages (``data``, ``position[0]``, ...).
    command_type, measurement_type : str
        Message types written by :func:`~hyst_id.io.bag.write_recording_bag`
        and expected when reading (another type is accepted, with a note, if
        the field resolves to a number).
    command_unit, measurement_unit : str
        Units for reports.
    stamp_source : str
        ``'header'``: ``header.stamp`` when the message has a header, else
        the log time; ``'log'``: always the log (receive) time.
    """

    command_topic: str = _COMMAND_DEFAULTS[0]
    command_field: str = _COMMAND_DEFAULTS[2]
    measurement_topic: str = _CHANNEL_DEFAULTS['position'][0]
    measurement_field: str = _CHANNEL_DEFAULTS['position'][2]
    command_type: str = _COMMAND_DEFAULTS[1]
    measurement_type: str = _CHANNEL_DEFAULTS['position'][1]
    command_unit: str = _COMMAND_DEFAULTS[3]
    measurement_unit: str = _CHANNEL_DEFAULTS['position'][3]
    stamp_source: str = 'header'

    def __post_init__(self) -> None:
        for f in fields(self):
            if not isinstance(getattr(self, f.name), str):
                raise ConfigError(f'{f.name} must be a string, got {getattr(self, f.name)!r}')
        for name in ('command_topic', 'measurement_topic', 'command_type', 'measurement_type'):
            if not getattr(self, name).strip():
                raise ConfigError(f'{name} is empty')
        for name in ('command_topic', 'measurement_topic'):
            # A bag holds fully qualified names; a relative name (as the nodes'
            # params files give them) means the root namespace here.
            if not getattr(self, name).startswith('/'):
                object.__setattr__(self, name, '/' + getattr(self, name))
        if self.command_topic == self.measurement_topic:
            raise ConfigError(f'command and measurement share the topic {self.command_topic}')
        parse_field_path(self.command_field)
        parse_field_path(self.measurement_field)
        if self.stamp_source not in ('header', 'log'):
            raise ConfigError(f"stamp_source must be 'header' or 'log', got "
                              f'{self.stamp_source!r}')

    @classmethod
    def for_channel(cls, channel: str, params: Mapping[str, Any] | None = None) -> TopicConfig:
        """Return the configuration of ``channel``, defaults overridden by ``params``.

        Parameters
        ----------
        channel : str
            One of ``position``, ``pressure``, ``flow``.
        params : mapping, optional
            Keys as in ``params/topics.yaml``: ``command_topic``,
            ``command_type``, ``command_field``, ``command_unit``,
            ``<channel>_topic``, ``<channel>_type``, ``<channel>_field``,
            ``<channel>_unit`` (keys of other channels are ignored) and
            ``stamp_source``. A ``*_type`` of ``hyst_id_interfaces/msg/StampedValue``
            whose field is left at ``data`` reads ``value`` (:func:`value_field`).

        Raises
        ------
        ConfigError
            Unknown channel or key, or an invalid value.
        """
        if channel not in _CHANNEL_DEFAULTS:
            raise ConfigError(f'unknown channel {channel!r}; expected one of {CHANNELS}')
        params = dict(params or {})
        unknown = sorted(set(params) - _KEYS)
        if unknown:
            raise ConfigError(f'unknown topic key(s) {unknown}; known: {sorted(_KEYS)}')
        defaults = _CHANNEL_DEFAULTS[channel]
        values = {}
        for role, prefix, default in (('command', 'command', _COMMAND_DEFAULTS),
                                      ('measurement', channel, defaults)):
            for i, suffix in enumerate(_SUFFIXES):
                values[f'{role}_{suffix}'] = params.get(f'{prefix}_{suffix}', default[i])
            values[f'{role}_field'] = value_field(values[f'{role}_type'], values[f'{role}_field'])
        values['stamp_source'] = params.get('stamp_source', 'header')
        return cls(**values)


def _node_sections(doc: dict, prefix: str = '') -> list[tuple[str, str, Any]]:
    """``(where, node name, ros__parameters)`` of every node section, namespaces walked."""
    out = []
    for key, value in doc.items():
        if not isinstance(value, dict):
            continue
        where = f'{prefix}{key}'
        if 'ros__parameters' in value:
            out.append((f'{where}.ros__parameters', str(key).strip('/'),
                        value['ros__parameters'] or {}))
        else:
            out += _node_sections(value, f'{where}.')
    return out


def node_parameters_in(yaml_path: str | Path) -> list[str]:
    """The keys of a params file's node sections that are not topics or fields (sorted).

    What a node reads (GAASS settings, QoS, its own streams such as
    ``topics.identified_params_topic``) and a recording's reader does not:
    the CLI names them so that a user does not take them as applied, and a
    misspelt topic key (``topics.comand_topic``) shows up among them.
    """
    return _node_parameters(read_yaml(Path(yaml_path)))


def _node_parameters(doc: Any) -> list[str]:
    known = _KEYS | NODE_STREAM_KEYS      # a node's own topics are named as not used here
    keys: set[str] = set()
    for _, _, params in _node_sections(doc if isinstance(doc, dict) else {}):
        if not isinstance(params, dict):
            continue
        keys |= {str(k) for k in params if k != 'topics'
                 and str(k).removeprefix('topics.') not in known}
        if isinstance(params.get('topics'), dict):   # a node's own streams, or a typo
            keys |= {f'topics.{k}' for k in params['topics'] if k not in known}
    return sorted(keys)


def load_topic_config(yaml_path: str | Path, channel: str, *,
                      node: str | None = None) -> TopicConfig:
    """Read the topic configuration of ``channel`` from a params YAML file.

    Accepted layouts: a top-level ``topics:`` mapping (its keys checked);
    or the ROS params-file layout ``<node>: ros__parameters:`` (also under
    namespaces, ``/ns: <node>: ros__parameters:``) with a ``topics:``
    mapping inside or the keys given flat (``command_topic``,
    ``<channel>_field``, ...) or dotted (``topics.command_topic``); a node
    section's other keys, and topic keys only that node knows (the
    identifier's ``identified_params_topic``, the recorder's list of topics),
    are the node's and left alone (:func:`node_parameters_in` names them).
    Sections are merged in file order; with ``node`` only ``/**`` and that
    node's section count. A file with neither gives the defaults; any other
    top-level key is refused.

    Raises
    ------
    ConfigError
        Unreadable or invalid YAML, unknown top-level keys, unknown keys in a
        top-level ``topics:`` mapping, invalid values.
    """
    yaml_path = Path(yaml_path)
    return _topic_config(read_yaml(yaml_path), yaml_path, channel, node)


def load_topic_file(yaml_path: str | Path, channel: str) -> tuple[TopicConfig, list[str]]:
    """:func:`load_topic_config` and :func:`node_parameters_in` of one read of the file."""
    yaml_path = Path(yaml_path)
    doc = read_yaml(yaml_path)
    return _topic_config(doc, yaml_path, channel, None), _node_parameters(doc)


def _topic_config(doc: Any, yaml_path: Path, channel: str, node: str | None) -> TopicConfig:
    doc = {} if doc is None else doc
    if not isinstance(doc, dict):
        raise ConfigError(f'{yaml_path}: expected a mapping at the top level')
    merged: dict[str, Any] = {}

    def take(where: str, section: Any, strict: bool) -> None:
        if not isinstance(section, dict):
            raise ConfigError(f'{yaml_path}: {where} must be a mapping')
        unknown = set(section) - _KEYS - NODE_STREAM_KEYS - NODE_TOPIC_KEYS
        if strict and unknown:
            raise ConfigError(f'{yaml_path}: unknown key(s) {sorted(unknown)} in '
                              f'{where}; known: {sorted(_KEYS)}')
        merged.update({k: v for k, v in section.items() if k in _KEYS})

    stray = [k for k, v in doc.items() if k != 'topics' and not _node_sections({k: v})]
    if stray:
        raise ConfigError(f'{yaml_path}: unknown top-level key(s) {sorted(map(str, stray))}: '
                          'a params file holds a topics: mapping or ROS node sections '
                          '(<node>: ros__parameters:)')
    if 'topics' in doc:
        take('topics', doc['topics'], True)
    for where, name, params in _node_sections(doc):
        if node is not None and name not in ('**', node.strip('/')):
            continue
        if not isinstance(params, dict):
            raise ConfigError(f'{yaml_path}: {where} must be a mapping')
        # a key of a topics: mapping (or topics.<key>) no node knows is a typo: refused, as in
        # the top-level layout (a review's topics: position_fild had only been noted)
        dotted = {k.removeprefix('topics.') for k in params if str(k).startswith('topics.')}
        both = sorted(dotted & set(params['topics'])) if isinstance(params.get('topics'),
                                                                    dict) else []
        if both:        # which one a node reads depends on their order
            raise ConfigError(f'{yaml_path}: {where} gives {", ".join(both)} twice, as '
                              'topics.<key> and under topics:; keep one')
        if isinstance(params.get('topics'), dict):
            take(f'{where}.topics', params['topics'], True)
        take(where, {k.removeprefix('topics.'): v for k, v in params.items()
                     if k.startswith('topics.')}, True)
        take(where, {k: v for k, v in params.items() if not k.startswith('topics.')}, False)
    try:
        return TopicConfig.for_channel(channel, merged)
    except ConfigError as exc:
        raise ConfigError(f'{yaml_path}: {exc}') from None
