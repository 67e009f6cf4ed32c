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

"""Collect a live run's command and measurement samples and turn them into a Recording.

:class:`SampleBuffer` keeps the two streams (stamps in ns) of the current
run; :meth:`SampleBuffer.recording` pairs them exactly as the bag reader
does (:func:`hyst_id.io.streams.pair_streams`).
"""

from __future__ import annotations

import bisect
from dataclasses import replace
import math
import time

import numpy as np

from hyst_id.io.recording import Recording
from hyst_id.io.streams import pair_streams

__all__ = ['SampleBuffer']


class SampleBuffer:
    """Command and measurement samples of the current run (stamps in ns).

    Samples may arrive in any order (they are sorted when the recording is
    built). At most ``max_samples`` of each stream are kept (the oldest are
    dropped, in blocks of a tenth). A NaN or infinite value is not kept (one
    bad reading would make the whole run unidentifiable): it is counted in
    :attr:`non_finite` and named in the recording's notes.
    """

    #: Samples before a window's bisected start that are also looked at (late arrivals).
    ORDER_MARGIN = 1000

    def __init__(self, max_samples: int = 2000000) -> None:
        self.max_samples = int(max_samples)
        self.clear()

    def clear(self) -> None:
        """Forget every sample."""
        self.cmd_t: list[int] = []
        self.cmd_v: list[float] = []
        self.meas_t: list[int] = []
        self.meas_v: list[float] = []
        self.last_rx: float | None = None
        #: Samples of each stream dropped on arrival for a NaN or infinite value.
        self.non_finite = {'command': 0, 'measurement': 0}

    def add_command(self, t_ns: int, value: float) -> bool:
        """Append a command sample; False (not kept, counted) for a NaN or infinite value."""
        if not math.isfinite(value):
            self.non_finite['command'] += 1
            return False
        self.cmd_t.append(int(t_ns))
        self.cmd_v.append(float(value))
        self._trim(self.cmd_t, self.cmd_v)
        return True

    def add_measurement(self, t_ns: int, value: float) -> bool:
        """Append a measurement sample; False (not kept, counted) for a NaN or infinite value."""
        self.last_rx = time.monotonic()
        if not math.isfinite(value):
            self.non_finite['measurement'] += 1
            return False
        self.meas_t.append(int(t_ns))
        self.meas_v.append(float(value))
        self._trim(self.meas_t, self.meas_v)
        return True

    @property
    def non_finite_note(self) -> str:
        """Words for the samples dropped for a NaN or infinite value ('' when none)."""
        dropped = [f'{n} {stream}' for stream, n in self.non_finite.items() if n]
        return (f'{" and ".join(dropped)} sample(s) with a NaN or infinite value were not '
                'collected' if dropped else '')

    def _trim(self, t: list, v: list) -> None:
        if len(t) > self.max_samples + self.max_samples // 10:
            del t[:len(t) - self.max_samples]
            del v[:len(v) - self.max_samples]

    @property
    def n_measurements(self) -> int:
        """Measurements collected."""
        return len(self.meas_t)

    @property
    def span_s(self) -> float:
        """Time from the first to the last measurement kept, seconds (0 when < 2).

        From the ends of the stream as it arrived (cheap; samples arrive
        nearly in order), not from a sort.
        """
        if len(self.meas_t) < 2:
            return 0.0
        return abs(self.meas_t[-1] - self.meas_t[0]) * 1e-9

    def recording(self, channel: str, source: str = '', units: tuple[str, str] = ('', ''),
                  names: tuple[str, str] = ('command', 'measurement'),
                  last_s: float | None = None) -> Recording:
        """The run so far as a Recording (see :func:`pair_streams`).

        With ``last_s`` only the measurements of the newest ``last_s`` seconds
        (and the commands from then on, with the one in effect at its start)
        are paired: a sliding window costs about its own length, not the
        whole buffer's (the streams arrive nearly in order, so the window's
        start is found by bisection and :data:`ORDER_MARGIN` samples before
        it are looked at too).
        """
        if last_s is not None and self.meas_t:
            newest = max(self.meas_t[-self.ORDER_MARGIN:])
            since = int(newest - last_s * 1e9)
            m0 = max(bisect.bisect_left(self.meas_t, since) - self.ORDER_MARGIN, 0)
            c0 = max(bisect.bisect_left(self.cmd_t, since) - self.ORDER_MARGIN, 0)
            ct, cv = np.array(self.cmd_t[c0:], dtype=np.int64), np.array(self.cmd_v[c0:])
            mt, mv = np.array(self.meas_t[m0:], dtype=np.int64), np.array(self.meas_v[m0:])
        else:
            ct, cv = np.array(self.cmd_t, dtype=np.int64), np.array(self.cmd_v)
            mt, mv = np.array(self.meas_t, dtype=np.int64), np.array(self.meas_v)
        if last_s is not None and mt.size:
            keep = mt >= since
            mt, mv = mt[keep], mv[keep]
            lead = ct >= since
            before = np.flatnonzero(~lead)
            if before.size:                 # the command in effect when the window opens
                lead[before[np.argmax(ct[before])]] = True
            ct, cv = ct[lead], cv[lead]
        rec = pair_streams(ct, cv, mt, mv, channel, source, units, names)
        note = self.non_finite_note
        return replace(rec, notes=(*rec.notes, note)) if note else rec
