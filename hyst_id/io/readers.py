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

:func:`read_recording` picks the reader from the path (:mod:`.csv_reader`,
:mod:`.mcap_reader`) and validates the result once.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from hyst_id.errors import ConfigError, RecordingError
from hyst_id.io.csv_reader import CSV_SUFFIXES, DEFAULT_COLUMNS, read_csv
from hyst_id.io.mcap_reader import read_mcap
from hyst_id.io.recording import CHANNELS, Recording, validate_recording
from hyst_id.io.topics import get_field, load_topic_config, parse_field_path, TopicConfig

# The readers and topic helpers keep their 0.1 import path here.
__all__ = ['CSV_SUFFIXES', 'DEFAULT_COLUMNS', 'TopicConfig', 'get_field', 'load_topic_config',
           'parse_field_path', 'read_csv', 'read_mcap', 'read_recording']


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
                       time_scale=time_scale,
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
