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

"""Writing and iterating rosbag2 MCAP bags with rosbags (no rclpy).

Chunking and crash safety (what was found in rosbags 0.11.9)
-------------------------------------------------------------
``rosbags.rosbag2.Writer(..., storage_plugin=StoragePlugin.MCAP)`` has no
chunk option: its ``McapWriter`` buffers messages in memory and writes a
chunk only when the buffer exceeds a hard-coded 1 MiB (``2**20`` bytes,
uncompressed); schemas and channels go into the first chunk. The summary
(chunk index, statistics), the footer and ``metadata.yaml`` are written only
by ``close()``; on an exception rosbags' context manager *aborts* (no
summary, no ``metadata.yaml``). So a recorder killed mid-run leaves
``<bag>/<bag>.mcap`` holding the header and the chunks closed so far, and
loses up to 1 MiB of messages -- more than a minute of a 100 Hz
command/measurement pair.

:class:`BagWriter` bounds that loss: it swaps in a subclass of rosbags'
``McapWriter`` (through the ``Writer.STORAGE_PLUGINS`` table of the writer
instance) that closes the pending chunk once it holds ``chunk_size`` bytes
(default 64 KiB, at most rosbags' 1 MiB) or spans ``chunk_span_s`` seconds
of log time (default 1 s), and flushes every closed chunk to the OS
(``fsync=True`` also survives a power cut). A killed process then leaves
every chunk but the pending one intact. rosbags' reader rejects such a
file (it reads the footer first: ``File end magic is invalid.``);
:func:`open_bag` with ``recover_truncated=True`` reads the complete chunks
of the prefix itself (the ``mcap recover`` CLI from foxglove/mcap does the
same and writes a new indexed file). Unlike rosbags' writer,
:class:`BagWriter` finalises the bag when the ``with`` body raises (for
example on Ctrl-C), so what was written stays readable.

``ros2 bag record -s mcap`` gets the same effect from a
``--storage-config-file`` with ``chunkSize`` (mcap ``McapWriterOptions``).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
import functools
import os
from pathlib import Path
import struct
from typing import Any, TYPE_CHECKING
import zlib

import numpy as np
from rosbags.highlevel import AnyReader, AnyReaderError
from rosbags.interfaces import QosDurability
from rosbags.rosbag2 import ReaderError, StoragePlugin, Writer, WriterError
from rosbags.rosbag2.storage_mcap import McapWriter
from rosbags.serde import SerdeError
from rosbags.typesys import (
    get_types_from_idl,
    get_types_from_msg,
    get_typestore,
    Stores,
    TypesysError,
)

from hyst_id.errors import ConfigError, MissingTopicError, RecordingError, TruncatedBagError
from hyst_id.io.bag_metadata import fix_metadata, rosbags_qos
from hyst_id.io.interface_types import register_interface_types
from hyst_id.io.mcap_recover import lacks_footer, scan_records
from hyst_id.io.messages import at_path, build_message, merge
from hyst_id.io.topics import parse_field_path, TopicConfig

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

    from hyst_id.io.recording import Recording

__all__ = [
    'DEFAULT_CHUNK_SIZE',
    'DEFAULT_CHUNK_SPAN_S',
    'DEFAULT_START_NS',
    'BagContents',
    'BagWriter',
    'build_message',
    'default_typestore',
    'iter_bag_messages',
    'open_bag',
    'write_recording_bag',
]

#: Largest uncompressed chunk payload, bytes, before a chunk is written.
DEFAULT_CHUNK_SIZE = 64 * 1024
#: Longest log-time span of one chunk, seconds, before it is written.
DEFAULT_CHUNK_SPAN_S = 1.0
#: Stamp of ``t_s = 0`` in bags made from a recording: 2026-01-01T00:00:00Z.
DEFAULT_START_NS = 1_767_225_600 * 10**9

#: What a damaged bag raises inside rosbags (a corrupt size field: OverflowError,
#: MemoryError; a short record: struct.error), found by flipping bytes of a bag.
_READ_ERRORS = (AnyReaderError, ReaderError, SerdeError, TypesysError, OSError, ValueError,
                TypeError, KeyError, IndexError, EOFError, AssertionError, zlib.error,
                OverflowError, MemoryError, struct.error)


def default_typestore() -> Typestore:
    """Return the newest ROS 2 typestore rosbags ships (Kilted, else Jazzy, else Humble).

    The typed messages of ``hyst_id_interfaces`` are registered in it.
    """
    for name in ('ROS2_KILTED', 'ROS2_JAZZY', 'ROS2_HUMBLE'):
        if hasattr(Stores, name):
            return register_interface_types(get_typestore(getattr(Stores, name)))
    raise ConfigError('rosbags provides no ROS 2 typestore')  # pragma: no cover


class _ChunkedMcapWriter(McapWriter):
    """rosbags' MCAP storage writer with a bounded chunk and a flush per chunk."""

    def __init__(self, path: Path, compression: Any, *, chunk_size: int, chunk_span_ns: int,
                 fsync: bool) -> None:
        super().__init__(path, compression)
        self._chunk_size = chunk_size
        self._chunk_span_ns = chunk_span_ns
        self._fsync = fsync

    def write(self, connection: Any, timestamp: int, data: bytes | memoryview) -> None:
        super().write(connection, timestamp, data)
        chunk = self.chunk
        if chunk.msgs and (chunk.bio.tell() >= self._chunk_size or (
                self._chunk_span_ns > 0
                and chunk.message_end_time - chunk.message_start_time >= self._chunk_span_ns)):
            self.close_chunk()

    def close_chunk(self) -> None:
        super().close_chunk()
        self.bio.flush()
        if self._fsync:
            os.fsync(self.bio.fileno())

    def flush(self) -> None:
        if self.chunk.msgs:
            self.close_chunk()


