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

"""Read a :class:`~hyst_id.io.recording.Recording` from a delimited text file (CSV, TSV).

Files are taken as they are: duplicate or decreasing timestamps are
reported by validation, never repaired.
"""

from __future__ import annotations

from collections.abc import Sequence
import math
from pathlib import Path
import re

import numpy as np

from hyst_id.errors import ConfigError, MissingTopicError, RecordingError
from hyst_id.io.recording import Recording

__all__ = ['CSV_SUFFIXES', 'DEFAULT_COLUMNS', 'TIME_UNIT_NOTE', 'read_csv', 'time_unit_hint',
           'time_unit_notes']

#: File suffixes read as delimited text.
CSV_SUFFIXES = ('.csv', '.txt', '.tsv')
#: Header names read by default: time in seconds, command, measurement.
DEFAULT_COLUMNS = ('t', 'command', 'measurement')
#: First words of the note :func:`time_unit_hint` adds (the CLI prints it).
TIME_UNIT_NOTE = 'time unit:'
# header words naming a time unit other than seconds, and the factor to seconds
_TIME_UNITS = (('ms|msec|millis|milliseconds?', 1e-3), ('us|usec|µs|micros|microseconds?', 1e-6),
               ('ns|nsec|nanos|nanoseconds?', 1e-9), ('min|minutes?', 60.0))
# header words of a sample counter, which has no unit to doubt
_COUNTER_WORDS = frozenset({'index', 'idx', 'sample', 'samples', 'n', 'k', 'step'})
#: A median sample interval from which seconds are doubtful for an actuator record.
_SLOW_INTERVAL_S = 0.5


def time_unit_notes(notes: Sequence[str]) -> list[str]:
    """The :func:`time_unit_hint` notes among a recording's ``notes``, without their tag."""
    return [n[len(TIME_UNIT_NOTE):].strip() for n in notes if str(n).startswith(TIME_UNIT_NOTE)]


def time_unit_hint(label: str, t: np.ndarray) -> str | None:
    """Why the time column ``label`` (read as seconds) may be in another unit, or None.

    The header's words decide when they name a unit (``t_ms``, ``time [us]``);
    a header with none (or a column index) is doubted when the median interval is at
    least 0.5 s, slow for an actuator record; a counter (``index``,
    ``sample``) stepping by one is a sample count, with no period. The words end
    with the ``--time-scale`` to give.
    """
    words = re.split(r'[^a-zµ]+', label.lower())
    if any(w in _COUNTER_WORDS for w in words):
        steps = np.diff(t[np.isfinite(t)])
        if steps.size and float(np.median(steps)) == 1.0:
            return (f'{TIME_UNIT_NOTE} the time column {label!r} counts samples and is read '
                    'as seconds (one sample = 1 s); give --time-scale with the sample period '
                    'in seconds (0.001 at 1 kHz) unless the time does not matter')
        return None
    for pattern, factor in _TIME_UNITS:
        if any(re.fullmatch(pattern, w) for w in words):
            return (f'{TIME_UNIT_NOTE} the time column {label!r} reads like '
                    f'{pattern.split("|")[0]}, but is read as seconds; if so, give '
                    f'--time-scale {factor:g}')
    steps = np.diff(t[np.isfinite(t)])
    steps = steps[steps > 0]
    if steps.size and float(np.median(steps)) >= _SLOW_INTERVAL_S \
            and not any(w in ('s', 'sec', 'secs', 'seconds', 'second') for w in words):
        return (f'{TIME_UNIT_NOTE} the time column {label!r} is read as seconds: a median '
                f'sample interval of {float(np.median(steps)):g} s; if it holds '
                'milliseconds, give --time-scale 0.001')
    return None


def _number(cell: str, decimal_comma: bool) -> float | None:
    """The cell's value, or None; ``1,5`` is 1.5 when cells are not comma-separated."""
    try:
        return float(cell)
    except ValueError:
        pass
    if decimal_comma and cell.count(',') == 1 and '.' not in cell:
        try:
            return float(cell.replace(',', '.'))
        except ValueError:
            return None
    return None


#: Header names that say a column is the measurement but not what was measured.
_GENERIC_MEASUREMENT = frozenset({'measurement', 'measured', 'meas', 'y', 'output', 'out',
                                  'response', 'value', 'signal', 'data', 'reading', 'sensor'})


def _signal_name(label: str) -> str:
    """The header's name for the measurement, or '' for a generic one (``measurement``)."""
    return '' if label.strip().lower() in _GENERIC_MEASUREMENT else label


def _name_and_unit(label: str) -> tuple[str, str]:
    """``'pos [um]'`` -> ``('pos', 'um')``; a label without a bracketed unit -> ``(label, '')``."""
    m = re.fullmatch(r'(.*?)\s*[\[(]([^\[\]()]+)[\])]\s*', label)
    return (m.group(1), m.group(2).strip()) if m and m.group(1) else (label, '')


def _unit_of(cell: str) -> str:
    """A unit row's cell without its brackets (``[mm]``, ``(V)``)."""
    return cell.strip().strip('[]()').strip()


