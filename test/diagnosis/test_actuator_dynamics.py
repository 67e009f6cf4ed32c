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

"""``actuator_dynamics`` on recordings from the independent reference simulator.

The issue's case: a second-order actuator (zeta 0.3, omega_n 2.5 rad/s) was
named ``dead_time`` with 26 x the floor left. The excitation moves quickly
between random levels and holds, so the travel rings after each move.
"""

from __future__ import annotations

from excitations import moves_and_holds
import numpy as np
import pytest
from reference_sim import backlash, first_order_sensor, hysteresis, second_order_sensor

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.mechanisms.registry import MECHANISMS
from hyst_id.io.recording import Recording

pytestmark = pytest.mark.slow

SETTINGS = DiagnoseSettings(seeds=(0,), generations=120, max_mechanisms=1,
                            hops=20)


def _recording(seed: int, zeta: float | None, omega_n: float = 2.5,
               lag_s: float | None = None) -> Recording:
    rng = np.random.default_rng(seed)
    t = np.arange(2400) * 0.05
    v = moves_and_holds(rng, t, dwell_s=6.0, move_s=0.5, n_levels=20)
    x = backlash(hysteresis(v, 1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0), 1.0,
                 -0.15, 0.15)
    if zeta is not None:
        x = second_order_sensor(t, x, zeta, omega_n)
    if lag_s is not None:
        x = first_order_sensor(t, x, lag_s)
    y = 12.0 * x + 3.0
    return Recording(t, v, y + rng.normal(0, 0.004 * np.ptp(y), t.size), 'position', 'mA',
                     'mm', f'actuator dynamics #{seed}')


def _judged_ratio(d) -> float:
    """Final %e_r over the noise floor on the held-out rows the blocks were judged on."""
    j = d.extra['judged_holdout']
    return j['final_er_percent'] / j['noise_floor_percent']


@pytest.mark.parametrize('seed', [0, pytest.param(3, marks=pytest.mark.thorough)])
def test_a_ringing_actuator_is_named_with_its_dynamics(seed):
    """Named, with its damping and frequency, in the reference's hold convention, at the floor.

    Measured on noise seeds 0-7, unperturbed and under the round-off probes 1-3 (32
    runs): named 32/32, hold ``after`` every time, zeta 0.2994-0.3003, omega_n
    2.4971-2.5015 rad/s, training %e_r 0.97-1.04 x its floor, judged held-out 0.96-1.19 x
    the floor (from 11-34 x before). Seed 3's held-out command leaves the training range
    after 124 of 720 samples; the whole held-out part there ends at 1.0-16.9 x depending
    on the probe (extrapolation, reported apart). Before the hold convention was chosen
    from the data: zeta 0.304-0.307, omega_n 3-4 % low, 1.3-9.3 x the floor left.
    """
    d = diagnose(_recording(seed, 0.3), settings=SETTINGS)
    assert d.verdict == 'actuator_dynamics', [f.mechanism for f in d.findings]
    assert d.extra['hold'] == 'after'
    f = d.findings[0]
    assert f.params['zeta'].value == pytest.approx(0.3, rel=0.02)
    assert f.params['omega_n_rad_s'].value == pytest.approx(2.5, rel=0.02)
    assert _judged_ratio(d) < 1.3
    assert f.er_holdout_after_percent < 0.5 * f.er_holdout_before_percent


@pytest.mark.parametrize('seed', [3, pytest.param(7, marks=pytest.mark.thorough)])
def test_a_first_order_lag_stays_sensor_lag(seed):
    """A 0.4 s lag is ``sensor_lag`` with its time constant, where the held-out part extrapolates.

    Measured on noise seeds 3-8, unperturbed and under the round-off probes 1-3 (24 runs):
    ``sensor_lag`` 24/24, tau 0.3985-0.4015 s, judged held-out 0.96-1.56 x the floor. Seeds
    3 and 7 are the ones whose held-out command leaves the training range (after 124 and 249
    of 720 samples): before the blocks were judged on the rows before that, they went to
    ``dead_time`` or ``actuator_dynamics`` (the lag fitted the training part at the floor
    and lost 17-22 x on the extrapolated rest); judged there they end at 0.96-1.01 x.
    """
    d = diagnose(_recording(seed, None, lag_s=0.4), settings=SETTINGS)
    assert d.verdict == 'sensor_lag', [f.mechanism for f in d.findings]
    assert d.findings[0].params['tau_lag_s'].value == pytest.approx(0.4, rel=0.03)
    assert d.extra['judged_holdout']['n_samples'] < d.extra['judged_holdout']['n_holdout']
    assert _judged_ratio(d) < 1.3


def test_actuator_dynamics_is_registered_with_words():
    m = MECHANISMS['actuator_dynamics']
    assert m.names == ('zeta', 'omega_n_rad_s') and m.units == ('1', 'rad/s')
    assert 'spring' in m.physics and m.compensation == 'not in-line'