class BagWriter:
    """Write a rosbag2 MCAP bag (directory, format version 9) with bounded chunks.

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory to create; must not exist.
    chunk_size : int
        Largest uncompressed chunk payload in bytes (1 KiB to 1 MiB).
    chunk_span_s : float or None
        Longest log-time span of a chunk in seconds; ``None`` or 0 disables.
    typestore : rosbags Typestore, optional
        Message definitions; default :func:`default_typestore`.
    fsync : bool
        ``os.fsync`` after every chunk (survives power loss, costs time).

    Notes
    -----
    Use as a context manager; :meth:`close` finalises the bag even when the
    ``with`` body raises. See the module docstring for crash safety.
    """

    def __init__(self, path: str | Path, *, chunk_size: int = DEFAULT_CHUNK_SIZE,
                 chunk_span_s: float | None = DEFAULT_CHUNK_SPAN_S,
                 typestore: Typestore | None = None, fsync: bool = False) -> None:
        if not 1024 <= int(chunk_size) <= 2**20:
            raise ConfigError(f'chunk_size must be in [1024, 1048576] bytes, got {chunk_size}')
        if chunk_span_s is not None and not chunk_span_s >= 0.0:
            raise ConfigError(f'chunk_span_s must be >= 0 s, got {chunk_span_s}')
        self.path = Path(path)
        self.typestore = typestore if typestore is not None else default_typestore()
        try:
            self._writer = Writer(self.path, version=9, storage_plugin=StoragePlugin.MCAP)
        except WriterError as exc:
            raise RecordingError(f'cannot create bag {self.path}: {exc}') from None
        span_ns = int(round((chunk_span_s or 0.0) * 1e9))
        self._writer.STORAGE_PLUGINS = {StoragePlugin.MCAP: functools.partial(
            _ChunkedMcapWriter, chunk_size=int(chunk_size), chunk_span_ns=span_ns,
            fsync=bool(fsync))}
        self._connections: dict[str, Any] = {}
        self._open = False

    def open(self) -> BagWriter:  # noqa: A003 (mirrors rosbags' Writer.open)
        """Create the bag directory and its ``.mcap`` file."""
        try:
            self._writer.open()
        except (WriterError, OSError) as exc:
            raise RecordingError(f'cannot create bag {self.path}: {exc}') from None
        self._open = True
        return self

    def __enter__(self) -> BagWriter:
        return self.open()

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> bool:
        self.close()
        return False

    def add_topic(self, name: str, msgtype: str, offered_qos: Sequence[Mapping[str, Any]] = (),
                  key: str | None = None) -> None:
        """Register topic ``name`` carrying ``msgtype`` (e.g. ``'std_msgs/msg/Float64'``).

        ``offered_qos`` are the publishers' QoS profiles as mappings of rmw
        values (``history``, ``depth``, ``reliability``, ``durability``,
        ``liveliness`` as rmw enum integers; ``deadline_ns``, ``lifespan_ns``,
        ``liveliness_lease_duration_ns``; ``avoid_ros_namespace_conventions``),
        stored in the bag as ``ros2 bag record`` stores them, so that a
        player can offer the same (a latched topic replays latched). ``key``
        (default ``name``) is what :meth:`write` takes: a second type on a topic.
        """
        if msgtype not in self.typestore.types:
            raise ConfigError(f'unknown message type {msgtype!r} for topic {name}')
        if (key or name) in self._connections:
            raise ValueError(f'topic {key or name} already added')
        self._connections[key or name] = self._writer.add_connection(
            name, msgtype, typestore=self.typestore,
            offered_qos_profiles=[rosbags_qos(q) for q in offered_qos])

    def write(self, topic: str, t_ns: int, msg: Any) -> None:
        """Write one message with log time ``t_ns`` (integer nanoseconds).

        Parameters
        ----------
        topic : str
            A topic registered with :meth:`add_topic`.
        t_ns : int
            Log (receive) time in nanoseconds since the epoch.
        msg : rosbags message, mapping or bytes
            A typestore message object; a mapping of field values (missing
            fields get zero/empty defaults, nested messages may be mappings,
            a ``builtin_interfaces/msg/Time`` may be an integer of ns); or an
            already CDR-serialised message (e.g. from
            ``rclpy.serialization.serialize_message``).
        """
        conn = self._connections.get(topic)
        if conn is None:
            raise ValueError(f'topic {topic} was not added; added: {sorted(self._connections)}')
        if isinstance(msg, (bytes, bytearray, memoryview)):
            data = bytes(msg)
        else:
            if isinstance(msg, Mapping):
                msg = build_message(self.typestore, conn.msgtype, msg)
            data = self.typestore.serialize_cdr(msg, conn.msgtype)
        self._writer.write(conn, int(t_ns), data)

    def flush(self) -> None:
        """Write the pending chunk now (e.g. from a recorder's timer)."""
        if self._open:
            self._writer.storage.flush()

    def close(self) -> None:
        """Write the last chunk, the summary and ``metadata.yaml``; idempotent."""
        if self._open:
            self._open = False
            try:
                self._writer.close()
                fix_metadata(self.path / 'metadata.yaml')
            except (WriterError, OSError) as exc:
                self._writer.abort()
                raise RecordingError(f'cannot finish bag {self.path}: {exc}') from None