def _decoded(raw: bytes) -> tuple[str, str]:
    """A CSV file's text and its encoding: UTF-8, UTF-16 with its BOM, else Latin-1.

    Spreadsheets save "Unicode text" as UTF-16 and older tools write Latin-1
    (a ``µm`` unit in the header); the numbers are ASCII in all three.
    """
    if raw[:2] in (b'\xff\xfe', b'\xfe\xff'):
        return raw.decode('utf-16'), 'UTF-16'
    try:
        return raw.decode('utf-8-sig'), 'utf-8'
    except UnicodeDecodeError:
        return raw.decode('latin-1'), 'Latin-1'


def read_csv(path: str | Path, channel: str, *,
             columns: Sequence[str | int] = DEFAULT_COLUMNS, time_scale: float | None = 1.0,
             delimiter: str | None = None, command_unit: str = '',
             measurement_unit: str = '') -> Recording:
    """Read a recording from delimited text, without validating or reordering it.

    Parameters
    ----------
    path : str or pathlib.Path
        The file. Blank lines and lines starting with ``#`` are skipped; the
        first other line is a header if any of its cells is not a number. A
        row under the header with no number in it is a unit row (``[s];[V];[um]``):
        its units fill ``command_unit`` / ``measurement_unit`` when not given,
        and the time column's is read by :func:`time_unit_hint`. Where cells are
        not comma-separated a decimal comma is read (``0,25`` is 0.25).
    channel : str
        Measured channel stored in the recording.
    columns : sequence of str or int
        Time, command and measurement columns: header names, or 0-based
        indices (needed for headerless files).
    time_scale : float or None
        Factor turning the time column into seconds (0.001 for ms). None
        reads seconds and adds a :func:`time_unit_hint` note when the
        column looks like another unit.
    delimiter : str, optional
        Cell separator; default a tab if the first line has one, else a
        semicolon, else a comma, else runs of whitespace.
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
    given_scale = time_scale is not None
    time_scale = 1.0 if time_scale is None else time_scale
    if not (isinstance(time_scale, (int, float)) and math.isfinite(time_scale)
            and time_scale > 0):
        raise ConfigError(f'time_scale must be a positive number, got {time_scale!r}')
    try:
        text, encoding = _decoded(path.read_bytes())
    except (OSError, UnicodeDecodeError) as exc:
        raise RecordingError(f'cannot read {path}: {exc}') from None
    lines = [(n, line) for n, line in enumerate(text.splitlines(), 1)
             if line.strip() and not line.lstrip().startswith('#')]
    if not lines:
        raise RecordingError(f'empty file: {path}')
    sep = delimiter
    if sep is None:
        first_line = lines[0][1]     # a tab or ';' first: their cells may hold decimal commas
        sep = next((c for c in ('\t', ';', ',') if c in first_line), None)

    def split(line: str) -> list[str]:
        return [c.strip().strip('"\'') for c in (line.split(sep) if sep else line.split())]

    comma = sep != ','      # a decimal comma (``0,25``) where cells are not comma-separated
    first = split(lines[0][1])
    names = first if not all(_number(c, comma) is not None for c in first) else None
    rows = lines[1:] if names is not None else lines
    unit_row = None
    second = split(rows[0][1]) if names is not None and rows else []
    if len(second) == len(first) and all(_number(c, comma) is None for c in second if c):
        unit_row = [_unit_of(c) for c in second]    # ``[s];[V];[um]`` under a header
        rows = rows[1:]
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
            if names.count(col) > 1:      # the first had been taken without a word
                at = [i for i, n in enumerate(names) if n == col]
                raise RecordingError(f'{path}: the header names {len(at)} columns {col!r} '
                                     f'(indices {at}): rename them, or give the column by '
                                     'its index')
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
            value = _number(cells[i], comma)
            if value is None:
                raise RecordingError(f'non-numeric value {cells[i]!r} in column {labels[j]} '
                                     f'at line {lineno} of {path}')
            data[r, j] = value
    for j, label in enumerate(labels):      # named as the file names it, at its line
        bad = ~np.isfinite(data[:, j])
        if bad.any():
            first = int(np.argmax(bad))
            raise RecordingError(f'column {label} of {path} has {int(bad.sum())} NaN/inf '
                                 f'values (first {data[first, j]} at line {rows[first][0]})')
    note = (f'columns: t_s = {labels[0]} x {time_scale:g}, command = {labels[1]}, '
            f'measurement = {labels[2]}')
    if encoding != 'utf-8':
        note += f'; read as {encoding} text (not UTF-8)'
    row_units = [unit_row[i] for i in index] if unit_row else ['', '', '']
    if unit_row:
        note += f'; units from the row under the header: {", ".join(row_units)}'
    named = [_name_and_unit(label) for label in labels]     # ``pos [um]``: pos in um
    units = [u or n[1] for u, n in zip(row_units, named)]
    command_unit, measurement_unit = command_unit or units[1], measurement_unit or units[2]
    time_label = f'{labels[0]} [{row_units[0]}]' if row_units[0] else labels[0]
    hint = None if given_scale else time_unit_hint(time_label, data[:, 0])
    return Recording(t_s=data[:, 0] * float(time_scale), command=data[:, 1],
                     measurement=data[:, 2], channel=channel, command_unit=command_unit,
                     measurement_unit=measurement_unit, source=str(path),
                     notes=(note,) + ((hint,) if hint else ()),
                     command_name=named[1][0] if names else '',
                     measurement_name=_signal_name(named[2][0]) if names else '')
