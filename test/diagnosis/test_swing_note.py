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

"""The note that a command whose swing trends with time confounds time gains and level shapes."""

from __future__ import annotations

import numpy as np
import pytest

from hyst_id.diagnosis.split_notes import swing_note

T = np.arange(0, 100, 0.05)
DECAYING = 150 * np.exp(-0.01 * T) * np.sin(2 * np.pi * T / 10)


@pytest.mark.parametrize('named', [['static_nonlinearity'], ['gain_loss', 'dead_time'],
                                   ['loop_shape', 'supply_decay']])
def test_a_decaying_sine_confounds_time_and_level(named):
    (note,) = swing_note(T, DECAYING, named)
    assert 'falls steadily' in note and 'rank correlation with time -1.00' in note
    assert all(n in note for n in named if n != 'dead_time')


def test_a_growing_swing_is_said_to_grow():
    (note,) = swing_note(T, DECAYING[::-1].copy(), ['gain_drift'])
    assert 'grows steadily' in note and '+1.00' in note


@pytest.mark.parametrize('named', [['dead_time'], ['offset_drift', 'creep'], []])
def test_no_note_when_nothing_named_depends_on_time_or_level(named):
    assert swing_note(T, DECAYING, named) == []


def test_no_note_on_swings_that_come_back():
    """Amplitude swinging up and down over the run (the gain tests' excitation)."""
    v = 9 + 3 * np.sin(2 * np.pi * T / 10) * (0.7 + 0.3 * np.sin(2 * np.pi * T / 47))
    assert swing_note(T, v, ['gain_drift', 'static_nonlinearity']) == []


@pytest.mark.filterwarnings('error')
def test_no_note_and_no_warning_on_equal_swings():
    """A triangle wave: every swing the same, so no rank correlation (scipy would warn)."""
    v = 2 * np.abs(((T / 5) % 2) - 1) - 1
    assert swing_note(T, v, ['static_nonlinearity']) == []


def test_no_note_on_too_few_swings():
    t = np.arange(0, 30, 0.05)
    v = np.exp(-0.05 * t) * np.sin(2 * np.pi * t / 10)       # six reversals
    assert swing_note(t, v, ['static_nonlinearity']) == []


@pytest.mark.slow
def test_a_diagnosis_on_a_decaying_sine_carries_the_note():
    """The note reaches the report: a gain falling over the paper's decaying sine.

    The reference simulator's chain (``test_gain_loss``'s) under the decaying 10 s sine;
    only ``gain_loss`` is offered, so the finding is a time gain whatever else might win.
    """
    from reference_sim import backlash, hysteresis

    from hyst_id.diagnosis import diagnose, DiagnoseSettings
    from hyst_id.io.recording import Recording
    t = np.arange(2400) * 0.05
    v = 9.0 + 3.0 * np.exp(-t / 80.0) * np.sin(2 * np.pi * t / 10.0)
    y0 = backlash(hysteresis(v, 1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0), 1.0,
                  -0.15, 0.15)
    y = 40.0 * (1.0 - 0.0015 * t) * (y0 - 4.0) + 100.0
    y = y + np.random.default_rng(3).normal(0, 0.004 * np.ptp(y), t.size)
    d = diagnose(Recording(t, v, y, 'position', 'mA', 'um', 'decaying sine, gain loss'),
                 settings=DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=1,
                                           hops=20, mechanisms=('gain_loss',)))
    assert d.verdict == 'gain_loss', d.report()
    assert any("command's swing falls steadily" in n for n in d.notes), d.notes
    assert "command's swing falls steadily" in d.report()