@dataclass
class BagContents:
    """An open bag: its topics and a message iterator (see :func:`open_bag`).

    Attributes
    ----------
    path : pathlib.Path
        The bag directory or ``.mcap`` file.
    topics : dict
        Topic name to message type.
    counts : dict
        Topic name to message count.
    notes : list of str
        What was unusual (no ``metadata.yaml``, truncated file recovered).
    latched : set of str
        Topics every recorded publisher offered transient local (latched).
    """

    path: Path
    topics: dict[str, str]
    counts: dict[str, int]
    notes: list[str] = field(default_factory=list)
    _source: Any = None
    latched: set[str] = field(default_factory=set)

    def check_topics(self, topics: Sequence[str]) -> None:
        """Raise :class:`MissingTopicError` if one of ``topics`` is not in the bag."""
        for topic in topics:
            if topic not in self.topics:
                present = ', '.join(sorted(self.topics)) or 'none'
                raise MissingTopicError(
                    f'topic {topic} not in {self.path}; topics present: {present}')

    def messages(self, topics: Sequence[str] | None = None) -> Iterator[tuple[str, str, int, Any]]:
        """Yield ``(topic, msgtype, t_ns, message)`` in log-time order."""
        wanted = list(self.topics) if topics is None else list(topics)
        self.check_topics(wanted)
        n_read = 0
        try:
            for item in self._source(set(wanted)):
                yield item
                n_read += 1
        except _READ_ERRORS as exc:
            where = (f' after {n_read} good message(s): the file is damaged there'
                     if n_read else '')
            raise RecordingError(
                f'cannot read bag {self.path}{where}: {_one_line(exc)}') from None


