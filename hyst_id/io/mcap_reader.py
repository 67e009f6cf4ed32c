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

"""Read a :class:`~hyst_id.io.recording.Recording` from a rosbag2 MCAP bag.

A bag holds two message streams that the reader pairs
(:func:`hyst_id.io.streams.pair_streams`): the measurement samples are the
time base and each gets the last command at or before its stamp (the DAC
holds a command until the next one); out-of-order stamps are sorted and
duplicate stamps dropped, each with a note in ``Recording.notes``.

Memory: messages are decoded one at a time (the bag is never loaded whole)
and their stamps and values go into typed buffers (:class:`array.array`,
8 bytes a number, where a list of Python numbers costs about 32), handed to
numpy without a copy; ``bench/bag_memory.py`` prints the peak against the
size of the arrays read.
"""

from __future__ import annotations

from array import array
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from hyst_id.errors import RecordingError
from hyst_id.io.bag import open_bag
from hyst_id.io.recording import Recording
from hyst_id.io.streams import pair_streams
from hyst_id.io.topics import get_field, parse_field_path, TopicConfig

__all__ = ['JUMP_BACK_INTERVALS', 'JUMP_BACK_MIN_S', 'read_mcap']

#: Header stamps of one topic that go back, in the bag's order, by more than this many median
#: intervals (and :data:`JUMP_BACK_MIN_S`) are a clock set back, not messages out of order:
#: sorting them would interleave two stretches of the run. An independent reviewer's bag
#: (stamps set back 5 s from message 600 of 1200) was sorted, lost 50 samples as duplicate
#: stamps and was identified at 137 x the floor, the physics blamed.
JUMP_BACK_INTERVALS = 20.0
#: ... and by more than this many seconds (a transport's jitter on a fast topic is not a jump).
JUMP_BACK_MIN_S = 0.1


def _collect(bag: Any, cfg: TopicConfig) -> dict[str, tuple[array, array, array]]:
    """Stamps, values and log times of the command and measurement topics (typed buffers)."""
    spec = {cfg.command_topic: (parse_field_path(cfg.command_field), cfg.command_field,
                                cfg.command_type),
            cfg.measurement_topic: (parse_field_path(cfg.measurement_field),
                                    cfg.measurement_field, cfg.measurement_type)}
    out: dict[str, tuple[array, array, array]] = {
        t: (array('q'), array('d'), array('q')) for t in spec}
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


def _refuse_jump_back(t_ns: np.ndarray, topic: str, path: str | Path) -> None:
    """Raise when a topic's stamps, in the bag's order, go back by a clock jump.

    A message or two out of order is sorted (:func:`hyst_id.io.streams.tidy_stream`); a
    stretch whose stamps run behind the ones recorded before it by more than
    :data:`JUMP_BACK_INTERVALS` median intervals and :data:`JUMP_BACK_MIN_S` has no order
    that its stamps could restore.
    """
    if t_ns.size < 3 or not (np.diff(t_ns) < 0).any():
        return
    behind = np.maximum.accumulate(t_ns) - t_ns
    steps = np.diff(np.unique(t_ns))
    median = float(np.median(steps)) if steps.size else 0.0
    limit = max(JUMP_BACK_INTERVALS * median, JUMP_BACK_MIN_S * 1e9)
    if median <= 0.0 or float(behind.max()) <= limit:
        return
    first = int(np.argmax(behind > limit))
    k = int(np.argmax(behind))
    raise RecordingError(
        f'{topic} in {path}: the header stamps jump back by {behind[k] / 1e9:.3g} s '
        f'({behind[k] / median:.0f} median intervals) at message {first} of {t_ns.size}, '
        "in the bag's order: a clock that was reset or changed its source, not messages out "
        'of order; sorting by stamp would interleave two stretches of the run. Split the '
        "recording there, or take the stamps from the bag's log time (stamp_source: log "
        'among the topics of the params file, --params)')


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
        t_ns = np.frombuffer(stamps, dtype=np.int64)
        if (t_ns == 0).any():
            notes.append(f'{topic}: {int((t_ns == 0).sum())} messages without header.stamp; '
                         f'used log times for the whole topic')
            t_ns = np.frombuffer(log_ns, dtype=np.int64)
        else:
            _refuse_jump_back(t_ns, topic, path)
        arrays[topic] = (t_ns, np.frombuffer(values, dtype=np.float64))
    cmd_t, cmd_v = arrays[cfg.command_topic]
    meas_t, meas_v = arrays[cfg.measurement_topic]
    return pair_streams(cmd_t, cmd_v, meas_t, meas_v, channel,
                        source=f'{path} ({cfg.command_topic}, {cfg.measurement_topic})',
                        units=(cfg.command_unit, cfg.measurement_unit),
                        names=(cfg.command_topic, cfg.measurement_topic), notes=notes)
