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

"""The compensator's in-line corrections against plants from the independent reference simulator.

Each plant is ``test/reference_sim`` (H and B written apart from the
package) with one effect the diagnosis library names: a command delay, a
supply-like decaying gain, an offset ramp. The compensator gets the true H
and B (canonical gauge) and the effect's true values: what is tested here is
the correction itself; ``test/diagnosis/test_compensator_set.py`` tests the
values a diagnosis hands it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.compensation import CommandLimits, Compensator, InverseModel
from hyst_id.compensation.augment import (Augmentation, augmentation_from_findings,
                                          AugmentedCompensator)
from hyst_id.compensation.params_file import read_compensator_params, write_compensator_params
from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.identification.gauge import canonical_gauge

H = (1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0)
B = (1.0, -0.15, 0.15)
K, B0 = 40.0, 100.0                      # the sensor: 40 units per mA-eq, 100 at zero
DT_S = 0.05
T = np.arange(2400) * DT_S
#: Minor loops inside the travel where the loop's side lines hold (readings 425-515).
DESIRED = 470.0 + 45.0 * np.sin(2 * np.pi * T / 9.0) * (0.6 + 0.4 * np.sin(2 * np.pi * T / 37.0))


def _model() -> InverseModel:
    return InverseModel.from_vector(canonical_gauge(np.r_[H, B], (K, B0)))


def _reading(cmds: np.ndarray, delay_s: float = 0.0, gain=None, offset_rate: float = 0.0
             ) -> np.ndarray:
    """The plant's noise-free reading for the commands sent (reference code)."""
    v = np.interp(T - delay_s, T, cmds) if delay_s else cmds
    y = K * backlash(hysteresis(v, *H), *B) + B0
    if gain is not None:
        y = B0 + gain(T) * (y - B0)
    return y + offset_rate * T


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x[T > 10.0]))))


def _commands(aug: Augmentation | None) -> np.ndarray:
    comp = AugmentedCompensator(_model(), aug, CommandLimits(4.0, 20.0), v0=9.0)
    return comp.run(DESIRED, T)


def test_without_corrections_it_is_the_plain_compensator():
    plain = Compensator(_model(), CommandLimits(4.0, 20.0), v0=9.0).run(DESIRED, T)
    assert np.array_equal(_commands(None), plain)
    assert np.array_equal(_commands(Augmentation(gain_centre=3.0, schedule_horizon_s=9.0)),
                          plain)
    assert _rms(_reading(plain) - DESIRED) < 1e-6 * np.ptp(DESIRED)


def test_a_ramp_is_predicted_ahead_exactly():
    comp = AugmentedCompensator(_model(), Augmentation(dead_time_s=0.5))
    got = [comp.predicted_desired(2.0 * t + 1.0, t) for t in T[:40]]
    assert got[0] == 1.0                                  # no slope yet: the value itself
    np.testing.assert_allclose(got[1:], 2.0 * (T[1:40] + 0.5) + 1.0, rtol=1e-12)


@pytest.mark.parametrize('delay_s', [0.2, 0.5])
def test_dead_time_predicted_ahead(delay_s):
    fixed = _rms(_reading(_commands(None), delay_s) - DESIRED)
    ahead = _rms(_reading(_commands(Augmentation(dead_time_s=delay_s)), delay_s) - DESIRED)
    # measured: 0.2 s: 2.91 -> 0.27 (0.09 x), 0.5 s: 7.24 -> 1.46 (0.20 x): the slope is
    # extrapolated over the delay, so what is left grows with delay^2 x the curvature
    # (noise-free and deterministic: the bound is the larger ratio with 50 % margin)
    assert ahead < 0.3 * fixed, (fixed, ahead)


def test_a_decaying_gain_is_scheduled():
    rate = 1.0 / 300.0
    gain = (lambda t: np.exp(-rate * t))
    aug = Augmentation(gain_law='exponential', gain_rate_per_s=rate, gain_centre=B0)
    fixed = _rms(_reading(_commands(None), gain=gain) - DESIRED)
    scheduled = _rms(_reading(_commands(aug), gain=gain) - DESIRED)
    assert fixed > 20.0 and scheduled < 1e-6 * fixed, (fixed, scheduled)
    # a set that holds at the record's mean gain: the same, referred to that gain
    g_ref = float(np.mean(gain(T)))
    # y = B0 + g_ref (K s + B0 - B0): calibration (K g_ref, B0)
    ref_model = InverseModel.from_vector(canonical_gauge(np.r_[H, B], (K * g_ref, B0)))
    comp = AugmentedCompensator(ref_model, Augmentation(
        gain_law='exponential', gain_rate_per_s=rate, gain_centre=B0, gain_reference=g_ref),
        CommandLimits(4.0, 20.0), v0=9.0)
    assert _rms(_reading(comp.run(DESIRED, T), gain=gain) - DESIRED) < 1e-6 * fixed