def _one_line(exc: BaseException) -> str:
    text = ' '.join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 300 else text[:297] + '...'


def _bag_file(path: Path) -> tuple[Path, list[str]]:
    """Resolve a bag path to what rosbags opens (directory or single .mcap file)."""
    if path.is_dir() and not (path / 'metadata.yaml').exists():
        files = sorted(path.glob('*.mcap'))
        if len(files) != 1:
            raise RecordingError(f'not a bag: {path} has no metadata.yaml and '
                                 f'{len(files)} .mcap files (need exactly one)')
        return files[0], [f'{path} has no metadata.yaml (recorder stopped early?); '
                          f'read {files[0].name} directly']
    return path, []


@contextmanager
def open_bag(path: str | Path, *, recover_truncated: bool = False,
             remedy: str = 'recover_truncated=True') -> Iterator[BagContents]:
    """Open a rosbag2 bag (directory or single ``.mcap`` file) for reading.

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory (with ``metadata.yaml``, or holding exactly one
        ``.mcap``) or a ``.mcap`` file.
    recover_truncated : bool
        When the MCAP file has no footer (writer killed), read the complete
        chunks instead of raising.
    remedy : str
        How the caller's user asks for that, named in the error of a truncated
        bag (a node's parameter is ``-p recover_truncated:=true``).

    Yields
    ------
    BagContents
        Topics, counts and a message iterator; valid inside the ``with``.

    Raises
    ------
    RecordingError
        The bag cannot be read (corrupt, truncated, not a bag).
    """
    path = Path(path)
    if not path.exists():
        raise RecordingError(f'no such file: {path}')
    target, notes = _bag_file(path)
    failure = None
    try:
        reader = AnyReader([target], default_typestore=default_typestore())
        reader.open()
    except _READ_ERRORS as exc:
        failure = _one_line(exc)
    if failure is not None:
        mcaps = sorted(target.glob('*.mcap')) if target.is_dir() else [target]
        if len(mcaps) == 1 and mcaps[0].suffix == '.mcap' and lacks_footer(mcaps[0]):
            if recover_truncated:
                yield _recover(mcaps[0], path, notes)
                return
            raise TruncatedBagError(
                f'cannot read bag {path}: {failure} (no MCAP footer: truncated, or the '
                f'recorder was killed; {remedy} reads its complete chunks)')
        raise RecordingError(f'cannot read bag {path}: {failure}')
    try:
        topics: dict[str, str] = {}
        counts: dict[str, int] = {}
        latched: set[str] = set()
        for conn in reader.connections:
            topics[conn.topic] = conn.msgtype
            counts[conn.topic] = counts.get(conn.topic, 0) + conn.msgcount
            offered = getattr(conn.ext, 'offered_qos_profiles', None) or []
            if offered and all(q.durability == QosDurability.TRANSIENT_LOCAL for q in offered):
                latched.add(conn.topic)

        def source(wanted: set[str]) -> Iterator[tuple[str, str, int, Any]]:
            conns = [c for c in reader.connections if c.topic in wanted]
            if not conns:
                return
            for conn, t_ns, raw in reader.messages(connections=conns):
                yield conn.topic, conn.msgtype, t_ns, reader.deserialize(raw, conn.msgtype)

        yield BagContents(path, topics, counts, notes, source, latched)
    finally:
        reader.close()


def _recover(target: Path, path: Path, notes: list[str]) -> BagContents:
    """Read the complete records of a footer-less MCAP file (schemas, channels, messages)."""
    raw = target.read_bytes()
    try:
        schemas, channels, messages = scan_records(raw)
        store = get_typestore(Stores.EMPTY)
        for name, enc, text in schemas.values():
            store.register(get_types_from_idl(text) if enc == 'ros2idl'
                           else get_types_from_msg(text, name))
    except _READ_ERRORS as exc:
        raise RecordingError(f'cannot recover bag {path}: {_one_line(exc)}') from None
    if not channels:
        raise RecordingError(f'cannot recover bag {path}: no complete chunk in the truncated '
                             f'file ({len(raw)} bytes)')
    messages.sort(key=lambda m: m[0])
    topics = {topic: schemas.get(sid, ('?',))[0] for topic, sid, _ in channels.values()}
    counts = dict.fromkeys(topics, 0)
    for _, cid, _ in messages:
        counts[channels[cid][0]] += 1
    notes = notes + [f'{target.name} is truncated (no footer): recovered {len(messages)} '
                     f'messages from its complete chunks']

    def source(wanted: set[str]) -> Iterator[tuple[str, str, int, Any]]:
        for t_ns, cid, data in messages:
            topic = channels[cid][0]
            if topic in wanted:
                yield topic, topics[topic], t_ns, store.deserialize_cdr(data, topics[topic])

    return BagContents(path, topics, counts, notes, source)


