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

"""Recorder node: logs a list of topics to a rosbag2 MCAP bag (hyst_id.io.bag).

Each configured topic is subscribed once it has a publisher: its type comes
from the ROS graph (imported with importlib), its QoS is adapted to the
publishers (best effort if any publisher is, transient local if all are),
and messages are written as received, still serialised (``raw=True``).
Every second the publishers are looked at again. A publisher whose QoS the
subscription does not match (a best-effort one joining reliable ones) makes
the recorder subscribe again with QoS that matches all (the new subscription
before the old one goes; a message both deliver is written once). A topic
carrying a second type is recorded in it too where the middleware allows;
Fast DDS takes one type per topic in a process, so there the second type's
messages are not recorded and ``/diagnostics`` says so (ERROR, naming the
topic and type) for the recorder's life. Before, the first type and QoS seen
were kept and a second publisher's messages were lost without a word.

Log time of a message is its *source timestamp* (when the publisher sent
it, from the middleware), not when the recorder got it: so a position
stamped right after the command that caused it is never logged before that
command, however late delivery was, and readers pairing streams by stamp
(``hyst_id.io.readers``) pair them as they happened. The bag is finalised
on Ctrl-C / SIGTERM (the summary and ``metadata.yaml`` are written).

Crash safety: messages go into MCAP chunks that are written (and flushed to
the OS) once they hold ``chunk_size`` bytes or span ``chunk_span_s`` of log
time, and at least every ``flush_period_s``. A recorder killed outright
(SIGKILL, power cut with ``fsync``) leaves a file whose complete chunks
``recover_truncated=True`` reads: it loses only the pending chunk, i.e. at
most the last ``chunk_span_s`` (1 s by default) of messages before the kill,
plus any messages still in transit to it.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
import datetime
from pathlib import Path
import threading
import time
from typing import Any

import rclpy
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from hyst_id.errors import ConfigError
from hyst_id.io.bag import BagWriter
from hyst_id.nodes.support import (
    DESIRED_TOPIC,
    HystNode,
    IDENTIFIED_PARAMS_TOPIC,
    message_class,
    Param,
    source_time_ns,
    spin_node,
    topic_params,
)
from hyst_id.nodes.support.ros import first_line

__all__ = ['PARAMS', 'Recorder', 'default_bag_name', 'main']

_DEFAULT_TOPICS = [p.default for p in topic_params()] + [DESIRED_TOPIC,
                                                         IDENTIFIED_PARAMS_TOPIC]

PARAMS = [
    Param('output', '', "bag directory to create; '' = hyst_id_<date-time> in the working "
          'directory', read_only=True),
    Param('topics', _DEFAULT_TOPICS, 'topics to record', read_only=True),
    Param('discovery_period_s', 0.1, 'how often to look for the publishers of missing '
          'topics', low=0.01, high=60.0, unit='s', read_only=True),
    Param('flush_period_s', 1.0, 'write the pending chunk at least this often', low=0.05,
          high=3600.0, unit='s', read_only=True),
    Param('chunk_size', 65536, 'largest MCAP chunk before it is written', low=1024,
          high=1048576, unit='bytes', read_only=True),
    Param('chunk_span_s', 1.0, 'longest log-time span of an MCAP chunk before it is written '
          '(0 = no limit)', low=0.0, high=3600.0, unit='s', read_only=True),
]


def default_bag_name() -> str:
    """Return ``hyst_id_YYYY_MM_DD-HH_MM_SS`` (rosbag2's naming)."""
    return datetime.datetime.now().strftime('hyst_id_%Y_%m_%d-%H_%M_%S')


def _qos_for(infos: list) -> QoSProfile:
    """Best effort (deep queue) if any publisher is, else reliable keep-all (nothing lost)."""
    best_effort = any(i.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
                      for i in infos)
    latched = bool(infos) and all(
        i.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for i in infos)
    history = HistoryPolicy.KEEP_LAST if best_effort else HistoryPolicy.KEEP_ALL
    return QoSProfile(history=history, depth=1000,
                      reliability=(ReliabilityPolicy.BEST_EFFORT if best_effort
                                   else ReliabilityPolicy.RELIABLE),
                      durability=(DurabilityPolicy.TRANSIENT_LOCAL if latched
                                  else DurabilityPolicy.VOLATILE))


def _offered(qos: QoSProfile) -> dict[str, Any]:
    """A publisher's QoS as rmw values, for the bag's ``offered_qos_profiles``."""
    def ns(duration: Any) -> int:
        return int(getattr(duration, 'nanoseconds', 0) or 0)

    return {'history': int(qos.history), 'depth': int(qos.depth),
            'reliability': int(qos.reliability), 'durability': int(qos.durability),
            'liveliness': int(qos.liveliness), 'deadline_ns': ns(qos.deadline),
            'lifespan_ns': ns(qos.lifespan),
            'liveliness_lease_duration_ns': ns(qos.liveliness_lease_duration),
            'avoid_ros_namespace_conventions': bool(qos.avoid_ros_namespace_conventions)}


@dataclass
class _Stream:
    """One recorded (topic, type): its subscription, and what drops repeats after a swap."""

    writer_key: str                 # the bag connection's key (the topic, for its first type)
    sub: Any = None
    qos: QoSProfile | None = None
    repeats_until_ns: int = 0       # a resubscription's overlap: repeats dropped until then
    recent: deque = field(default_factory=lambda: deque(maxlen=256))

    def repeat(self, source_stamp: int | None, data: bytes) -> bool:
        """Whether a message was delivered already (only within a resubscription's overlap).

        The last messages are remembered always, so that a latched topic's history
        delivered again by the new subscription is recognised.
        """
        if not source_stamp:
            return False
        seen = (source_stamp, hash(data))
        if self.repeats_until_ns and time.monotonic_ns() > self.repeats_until_ns:
            self.repeats_until_ns = 0
        if self.repeats_until_ns and seen in self.recent:
            return True
        self.recent.append(seen)
        return False


class Recorder(HystNode):
    """Write the configured topics into an MCAP bag until shut down."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('recorder', PARAMS, **kwargs)
        topics = [t for t in self.p('topics') if t]
        if not topics:
            raise ConfigError('recorder: no topics to record')
        # relative names take the node's namespace; remaps apply
        self._wanted = list(dict.fromkeys(self.resolve_topic_name(t) for t in topics))
        self.path = Path(self.p('output') or default_bag_name()).expanduser()
        self._lock = threading.Lock()
        self._writer = BagWriter(self.path, chunk_size=self.p('chunk_size'),
                                 chunk_span_s=self.p('chunk_span_s')).open()
        self._subs: dict[tuple[str, str], _Stream] = {}
        self._unrecordable: dict[tuple[str, str], str] = {}
        self.counts: dict[str, int] = {}
        self.create_steady_timer(self.p('discovery_period_s'), self._discover)
        self.create_steady_timer(self.p('flush_period_s'), self._flush)
        self.create_steady_timer(1.0, self._status)
        self.get_logger().info(f'recording {len(self._wanted)} topic(s) to {self.path}: '
                               f'{", ".join(self._wanted)}')
        self._discover()

    @property
    def not_recorded(self) -> dict[str, str]:
        """``'topic (type)'`` -> why, for every publisher type the bag does not hold."""
        return {f'{t} ({m})': why for (t, m), why in self._unrecordable.items()}

    @property
    def subscribed(self) -> list[str]:
        """Topics subscribed so far."""
        return list(dict.fromkeys(topic for topic, _ in self._subs))

    def _discover(self, recheck: bool = False) -> None:
        """Subscribe to every type a wanted topic carries; with ``recheck``, follow its QoS.

        A topic is recorded in every type its publishers offer (each its own
        connection in the bag), and its subscription follows the publishers'
        QoS: a best-effort publisher joining a reliable one makes the
        subscription best effort, else its messages would not arrive.
        """
        if self._writer is None:
            return
        pending = [t for t in self._wanted if t not in self.counts]
        if not pending and not recheck:
            return
        graph = dict(self.get_topic_names_and_types())
        for topic in (self._wanted if recheck else pending):
            types = [m for m in graph.get(topic, []) if (topic, m) not in self._unrecordable]
            if not types:
                continue
            infos = self.get_publishers_info_by_topic(topic)
            for msgtype in types:
                mine = [i for i in infos if i.topic_type == msgtype]
                if not mine:
                    continue
                if (topic, msgtype) in self._subs:
                    self._follow_qos(topic, msgtype, mine)
                else:
                    self._subscribe(topic, msgtype, mine)

    def _subscribe(self, topic: str, msgtype: str, infos: list) -> None:
        first = next((m for t, m in self._subs if t == topic), None)
        stream = _Stream(topic if first is None else f'{topic}\0{msgtype}')
        try:
            cls = message_class(msgtype)
            with self._lock:
                self._writer.add_topic(topic, msgtype, [_offered(i.qos_profile) for i in infos],
                                       key=stream.writer_key)
        except (ConfigError, ValueError) as exc:
            self._unrecordable[(topic, msgtype)] = str(exc)
            self.get_logger().error(f'cannot record {topic} ({msgtype}): {exc}')
            return
        try:
            self._make_subscription(topic, stream, cls, _qos_for(infos))
        except RuntimeError as exc:     # Fast DDS: one type per topic in a process
            why = (f'this middleware takes one type per topic in a process; recording {first}'
                   if first is not None else first_line(exc))
            self._unrecordable[(topic, msgtype)] = why
            self.get_logger().error(f'{topic} carries several types: its {msgtype} messages '
                                    f'are NOT recorded ({why})')
            return
        self._subs[(topic, msgtype)] = stream
        self.counts.setdefault(topic, 0)
        self.get_logger().info(f'recording {topic} ({msgtype}, '
                               f'{stream.qos.reliability.name.lower()})')

    def _make_subscription(self, topic: str, stream: _Stream, cls: Any,
                           qos: QoSProfile) -> None:
        """(Re)subscribe; the old subscription goes after the new one is up (no gap)."""
        old = stream.sub
        stream.sub = self.create_subscription(
            cls, topic, lambda data, info: self._on_message(topic, stream, data, info), qos,
            raw=True)
        stream.qos = qos
        if old is not None:     # both deliver for a moment: drop repeats for 2 s
            stream.repeats_until_ns = time.monotonic_ns() + 2 * 10**9
            self.destroy_subscription(old)

    def _follow_qos(self, topic: str, msgtype: str, infos: list) -> None:
        want = _qos_for(infos)
        have = self._subs[(topic, msgtype)].qos
        if (want.reliability, want.durability) == (have.reliability, have.durability):
            return
        self.get_logger().warning(
            f'{topic}: its publishers now offer {want.reliability.name.lower()}, '
            f'{want.durability.name.lower()}; subscribing again so that every one is recorded')
        self._make_subscription(topic, self._subs[(topic, msgtype)], message_class(msgtype),
                                want)

    def _on_message(self, topic: str, stream: _Stream, data: bytes, info: dict) -> None:
        if stream.repeat(info.get('source_timestamp'), data):
            return
        t_ns = source_time_ns(self, info)
        with self._lock:
            if self._writer is None:
                return
            self._writer.write(stream.writer_key, t_ns, data)
            self.counts[topic] += 1

    def _flush(self) -> None:
        with self._lock:
            if self._writer is not None:
                self._writer.flush()

    def _status(self) -> None:
        self._discover(recheck=True)
        total = sum(self.counts.values())
        missing = [t for t in self._wanted if t not in self.counts]
        text = f'recording to {self.path}: {total} messages'
        text += f'; waiting for {", ".join(missing)}' if missing else ''
        text += ''.join(f'; NOT recorded: {k}: {why}' for k, why in self.not_recorded.items())
        level = 2 if self._unrecordable else 1 if missing else 0
        self.publish_diagnostics(level, text, {'messages': total, 'path': str(self.path)})

    def close(self) -> None:
        """Finalise the bag (summary, metadata.yaml); idempotent."""
        if not hasattr(self, '_writer'):    # __init__ failed before the bag was opened
            return
        with self._lock:
            writer, self._writer = self._writer, None
        if writer is not None:
            writer.close()
            total = sum(self.counts.values())
            detail = ', '.join(f'{t} {n}' for t, n in self.counts.items())
            # after SIGTERM the context (and the node's /rosout publisher) is gone: log
            # through a logger that is not bound to /rosout
            logger = self.get_logger() if self.context.ok() else rclpy.logging.get_logger(
                f'{self.get_name()}.bag')
            logger.info(f'closed {self.path}: {total} messages ({detail})')

    def destroy_node(self) -> None:
        """Close the bag, then the node."""
        try:
            self.close()
        finally:
            super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Record until Ctrl-C / SIGTERM, then finalise the bag."""
    return spin_node(Recorder, 'recorder', args)


if __name__ == '__main__':
    raise SystemExit(main())
