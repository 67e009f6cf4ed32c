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

"""Read a :class:`~hyst_id.io.recording.Recording` from a CSV file or a rosbag2 MCAP bag.

:func:`read_recording` picks the reader from the path and validates the
result once. CSV files are taken as they are: duplicate or decreasing
timestamps are reported by validation, never repaired. Bags are two
message streams that the reader pairs: the measurement samples are the
time base and each gets the last command at or before its stamp (the DAC
holds a command until the next one); out-of-order stamps are sorted and
duplicate stamps dropped, each with a note in ``Recording.notes``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
import math
from pathlib import Path
import re
from typing import Any

import numpy as np

from hyst_id.errors import ConfigError, MissingTopicError, RecordingError
from hyst_id.io.bag import open_bag
from hyst_id.io.params_file import read_yaml
from hyst_id.io.recording import CHANNELS, Recording, validate_recording

__all__ = [
    'CSV_SUFFIXES',
    'DEFAULT_COLUMNS',
    'TopicConfig',
    'get_field',
    'load_topic_config',
    'parse_field_path',
    'read_csv',
    'read_mcap',
    'read_recording',
]

#: File suffixes read as delimited text.
CSV_SUFFIXES = ('.csv', '.txt', '.tsv')
#: Header names read by default: time in seconds, command, measurement.
DEFAULT_COLUMNS = ('t', 'command', 'measurement')

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
_FIELD_RE = re.compile(r'[A-Za-z_]\w*(\[\d+\])*(\.[A-Za-z_]\w*(\[\d+\])*)*')


def parse_field_path(path: str) -> tuple[str | int, ...]:
    """Split a field path such as ``'position[0]'`` or ``'a.b[2].c'`` into tokens.

    Raises
    ------
    ConfigError
        The path is not dotted attribute names with optional ``[i]`` indices.
    """
    if not isinstance(path, str) or not _FIELD_RE.fullmatch(path):
        raise ConfigError(f'bad field path {path!r}: expected names with optional [i] indices, '
                          f'e.g. position[0] or header.stamp.sec')
    return tuple(int(tok[1:-1]) if tok.startswith('[') else tok
                 for tok in re.findall(r'\[\d+\]|[A-Za-z_]\w*', path))


def get_field(msg: Any, tokens: Sequence[str | int]) -> Any:
    """Follow parsed field-path ``tokens`` into a message (AttributeError/IndexError if absent)."""
    value = msg
    for tok in tokens:
        value = value[tok] if isinstance(tok, int) else getattr(value, tok)
    return value


@dataclass(frozen=True)
class TopicConfig:
    """Where a recording's command and measurement live in a bag.

    Attributes
    ----------
    command_topic, measurement_topic : str
        Topic names.
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
            ``stamp_source``.

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
        values['stamp_source'] = params.get('stamp_source', 'header')
        return cls(**values)