def iter_bag_messages(path: str | Path, topics: Sequence[str] | None = None, *,
                      recover_truncated: bool = False) -> Iterator[tuple[str, str, int, Any]]:
    """Yield ``(topic, msgtype, t_ns, message)`` from a bag in log-time order.

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory or ``.mcap`` file.
    topics : sequence of str, optional
        Topics to yield; default all. A missing topic raises
        :class:`~hyst_id.errors.MissingTopicError`.
    recover_truncated : bool
        Read the complete chunks of a footer-less (killed writer) file.

    Yields
    ------
    tuple
        Topic, message type, log time in ns, deserialised rosbags message.
    """
    with open_bag(path, recover_truncated=recover_truncated) as bag:
        yield from bag.messages(topics)


def write_recording_bag(path: str | Path, recording: Recording,
                        topics: TopicConfig | None = None, *,
                        start_ns: int = DEFAULT_START_NS,
                        chunk_size: int = DEFAULT_CHUNK_SIZE) -> Path:
    """Write a recording as a bag: one command and one measurement message per sample.

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory to create.
    recording : Recording
        The run to write (not validated, so broken recordings can be made).
    topics : TopicConfig, optional
        Topics, message types and fields; default
        ``TopicConfig.for_channel(recording.channel)``.
    start_ns : int
        Stamp of ``t_s = 0`` in nanoseconds since the epoch.
    chunk_size : int
        See :class:`BagWriter`.

    Returns
    -------
    pathlib.Path
        The bag directory. Sample ``i`` has log time and ``header.stamp``
        (when the type has a header) ``start_ns + round(t_s[i] * 1e9)``.
    """
    cfg = topics if topics is not None else TopicConfig.for_channel(recording.channel)
    t_s = np.asarray(recording.t_s, dtype=float)
    command = np.asarray(recording.command, dtype=float)
    meas = np.asarray(recording.measurement, dtype=float)
    if not (t_s.shape == command.shape == meas.shape) or t_s.ndim != 1:
        raise RecordingError(f'length mismatch: {t_s.shape}, {command.shape}, {meas.shape}')
    if not np.isfinite(t_s).all():
        raise RecordingError('t_s has NaN/inf values: cannot stamp messages')
    stamps = int(start_ns) + np.rint(t_s * 1e9).astype(np.int64)
    if (stamps < 0).any():
        raise RecordingError('stamps before the epoch: raise start_ns')
    streams = ((cfg.command_topic, cfg.command_type, parse_field_path(cfg.command_field),
                command), (cfg.measurement_topic, cfg.measurement_type,
                           parse_field_path(cfg.measurement_field), meas))
    with BagWriter(path, chunk_size=chunk_size) as writer:
        headers = {}
        for topic, msgtype, _, _ in streams:
            writer.add_topic(topic, msgtype)
            headers[topic] = 'header' in dict(writer.typestore.fielddefs[msgtype][1])
        for i, t_ns in enumerate(stamps.tolist()):
            for topic, msgtype, tokens, values in streams:
                fields = at_path(tokens, float(values[i]))
                if headers[topic]:
                    fields = merge({'header': {'stamp': t_ns}}, fields)
                if msgtype == 'sensor_msgs/msg/JointState' and 'name' not in fields:
                    n = max(len(fields.get('position') or ()), 1)
                    fields['name'] = ['actuator'] if n == 1 else [f'actuator_{k}'
                                                                  for k in range(n)]
                writer.write(topic, t_ns, fields)
    return Path(path)
