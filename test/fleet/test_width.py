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


"""The fleet's loop width against the independent reference simulator's loop."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.fleet.width import loop_width_command
from hyst_id.identification.chains import chain_spec

PAPER_H = (1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0)


def _reference_width(half_band: float, lo: float, hi: float) -> float:
    """The width of the reference's loop at mid level, read off a dense slow triangle."""
    up = np.linspace(lo, hi, 20001)
    v = np.concatenate([up, up[::-1], up, up[::-1]])
    y = backlash(hysteresis(v, *PAPER_H), 1.0, -half_band, half_band)
    n = up.size
    rising, falling = y[2 * n:3 * n], y[3 * n:][::-1]
    mid = 0.5 * (max(rising.min(), falling.min()) + min(rising.max(), falling.max()))
    return abs(float(up[np.argmax(falling >= mid)] - up[np.argmax(rising >= mid)]))


@pytest.mark.parametrize('half_band', [0.05, 0.15, 0.3])
def test_loop_width_is_the_reference_loops_width(half_band):
    """Position and pressure chains (the sensor settles in a quasi-static sweep) alike."""
    lo, hi = 7.0, 11.0
    want = _reference_width(half_band, lo, hi)
    for channel, sensor in (('position', ()), ('pressure', (0.8,))):
        ident = SimpleNamespace(spec=lambda channel=channel: chain_spec(channel),
                                x=np.array(PAPER_H + (1.0, -half_band, half_band) + sensor))
        got = loop_width_command(ident, (lo, hi))
        # the reference's width at one level, ours the median over the loop's middle half:
        # the paper's loop has near-parallel sides there
        assert got == pytest.approx(want, rel=0.03, abs=0.005), (channel, got, want)
    wider = SimpleNamespace(spec=lambda: chain_spec('position'),
                            x=np.array(PAPER_H + (1.0, -half_band - 0.05, half_band + 0.05)))
    assert loop_width_command(wider, (lo, hi)) == pytest.approx(
        loop_width_command(ident, (lo, hi)) + 0.1, abs=0.01)


def test_a_range_with_no_loop_gives_none():
    ident = SimpleNamespace(spec=lambda: chain_spec('position'),
                            x=np.array(PAPER_H + (1.0, -0.15, 0.15)))
    assert loop_width_command(ident, (9.0, 9.0)) is None
