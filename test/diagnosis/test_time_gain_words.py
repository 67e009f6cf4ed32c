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

"""The words of a gain that changes in time say which way the readings move.

A new user's gain growing about a zero above the travel lowered every reading,
and the report said "the same travel gives a larger reading later"; the fitted
zero (``b1``, the reading the gain leaves unchanged) was only in the JSON.
"""

from __future__ import annotations

import numpy as np
import pytest

from hyst_id.diagnosis.mechanisms import Context, get_mechanisms

__all__: list[str] = []

T = np.arange(0.0, 100.0, 0.05)
INFO = {'coef': np.array([2.0, -30.0, 128.0]), 'labels': ['gain_drift:0', 'gain', 'offset']}


@pytest.mark.parametrize('mid, channel, grows', [('gain_drift', 'position', True),
                                                 ('gain_loss', 'position', False),
                                                 ('supply_decay', 'pressure', False)])
def test_the_unchanged_reading_is_a_fitted_value_and_the_words_follow_it(mid, channel, grows):
    """The zero is printed with the block, and the words say readings move about it."""
    m = get_mechanisms((mid,), channel=channel)[0]
    ctx = Context(channel, T, 1400)
    values = m.describe(np.array([1e-3]), INFO['coef'], INFO, ctx)
    assert values['unchanged_reading'].value == pytest.approx(128.0)
    text = m.explain(values, None, ctx)
    assert 'about the reading 128' in text
    up, down = ('rise', 'fall') if grows else ('fall', 'rise')
    assert f'readings above it {up} over the run, readings below it {down}' in text


@pytest.mark.parametrize('middle, doubted', [(100.0, True), (150.0, False), (None, False)])
def test_a_supply_decay_whose_readings_rise_says_so(middle, doubted):
    """Unchanged reading 128 above the readings' middle: a judgement call in the words."""
    m = get_mechanisms(('supply_decay',), channel='pressure')[0]
    ctx = Context('pressure', T, 1400)
    info = dict(INFO) if middle is None else {**INFO, 'readings_median': middle}
    values = m.describe(np.array([1e-3]), INFO['coef'], info, ctx)
    text = m.explain(values, None, ctx)
    assert ('middle_reading' in values) is doubted
    assert ('so most readings would rise as the supply runs down' in text) is doubted
    if doubted:
        assert values['middle_reading'].value == 100.0
        assert 'a judgement call against a gain growing or an offset drifting' in text


@pytest.mark.parametrize('middle', [100.0, 127.9, 128.1, 150.0])
def test_the_doubt_and_the_words_read_the_same_middle(middle):
    """The tie-break's doubt and the report's words judge one median: the measurement's.

    The doubt (``trial.judge``) had read the training measurement's median and the
    words (``driver._info``) the fitted prediction's: near the unchanged reading
    the report could state a judgement call the tie-break had not made, or the reverse.
    """
    m = get_mechanisms(('supply_decay',), channel='pressure')[0]
    readings = np.full(1400, middle)
    ctx = Context('pressure', T, 1400)
    info = {**INFO, 'readings_median': float(np.median(readings))}
    values = m.describe(np.array([1e-3]), INFO['coef'], info, ctx)
    doubt = m.doubt(np.array([1e-3]), INFO['coef'], INFO['labels'], readings)
    assert bool(doubt) is ('middle_reading' in values) is (middle < 128.0)
