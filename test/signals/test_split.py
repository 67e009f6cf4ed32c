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

"""The train / held-out split and the held-out rows blocks are judged on."""

from __future__ import annotations

import numpy as np
import pytest

from hyst_id.errors import ConfigError
from hyst_id.signals.split import inside_rows, split_index


def test_split_is_by_duration_not_by_samples():
    t = np.concatenate([np.arange(100) * 0.01, 1.0 + np.arange(100) * 0.1])
    n = split_index(t, 0.5)
    assert t[n - 1] < 0.5 * t[-1] + t[0] <= t[n]
    with pytest.raises(ConfigError):
        split_index(t, 1.0)


def test_judged_rows_stop_where_the_command_first_leaves_the_training_range():
    v = np.concatenate([np.linspace(0, 10, 700), np.linspace(10, 2, 150),
                        np.linspace(2, 12, 100), np.linspace(12, 5, 50)])
    rows = inside_rows(v, 700)
    first_out = 700 + int(np.flatnonzero(v[700:] > 10.2)[0])
    assert rows[0] == 700 and rows[-1] == first_out - 1
    assert np.all(v[rows] <= 10.2)


def test_all_held_out_rows_when_the_command_stays_inside_or_leaves_at_once():
    v = np.concatenate([np.linspace(0, 10, 700), np.linspace(10, 0, 300)])
    assert np.array_equal(inside_rows(v, 700), np.arange(700, 1000))
    # out after 10 held-out samples: under a tenth, so nothing better than all of them
    w = np.concatenate([np.linspace(0, 10, 700), np.full(10, 5.0), np.full(290, 11.0)])
    assert np.array_equal(inside_rows(w, 700), np.arange(700, 1000))
    # a small overshoot (under 2 % of the range) is not an excursion
    u = np.concatenate([np.linspace(0, 10, 700), np.full(300, 10.15)])
    assert inside_rows(u, 700).size == 300


def test_level_excursion_finds_a_held_out_plateau_the_training_part_never_reached():
    """The command stays inside, the response rises to a plateau only after the split."""
    from hyst_id.diagnosis.split_notes import level_note
    from hyst_id.signals.split import level_excursion
    t = np.linspace(0.0, 20.0, 2000)
    rng = np.random.default_rng(1)
    climbing = (np.clip(2.0 * (t - 14.0), 0.0, 1.0) * 0.5 + 0.05 * np.sin(2 * np.pi * t)
                + rng.normal(0, 1e-3, t.size))      # up to a plateau half a second after 14 s
    share, lo, hi, lo_h, hi_h = level_excursion(climbing, 1400)
    assert share > 0.5 and hi_h > hi and lo < lo_h
    assert level_note(climbing, 1400)[0].startswith(f'{100 * share:.0f} % of the held-out')
    steady = 0.05 * np.sin(2 * np.pi * t) + rng.normal(0, 1e-3, t.size)
    assert level_excursion(steady, 1400)[0] == 0.0 and level_note(steady, 1400) == []
    assert level_excursion(steady, steady.size)[0] == 0.0          # nothing held out