def load_topic_config(yaml_path: str | Path, channel: str, *,
                      node: str | None = None) -> TopicConfig:
    """Read the topic configuration of ``channel`` from a params YAML file.

    Accepted layouts: a top-level ``topics:`` mapping; or the ROS params-file
    layout ``<node>: ros__parameters:`` with a ``topics:`` mapping inside or
    the keys given flat (``command_topic``, ``<channel>_field``, ...) or
    dotted (``topics.command_topic``). Sections are merged in file order;
    with ``node`` only ``/**`` and that node's section count. A file without
    any of these keys gives the defaults.

    Raises
    ------
    ConfigError
        Unreadable or invalid YAML, unknown keys in a ``topics:`` mapping,
        invalid values.
    """
    yaml_path = Path(yaml_path)
    doc = read_yaml(yaml_path)
    doc = {} if doc is None else doc
    if not isinstance(doc, dict):
        raise ConfigError(f'{yaml_path}: expected a mapping at the top level')
    merged: dict[str, Any] = {}

    def take(where: str, section: Any, strict: bool) -> None:
        if not isinstance(section, dict):
            raise ConfigError(f'{yaml_path}: {where} must be a mapping')
        if strict and set(section) - _KEYS:
            raise ConfigError(f'{yaml_path}: unknown key(s) {sorted(set(section) - _KEYS)} in '
                              f'{where}; known: {sorted(_KEYS)}')
        merged.update({k: v for k, v in section.items() if k in _KEYS})

    if 'topics' in doc:
        take('topics', doc['topics'], True)
    for key, value in doc.items():
        if not (isinstance(value, dict) and 'ros__parameters' in value):
            continue
        if node is not None and str(key).strip('/') not in ('**', node.strip('/')):
            continue
        params = value['ros__parameters'] or {}
        where = f'{key}.ros__parameters'
        if not isinstance(params, dict):
            raise ConfigError(f'{yaml_path}: {where} must be a mapping')
        if 'topics' in params:
            take(f'{where}.topics', params['topics'], True)
        take(where, {k.removeprefix('topics.'): v for k, v in params.items()}, False)
    try:
        return TopicConfig.for_channel(channel, merged)
    except ConfigError as exc:
        raise ConfigError(f'{yaml_path}: {exc}') from None


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def read_csv(path: str | Path, channel: str, *,
             columns: Sequence[str | int] = DEFAULT_COLUMNS, time_scale: float = 1.0,
             delimiter: str | None = None, command_unit: str = '',
             measurement_unit: str = '') -> Recording:
    """Read a recording from delimited text, without validating or reordering it.

    Parameters
    ----------
    path : str or pathlib.Path
        The file. Blank lines and lines starting with ``#`` are skipped; the
        first other line is a header if any of its cells is not a number.
    channel : str
        Measured channel stored in the recording.
    columns : sequence of str or int
        Time, command and measurement columns: header names, or 0-based
        indices (needed for headerless files).
    time_scale : float
        Factor turning the time column into seconds (0.001 for ms).
    delimiter : str, optional
        Cell separator; default comma if the first line has one, else
        semicolon if it has one, else runs of whitespace.
    command_unit, measurement_unit : str
        Units for reports.

    Returns
    -------
    Recording
        Not validated: :func:`read_recording` validates.

    Raises
    ------
    RecordingError
        Empty file, non-numeric cell, ragged rows.
    MissingTopicError
        A column is missing (or there is no header to look names up in).
    ConfigError
        Bad ``columns`` or ``time_scale``.
    """
    path = Path(path)
    if not path.is_file():
        raise RecordingError(f'no such file: {path}')
    columns = tuple(columns)
    if len(columns) != 3:
        raise ConfigError(f'columns must name 3 columns (time, command, measurement), '
                          f'got {columns!r}')
    if not (isinstance(time_scale, (int, float)) and math.isfinite(time_scale)
            and time_scale > 0):
        raise ConfigError(f'time_scale must be a positive number, got {time_scale!r}')
    try:
        text = path.read_text(encoding='utf-8-sig')
    except (OSError, UnicodeDecodeError) as exc:
        raise RecordingError(f'cannot read {path}: {exc}') from None
    lines = [(n, line) for n, line in enumerate(text.splitlines(), 1)
             if line.strip() and not line.lstrip().startswith('#')]
    if not lines:
        raise RecordingError(f'empty file: {path}')
    sep = delimiter
    if sep is None:
        sep = ',' if ',' in lines[0][1] else ';' if ';' in lines[0][1] else None

    def split(line: str) -> list[str]:
        return [c.strip().strip('"\'') for c in (line.split(sep) if sep else line.split())]

    first = split(lines[0][1])
    names = first if not all(_is_number(c) for c in first) else None
    rows = lines[1:] if names is not None else lines
    if not rows:
        raise RecordingError(f'no data rows in {path}: only a header')
    ncols = len(first)
    index = []
    for role, col in zip(('time', 'command', 'measurement'), columns, strict=True):
        if isinstance(col, (int, np.integer)) and not isinstance(col, bool):
            if not 0 <= int(col) < ncols:
                raise MissingTopicError(f'{role} column index {col} out of range: {path} has '
                                        f'{ncols} columns (0..{ncols - 1})')
            index.append(int(col))
        elif isinstance(col, str):
            if names is None:
                raise MissingTopicError(f'column {col!r} not found: {path} has no header row '
                                        f'(pass integer column indices)')
            if col not in names:
                raise MissingTopicError(f'column {col!r} not in {path}; columns present: '
                                        f'{", ".join(names)}')
            index.append(names.index(col))
        else:
            raise ConfigError(f'column {col!r} must be a header name or an integer index')
    labels = [names[i] if names else f'#{i}' for i in index]
    data = np.empty((len(rows), 3))
    for r, (lineno, line) in enumerate(rows):
        cells = split(line)
        if len(cells) != ncols:
            raise RecordingError(f'ragged rows in {path}: line {lineno} has {len(cells)} '
                                 f'fields, expected {ncols}')
        for j, i in enumerate(index):
            try:
                data[r, j] = float(cells[i])
            except ValueError:
                raise RecordingError(f'non-numeric value {cells[i]!r} in column {labels[j]} '
                                     f'at line {lineno} of {path}') from None
    note = (f'columns: t_s = {labels[0]} x {time_scale:g}, command = {labels[1]}, '
            f'measurement = {labels[2]}')
    return Recording(t_s=data[:, 0] * float(time_scale), command=data[:, 1],
                     measurement=data[:, 2], channel=channel, command_unit=command_unit,
                     measurement_unit=measurement_unit, source=str(path), notes=(note,))