def test_an_offset_ramp_is_scheduled_and_held_after_the_horizon():
    rate = 0.1
    aug = Augmentation(offset_rate_per_s=rate)
    fixed = _rms(_reading(_commands(None), offset_rate=rate) - DESIRED)
    assert fixed > 5.0
    assert _rms(_reading(_commands(aug), offset_rate=rate) - DESIRED) < 1e-6 * fixed
    held = Augmentation(offset_rate_per_s=rate, schedule_horizon_s=60.0)
    assert held.offset(200.0) == held.offset(60.0) == pytest.approx(6.0)


def test_the_gain_never_falls_below_its_floor():
    aug = Augmentation(gain_law='linear', gain_rate_per_s=-0.01)
    assert aug.gain(50.0) == pytest.approx(0.5) and aug.gain(1000.0) == 0.05
    assert math.isfinite(aug.model_target(10.0, 1e6))


def test_stops_narrow_the_command_limits():
    comp = AugmentedCompensator(_model(), Augmentation(min_command=6.0, max_command=12.0),
                                CommandLimits(4.0, 20.0))
    assert (comp.limits.min_command, comp.limits.max_command) == (6.0, 12.0)
    cmds = comp.run(np.r_[300.0, 900.0, 100.0], T[:3])
    assert cmds.min() >= 6.0 and cmds.max() <= 12.0
    comp.limits = CommandLimits(8.0, 10.0)
    assert (comp.limits.min_command, comp.limits.max_command) == (8.0, 10.0)
    with pytest.raises(InvalidParametersError, match='leave no command'):
        Augmentation(min_command=30.0, max_command=40.0).limits(CommandLimits(4.0, 20.0))


@pytest.mark.parametrize('bad, match', [
    ({'augment.dead_time_s': -1.0}, 'dead_time_s'),
    ({'augment.gain_law': 'cubic'}, 'gain_law'),
    ({'augment.gain_reference': 0.0}, 'gain_reference'),
    ({'augment.offset_rate_per_s': 'fast'}, 'offset_rate_per_s'),
    ({'augment.gain_rate_per_s': float('nan')}, 'gain_rate_per_s'),
    ({'augment.min_command': 5.0, 'augment.max_command': 5.0}, 'min_command'),
])
def test_bad_corrections_are_refused(bad, match):
    with pytest.raises(InvalidParametersError, match=match):
        Augmentation.from_mapping(bad)


def test_time_based_corrections_need_times():
    comp = AugmentedCompensator(_model(), Augmentation(dead_time_s=0.3))
    with pytest.raises(InvalidParametersError, match='sample times'):
        comp.run(DESIRED[:5])


def test_params_file_round_trip_with_corrections(tmp_path):
    aug = Augmentation(dead_time_s=0.4, gain_law='exponential', gain_rate_per_s=0.002,
                       gain_centre=100.0, schedule_horizon_s=120.0, max_command=18.0)
    values = {'channel': 'position', 'er_percent': 1.2, **_model().as_mapping(),
              'augment': aug}
    path = write_compensator_params(values, tmp_path / 'c.yaml')
    text = path.read_text()
    assert '    augment:\n      dead_time_s: 0.4' in text and 'min_command: .nan' in text
    back = read_compensator_params(path)
    assert Augmentation.from_mapping(back) == aug
    assert InverseModel.from_mapping(back) == _model()
    path.write_text(text.replace('dead_time_s', 'dead_tme_s'))
    with pytest.raises(ConfigError, match='unknown in-line corrections: augment.dead_tme_s'):
        read_compensator_params(path)


def test_findings_become_corrections_once_each():
    findings = [
        {'mechanism': 'dead_time', 'compensation': {'kind': 'in-line', 'how': 'ahead',
                                                    'correction': {'augment.dead_time_s': 0.3}}},
        {'mechanism': 'stiction', 'compensation': {'kind': 'not in-line', 'how': 'dither'}},
        {'mechanism': 'dead_time', 'compensation': {
            'kind': 'in-line', 'how': 'ahead', 'correction': {'augment.dead_time_s': 0.9}}},
        {'mechanism': 'offset_drift', 'compensation': {
            'kind': 'in-line', 'how': 'ramp', 'correction': {'augment.offset_rate_per_s': 0.01}}},
    ]
    aug, applied = augmentation_from_findings(findings, 200.0)
    assert aug == Augmentation(dead_time_s=0.3, offset_rate_per_s=0.01,
                               schedule_horizon_s=200.0)
    assert [a[1].split(':')[0] for a in applied] == [
        'in-line', 'no in-line correction', 'not applied', 'in-line']


POLY = (470.0, 45.0, 8.0, 4.0)          # reading = cubic of z = (linear reading - 470) / 45


