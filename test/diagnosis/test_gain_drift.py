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

"""``gain_drift`` on recordings from the independent reference simulator.

The issue's case: a sensitivity growing 0.08 %/s (as with temperature) was
named ``offset_drift`` with 3 x the floor left. A falling gain stays
``supply_decay``'s; a clean recording claims neither.
"""

from __future__ import annotations

import numpy as np
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.mechanisms.base import Context
from hyst_id.diagnosis.mechanisms.registry import MECHANISMS
from hyst_id.io.recording import Recording

pytestmark = pytest.mark.slow

#: One GAASS seed and one round (what ``test_diagnose.FAST`` uses): a single drift is
#: the first finding or none.
SETTINGS = DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=1,
                            hops=20)


def _recording(seed: int, gain_of_t, channel: str = 'position') -> Recording:
    rng = np.random.default_rng(seed)
    t = np.arange(2400) * 0.05
    v = 9.0 + 3.0 * np.sin(2 * np.pi * t / 10.0) * (0.7 + 0.3 * np.sin(2 * np.pi * t / 47.0))
    y0 = backlash(hysteresis(v, 1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0), 1.0,
                  -0.15, 0.15)
    y = 40.0 * gain_of_t(t) * y0 + 100.0           # a sensor in its own units
    return Recording(t, v, y + rng.normal(0, 0.004 * np.ptp(y), t.size), channel, 'mA',
                     'um', f'gain drift #{seed}')


@pytest.mark.parametrize('seed', [0, pytest.param(1, marks=pytest.mark.thorough)])
def test_a_growing_gain_is_gain_drift(seed):
    d = diagnose(_recording(seed, lambda t: 1.0 + 0.0008 * t), settings=SETTINGS)
    assert d.verdict == 'gain_drift', [f.mechanism for f in d.findings]
    growth = d.findings[0].params['growth_percent_per_s'].value
    assert growth == pytest.approx(0.08, rel=0.25)
    assert d.final.er_holdout_percent < 1.5 * d.noise_floor_percent


def test_a_falling_gain_stays_supply_decay():
    """Read as pressure: a supply reaches it (not the position reading, where it is not tried)."""
    d = diagnose(_recording(3, lambda t: np.exp(-t / 300.0), 'pressure'), settings=SETTINGS)
    assert d.verdict == 'supply_decay', [f.mechanism for f in d.findings]


def test_gain_drift_is_registered_with_words():
    m = MECHANISMS['gain_drift']
    assert m.names == ('growth_per_s',) and m.units == ('1/s',) and 'warm' in m.physics


def test_a_steady_gain_claims_no_drift():
    d = diagnose(_recording(5, lambda t: np.ones_like(t)), settings=SETTINGS)
    found = {f.mechanism for f in d.findings}
    assert not found & {'gain_drift', 'gain_loss', 'supply_decay', 'offset_drift'}, found


@pytest.mark.parametrize('mech', ['gain_drift', 'supply_decay'])
def test_a_rate_at_the_slowest_end_is_not_a_changing_gain(mech):
    """At its slowest rate the block is an offset ramp ``g(t) b0`` (probe 3 named one so)."""
    m = MECHANISMS[mech]
    t = np.arange(2400) * 0.05
    ctx = Context('pressure', t, 1680)
    slowest = float(m.bounds(ctx)[0, 0])
    coef, span = np.array([40.0, 900.0, 100.0]), (0.0, 12.0)
    assert 'offset drift' in m.implausible(np.array([slowest]), coef, span, 0.01, ctx)
    assert 'slowest end' in m.implausible(np.array([1.04 * slowest]), coef, span, 0.01, ctx)
    assert m.implausible(np.array([1.2 * slowest]), coef, span, 0.01, ctx) == ''
    assert m.implausible(np.array(m.starts(ctx)[0]), coef, span, 0.01, ctx) == ''
    assert m.implausible(np.array([slowest]), coef, span, 0.01) == ''     # no bounds known
