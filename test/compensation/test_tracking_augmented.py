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

"""Tracking on top of a diagnosis's in-line corrections (issue 17, column (c)).

The plant is the independent reference simulator's H and B read through a
calibration, with the drifts written here (not with the package's schedule
code); the compensator is an :class:`AugmentedCompensator` whose schedule
holds part of the drift, and the tracker must follow only what the schedule
leaves.
"""

from __future__ import annotations

import numpy as np
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.compensation import CommandLimits, InverseModel
from hyst_id.compensation.augment import Augmentation, AugmentedCompensator
from hyst_id.compensation.tracking import (AdaptiveCompensator, GainOffsetTracker,
                                           MIN_UPDATES, SensorPredictor)
from hyst_id.errors import InvalidParametersError
from hyst_id.identification.gauge import canonical_gauge

H = (1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0)
B = (1.0, -0.15, 0.15)
K, B0 = 40.0, 100.0                     # the reading: 40 units per mA-eq, 100 at zero
DT_S = 0.05
T = np.arange(1200) * DT_S
DESIRED = 470.0 + 40.0 * np.sin(2 * np.pi * T / 6.0) * (0.7 + 0.3 * np.sin(2 * np.pi * T / 23.0))
OFFSET_RATE = 0.5                        # reading units per second, scheduled


def _reading(cmds: np.ndarray, k: int, delay_samples: int, gain_fall: float,
             rng: np.random.Generator) -> float:
    """The plant's reading at sample ``k`` for the commands sent so far (reference code)."""
    v = np.concatenate([np.full(delay_samples, cmds[0]), cmds])[:k + 1]
    y = K * backlash(hysteresis(v, *H), *B)[-1] + B0
    g = 1.0 - gain_fall * T[k] / T[-1]
    return float(B0 + g * (y - B0) + OFFSET_RATE * T[k] + rng.normal(0.0, 0.2))


def _run(tracking: bool, gain_fall: float = 0.0, delay_samples: int = 0, seed: int = 0):
    """Closed loop: late rms error of the reading and the tracker (or None)."""
    rng = np.random.default_rng(seed)
    model = InverseModel.from_vector(canonical_gauge(np.r_[H, B], (K, B0)))
    aug = Augmentation(offset_rate_per_s=OFFSET_RATE, gain_centre=B0,
                       dead_time_s=delay_samples * DT_S)
    comp = AugmentedCompensator(model, aug, CommandLimits(0.0, 30.0), v0=9.0)
    adaptive = AdaptiveCompensator(comp, GainOffsetTracker(forget_time_s=5.0),
                                   SensorPredictor('none')) if tracking else None
    cmds, out = np.empty(T.size), np.empty(T.size)
    for k, tk in enumerate(T):
        cmds[k] = comp.step(DESIRED[k], tk) if adaptive is None else \
            adaptive.step(DESIRED[k], tk)
        out[k] = _reading(cmds, k, delay_samples, gain_fall, rng)
        if adaptive is not None:
            adaptive.observe(out[k], float(tk), DT_S if k else 0.0)
    late = T > 2 * T[-1] / 3
    err = float(np.sqrt(np.mean((out - DESIRED)[late] ** 2)))
    return err, None if adaptive is None else adaptive.tracker


def _random_augmentation(rng: np.random.Generator) -> Augmentation:
    while True:
        try:
            return Augmentation(
                gain_law=str(rng.choice(['none', 'linear', 'exponential'])),
                gain_rate_per_s=float(rng.uniform(-2e-3, 2e-3)),
                gain_centre=float(rng.uniform(-5.0, 5.0)),
                gain_reference=float(rng.uniform(0.8, 1.2)),
                offset_rate_per_s=float(rng.uniform(-0.1, 0.1)),
                offset_reference_s=float(rng.uniform(0.0, 50.0)),
                schedule_horizon_s=float(rng.choice([0.0, 100.0])),
                poly_c0=float(rng.uniform(-1.0, 1.0)), poly_c1=float(rng.uniform(0.5, 3.0)),
                poly_c2=float(rng.uniform(-0.4, 0.4)), poly_c3=float(rng.uniform(-0.3, 0.3)))
        except InvalidParametersError:         # an output map that folds back: draw again
            continue