def test_an_output_map_is_inverted():
    aug = Augmentation(poly_c0=POLY[0], poly_c1=POLY[1], poly_c2=POLY[2], poly_c3=POLY[3])

    def curved(cmds):        # the cubic over the travel |z| <= 1, straight beyond it
        z = (_reading(cmds) - 470.0) / 45.0
        zc = np.clip(z, -1.0, 1.0)
        slope = POLY[1] + 2 * POLY[2] * zc + 3 * POLY[3] * zc * zc
        return POLY[0] + zc * (POLY[1] + zc * (POLY[2] + zc * POLY[3])) + slope * (z - zc)

    z_cal = (K / 45.0, (B0 - 470.0) / 45.0)                 # H and B output z
    z_model = InverseModel.from_vector(canonical_gauge(np.r_[H, B], z_cal))
    mapped = AugmentedCompensator(z_model, aug, CommandLimits(4.0, 20.0), v0=9.0)
    straight = _rms(curved(_commands(None)) - DESIRED)
    inverted = _rms(curved(mapped.run(DESIRED, T)) - DESIRED)
    assert straight > 3.0 and inverted < 1e-6 * straight, (straight, inverted)
    for d in (430.0, 470.0, 512.5):
        z = aug.invert_output_map(d)
        assert POLY[0] + z * (POLY[1] + z * (POLY[2] + z * POLY[3])) == pytest.approx(d)
    # past the fitted travel (|z| > 1) the map is the straight line of its end slope
    for d in (-1e6, 200.0, 800.0, 1e6):
        z = aug.invert_output_map(d)
        assert abs(z) > 1.0 and aug.output_map(z) == pytest.approx(d)
        end = np.sign(z)
        slope = POLY[1] + 2 * POLY[2] * end + 3 * POLY[3]
        assert aug.output_map(z) == pytest.approx(aug.output_map(end) + slope * (z - end))
    zs = np.linspace(-3.0, 3.0, 601)         # continuous and monotone across the ends
    mapped_z = np.array([aug.output_map(z) for z in zs])
    assert np.all(np.diff(mapped_z) > 0) or np.all(np.diff(mapped_z) < 0)
    assert aug.output_map(1.0 + 1e-9) == pytest.approx(aug.output_map(1.0), abs=1e-6)
    assert 'output map' in aug.describe()


def test_a_map_that_folds_back_is_refused():
    with pytest.raises(InvalidParametersError, match='not monotone'):
        Augmentation(poly_c1=1.0, poly_c3=-1.0)      # slope 1 - 3 z^2 changes sign
    _, applied = augmentation_from_findings([{'mechanism': 'static_nonlinearity',
                                              'compensation': {'correction': {
                                                  'augment.poly_c2': 0.1}}}], 10.0)
    assert applied[0][1].startswith("not applied: its output map needs the diagnosis's")


def test_a_non_finite_desired_value_holds_the_last_command():
    aug = Augmentation(poly_c0=POLY[0], poly_c1=POLY[1], poly_c2=POLY[2], poly_c3=POLY[3],
                       offset_rate_per_s=0.01)
    comp = AugmentedCompensator(_model(), aug, CommandLimits(4.0, 20.0), v0=9.0)
    v = comp.step(460.0, 0.0)
    for bad in (float('nan'), float('inf'), -float('inf')):
        assert comp.step(bad, 0.05) == v


def test_limits_and_stops_change_together_or_not_at_all():
    comp = AugmentedCompensator(_model(), Augmentation(min_command=6.0), CommandLimits(4.0, 20.0))
    with pytest.raises(InvalidParametersError, match='leave no command'):
        comp.limits = CommandLimits(4.0, 5.0)
    assert (comp.limits.min_command, comp.limits.max_command) == (6.0, 20.0)
    assert comp.base_limits == CommandLimits(4.0, 20.0)
    comp.configure(Augmentation(min_command=32.0, max_command=38.0), CommandLimits(30.0, 40.0))
    assert (comp.limits.min_command, comp.limits.max_command) == (32.0, 38.0)


def test_a_reset_keeps_the_schedule_and_a_restart_does_not():
    aug = Augmentation(offset_rate_per_s=1.0)
    comp = AugmentedCompensator(_model(), aug, CommandLimits(4.0, 20.0), v0=9.0)
    comp.run(DESIRED[:101], T[:101])                   # 5 s of schedule
    comp.reset(9.0)
    after_reset = comp.step(470.0, T[101])
    comp.restart_schedules()
    comp.reset(9.0)
    after_restart = comp.step(470.0, T[101])
    fresh = AugmentedCompensator(_model(), aug, CommandLimits(4.0, 20.0), v0=9.0)
    assert after_restart == fresh.step(470.0, T[101]) != after_reset


@pytest.mark.parametrize('field, value', [('gain_centre', float('inf')),
                                          ('offset_rate_per_s', -float('inf')),
                                          ('predict_window_s', float('inf')),
                                          ('dead_time_s', True)])
def test_infinities_and_booleans_are_refused(field, value):
    with pytest.raises(InvalidParametersError, match=field):
        Augmentation(**{field: value})
