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

"""``gain_loss`` on recordings from the independent reference simulator.

The new-user trial's case: a position (force) reading whose sensitivity fell
30 % over the run was named ``creep`` and later ``static_nonlinearity``: no
block took a falling gain on the position channel. A steady gain claims none
(``test_gain_drift.test_a_steady_gain_claims_no_drift``).
"""

from __future__ import annotations

import numpy as np
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.compensation.augment import Augmentation
from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.export import compensator_set
from hyst_id.diagnosis.mechanisms.base import Context
from hyst_id.diagnosis.mechanisms.registry import get_mechanisms, MECHANISMS
from hyst_id.errors import ConfigError
from hyst_id.io.recording import Recording

#: One GAASS seed and one round, as ``test_gain_drift``.
SETTINGS = DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=1, hops=20)


def _recording(seed: int, loss_per_s: float) -> Recording:
    rng = np.random.default_rng([seed, 17])
    t = np.arange(2400) * 0.05
    v = 9.0 + 3.0 * np.sin(2 * np.pi * t / 10.0) * (0.7 + 0.3 * np.sin(2 * np.pi * t / 47.0))
    y0 = backlash(hysteresis(v, 1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0), 1.0,
                  -0.15, 0.15)
    y = 40.0 * (1.0 - loss_per_s * t) * (y0 - 4.0) + 100.0    # pivot inside the travel
    return Recording(t, v, y + rng.normal(0, 0.004 * np.ptp(y), t.size), 'position', 'mA',
                     'um', f'gain loss #{seed}')


@pytest.mark.slow
@pytest.mark.parametrize('seed', [0, pytest.param(1, marks=pytest.mark.thorough)])
def test_a_falling_gain_on_position_is_gain_loss(seed):
    d = diagnose(_recording(seed, 0.0015), settings=SETTINGS)
    assert d.verdict == 'gain_loss', [f.mechanism for f in d.findings]
    # measured (seeds 0-3): loss 0.150-0.152 %/s, final 1.02-1.07 x the floor
    loss = d.findings[0].params['loss_percent_per_s'].value
    assert loss == pytest.approx(0.15, rel=0.05)
    assert d.final.er_holdout_percent < 1.2 * d.noise_floor_percent
    _, aug, applied = compensator_set(d)
    assert 'gain_loss' in {m for m, _ in applied}
    assert aug.gain_law == 'linear' and aug.gain_rate_per_s < 0.0
    assert aug.gain(100.0) < aug.gain(0.0)


def test_gain_loss_acts_on_position_only():
    assert 'gain_loss' in {m.id for m in get_mechanisms(channel='position')}
    for channel in ('pressure', 'flow'):
        assert 'gain_loss' not in {m.id for m in get_mechanisms(channel=channel)}
        with pytest.raises(ConfigError, match='gain_loss cannot act on the'):
            get_mechanisms(['gain_loss'], channel=channel)


def test_the_compensator_schedules_a_falling_gain():
    """The in-line correction is the linear law with a negative rate: the gain falls."""
    m = MECHANISMS['gain_loss']
    t = np.arange(2400) * 0.05
    ctx = Context('position', t, 1680)
    info = {'coef': [40.0, -160.0, 100.0], 'labels': ['sensor', 'gain_loss:0', 'offset']}
    corr = m.correction(np.array([0.0015]), None, info, ctx)
    assert corr['augment.gain_law'] == 'linear'
    assert corr['augment.gain_rate_per_s'] == pytest.approx(-0.0015)
    aug = Augmentation(gain_law='linear', gain_rate_per_s=corr['augment.gain_rate_per_s'],
                       schedule_horizon_s=120.0)
    assert aug.gain(0.0) == pytest.approx(1.0)
    assert aug.gain(100.0) == pytest.approx(0.85)


def test_a_loss_at_the_slowest_end_is_an_offset_ramp():
    m = MECHANISMS['gain_loss']
    t = np.arange(2400) * 0.05
    ctx = Context('position', t, 1680)
    slowest = float(m.bounds(ctx)[0, 0])
    coef, span = np.array([40.0, 900.0, 100.0]), (0.0, 12.0)
    assert 'offset drift' in m.implausible(np.array([slowest]), coef, span, 0.01, ctx)
    assert m.implausible(np.array([1.2 * slowest]), coef, span, 0.01, ctx) == ''
    # at the fastest loss the gain still holds 14 % at the end of a 70/30 split's record
    fastest = float(m.bounds(ctx)[0, 1])
    assert m.gain(fastest, np.array([t[-1] - t[0]]))[0] == pytest.approx(1 - 0.6 / 0.7, abs=0.01)