def _tidy(t_ns: np.ndarray, values: np.ndarray, topic: str,
          notes: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Sort a stream by stamp and keep the last message of each repeated stamp."""
    if (np.diff(t_ns) < 0).any():
        notes.append(f'{topic}: {int((np.diff(t_ns) < 0).sum())} stamps out of order; '
                     f'sorted by stamp')
        order = np.argsort(t_ns, kind='stable')
        t_ns, values = t_ns[order], values[order]
    keep = np.append(t_ns[1:] != t_ns[:-1], True)
    if not keep.all():
        notes.append(f'{topic}: dropped {int((~keep).sum())} messages with a duplicate stamp '
                     f'(kept the last at each stamp)')
        t_ns, values = t_ns[keep], values[keep]
    return t_ns, values


def _collect(bag: Any, cfg: TopicConfig) -> dict[str, tuple[list[int], list[float]]]:
    """Read stamps and values of the command and measurement topics."""
    spec = {cfg.command_topic: (parse_field_path(cfg.command_field), cfg.command_field,
                                cfg.command_type),
            cfg.measurement_topic: (parse_field_path(cfg.measurement_field),
                                    cfg.measurement_field, cfg.measurement_type)}
    out: dict[str, tuple[list[int], list[float], list[int]]] = {t: ([], [], []) for t in spec}
    for topic, msgtype, log_ns, msg in bag.messages(list(spec)):
        tokens, field_path, expected = spec[topic]
        try:
            value = get_field(msg, tokens)
        except (AttributeError, IndexError, KeyError, TypeError) as exc:
            raise RecordingError(
                f'{topic} ({msgtype}, expected {expected}): cannot read field {field_path!r} '
                f'from message {len(out[topic][0])}: {exc}') from None
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
            raise RecordingError(f'{topic} ({msgtype}, expected {expected}): field '
                                 f'{field_path!r} is {type(value).__name__}, not a number')
        stamp = log_ns
        if cfg.stamp_source == 'header' and hasattr(msg, 'header'):
            stamp = int(msg.header.stamp.sec) * 10**9 + int(msg.header.stamp.nanosec)
        out[topic][0].append(stamp)
        out[topic][1].append(float(value))
        out[topic][2].append(log_ns)
    return out


def read_mcap(path: str | Path, channel: str, topics: TopicConfig | Mapping | None = None, *,
              recover_truncated: bool = False) -> Recording:
    """Read a recording from a rosbag2 bag (MCAP directory or single ``.mcap`` file).

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory or ``.mcap`` file.
    channel : str
        Measured channel.
    topics : TopicConfig or mapping, optional
        Topic configuration (a mapping goes through
        :meth:`TopicConfig.for_channel`); default for ``channel``.
    recover_truncated : bool
        Read the complete chunks of a footer-less file (killed recorder).

    Returns
    -------
    Recording
        Times in seconds from the first kept measurement; not validated.

    Raises
    ------
    RecordingError
        Unreadable bag, empty topic, missing field, no overlap in time.
    MissingTopicError
        A configured topic is not in the bag.
    """
    cfg = topics if isinstance(topics, TopicConfig) else TopicConfig.for_channel(channel, topics)
    with open_bag(path, recover_truncated=recover_truncated) as bag:
        notes = list(bag.notes)
        bag.check_topics([cfg.command_topic, cfg.measurement_topic])
        for topic, expected in ((cfg.command_topic, cfg.command_type),
                                (cfg.measurement_topic, cfg.measurement_type)):
            if bag.counts.get(topic, 0) == 0:
                raise RecordingError(f'topic {topic} in {path} has no messages')
            if bag.topics[topic] != expected:
                notes.append(f'{topic} is {bag.topics[topic]} (configured {expected})')
        streams = _collect(bag, cfg)
    arrays = {}
    for topic, (stamps, values, log_ns) in streams.items():
        if not stamps:
            raise RecordingError(f'topic {topic} in {path} has no messages')
        t_ns = np.asarray(stamps, dtype=np.int64)
        if (t_ns == 0).any():
            notes.append(f'{topic}: {int((t_ns == 0).sum())} messages without header.stamp; '
                         f'used log times for the whole topic')
            t_ns = np.asarray(log_ns, dtype=np.int64)
        arrays[topic] = _tidy(t_ns, np.asarray(values, dtype=float), topic, notes)
    cmd_t, cmd_v = arrays[cfg.command_topic]
    meas_t, meas_v = arrays[cfg.measurement_topic]
    idx = np.searchsorted(cmd_t, meas_t, side='right') - 1
    keep = idx >= 0
    if not keep.any():
        raise RecordingError(
            f'no {cfg.measurement_topic} sample at or after the first {cfg.command_topic} '
            f'message (measurements {meas_t[0] / 1e9:.3f}..{meas_t[-1] / 1e9:.3f} s, first '
            f'command {cmd_t[0] / 1e9:.3f} s since the epoch; different clocks?)')
    if not keep.all():
        notes.append(f'dropped {int((~keep).sum())} {cfg.measurement_topic} samples before '
                     f'the first command')
    meas_t, meas_v, idx = meas_t[keep], meas_v[keep], idx[keep]
    notes.append(f'time origin t_s = 0: stamp {meas_t[0] / 1e9:.9f} s since the epoch')
    return Recording(t_s=(meas_t - meas_t[0]).astype(np.float64) * 1e-9, command=cmd_v[idx],
                     measurement=meas_v, channel=channel, command_unit=cfg.command_unit,
                     measurement_unit=cfg.measurement_unit,
                     source=f'{path} ({cfg.command_topic}, {cfg.measurement_topic})',
                     notes=tuple(notes))


def read_recording(path: str | Path, channel: str, *,
                   topics: TopicConfig | Mapping | None = None,
                   columns: Sequence[str | int] | None = None, time_scale: float | None = None,
                   validate: bool = True, recover_truncated: bool = False) -> Recording:
    """Read and validate a recording from a bag directory, ``.mcap`` or CSV file.

    Parameters
    ----------
    path : str or pathlib.Path
        A bag directory (with ``metadata.yaml``, or holding one ``.mcap``),
        a ``.mcap`` file, or a ``.csv`` / ``.tsv`` / ``.txt`` file.
    channel : str
        Measured channel: ``position``, ``pressure`` or ``flow``.
    topics : TopicConfig or mapping, optional
        Bag topics (see :func:`read_mcap`). For CSV files only its units
        are used.
    columns, time_scale : optional
        CSV only (see :func:`read_csv`).
    validate : bool
        Run :func:`~hyst_id.io.recording.validate_recording` (messages are
        prefixed with the path).
    recover_truncated : bool
        Bags only: read the complete chunks of a footer-less MCAP file.

    Returns
    -------
    Recording
        The recording, validated unless ``validate`` is false.

    Raises
    ------
    RecordingError
        Missing or unreadable file, failed validation (subclasses:
        :class:`~hyst_id.errors.MissingTopicError`,
        :class:`~hyst_id.errors.NoExcitationError`).
    ConfigError
        Unknown channel, CSV options given for a bag, bad topic config.
    """
    path = Path(path)
    if not path.exists():
        raise RecordingError(f'no such file: {path}')
    if channel not in CHANNELS:
        raise ConfigError(f'unknown channel {channel!r}; expected one of {CHANNELS}')
    suffix = path.suffix.lower()
    if path.is_dir() or suffix in ('.mcap', '.db3'):
        if columns is not None or time_scale is not None:
            raise ConfigError(f'columns/time_scale apply to CSV files only, not to {path}')
        rec = read_mcap(path, channel, topics, recover_truncated=recover_truncated)
    elif suffix in CSV_SUFFIXES:
        units = ('', '')
        if topics is not None:
            cfg = (topics if isinstance(topics, TopicConfig)
                   else TopicConfig.for_channel(channel, topics))
            units = (cfg.command_unit, cfg.measurement_unit)
        rec = read_csv(path, channel, columns=DEFAULT_COLUMNS if columns is None else columns,
                       time_scale=1.0 if time_scale is None else time_scale,
                       command_unit=units[0], measurement_unit=units[1])
    else:
        raise RecordingError(f'unrecognised recording format: {path} (expected a bag '
                             f'directory, .mcap, {", ".join(CSV_SUFFIXES)})')
    if not validate:
        return rec
    try:
        return validate_recording(rec)
    except RecordingError as exc:
        raise type(exc)(f'{path}: {exc}') from None