@pytest.mark.parametrize('seed', range(20))
def test_reading_undoes_model_target_over_random_corrections(seed):
    rng = np.random.default_rng(seed)
    aug = _random_augmentation(rng)
    for _ in range(20):
        z, elapsed = float(rng.uniform(-1.5, 1.5)), float(rng.uniform(0.0, 200.0))
        assert aug.model_target(aug.reading(z, elapsed), elapsed) == pytest.approx(
            z, abs=1e-9)
        assert aug.model_target(aug.reading(z, None), None) == pytest.approx(z, abs=1e-9)


@pytest.mark.parametrize('seed', [0, 1])
def test_a_drift_the_schedule_holds_is_not_corrected_twice(seed):
    fixed, _ = _run(tracking=False, seed=seed)
    err, tracker = _run(tracking=True, seed=seed)
    # measured over seeds 0-3: fixed and tracked both 0.19-0.20 (noise 0.2), gain within
    # 0.001 of 1, offset within 0.06; with the bare model's prediction (no ramp in it) the
    # tracker takes the scheduled ramp again: offset 30, error 24.9
    assert err < 1.3 * fixed, (fixed, err)
    assert abs(tracker.gain - 1.0) < 0.02 and abs(tracker.offset_at(T[-1])) < 1.0


@pytest.mark.parametrize('seed', [0, 1])
def test_what_the_schedule_leaves_is_tracked(seed):
    fixed, _ = _run(tracking=False, gain_fall=0.3, seed=seed)
    err, tracker = _run(tracking=True, gain_fall=0.3, seed=seed)
    # measured over seeds 0-3: fixed 86.5, tracked 0.77-0.78; gain 0.733 (the plant's
    # unscheduled gain ends at 0.7; the estimate lags it by about its forgetting time)
    assert fixed > 50.0 and err < 0.05 * fixed, (fixed, err)
    assert tracker.applied and 0.65 < tracker.gain < 0.75


def test_the_prediction_waits_out_the_dead_time():
    err_fixed, _ = _run(tracking=False, delay_samples=10)
    err, tracker = _run(tracking=True, delay_samples=10)
    # measured over seeds 0-3: gain within 0.001 of 1, error as without tracking (3.3,
    # the slope's prediction over the delay); compared with the latest model output
    # instead of the one sent 0.5 s before, the tracker reads the delay as a gain of 0.875
    assert abs(tracker.gain - 1.0) < 0.03 and err < 1.3 * err_fixed, (err_fixed, err)


def test_no_estimate_before_a_dead_time_has_passed():
    model = InverseModel.from_vector(canonical_gauge(np.r_[H, B], (K, B0)))
    comp = AugmentedCompensator(model, Augmentation(dead_time_s=0.5), v0=9.0)
    adaptive = AdaptiveCompensator(comp, GainOffsetTracker(), SensorPredictor('none'))
    for k in range(5):
        adaptive.step(470.0, 0.1 * k)
        assert np.isnan(adaptive.observe(470.0, 0.1 * k))
    adaptive.step(470.0, 0.5)
    assert np.isfinite(adaptive.observe(470.0, 0.5))


def test_the_correction_waits_for_enough_samples():
    tracker = GainOffsetTracker(forget_time_s=5.0)
    p = 9.0 + np.sin(np.arange(200) / 5.0)
    applied_at = None
    for k, pk in enumerate(p):
        tracker.update(0.1 * k, float(pk), 0.7 * float(pk) + 2.0)
        if tracker.applied and applied_at is None:
            applied_at = k
    # the first sample only sets the centre (no excitation yet); the estimate is exact
    # long before (test_tracking.py), but a correction waits for MIN_UPDATES samples
    assert applied_at == MIN_UPDATES
