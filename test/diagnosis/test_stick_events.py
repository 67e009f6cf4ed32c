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

"""Stick-slip from its events: plateaus, the stick/slip conditions, the chain fit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hyst_id.diagnosis.mechanisms.stiction import stick_slip
from hyst_id.diagnosis.plateaus import plateaus
from hyst_id.diagnosis.stick_events import (
    bands_from_demand,
    fit_stick_slip_events,
    stick_intervals,
)
from hyst_id.identification.chains import chain_spec
from hyst_id.signals.excitation import multisine

__all__: list[str] = []

POS = chain_spec('position')
#: The paper's induced hysteresis and a small backlash.
CHAIN = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])
NOISE = 0.005


def _demand(duration_s: float = 84.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.arange(0.0, duration_s, 0.05)
    v = multisine(t, amplitude_ma=1.8)
    return t, v, POS.signal(CHAIN, t, v)


def _he_model(x: np.ndarray, static: float, dynamic: float) -> np.ndarray:
    """Two-band stick-slip (slips to ``dynamic`` short of the demand), starting on it."""
    out = np.empty_like(x)
    out[0] = x[0]
    for j in range(1, x.size):
        d = x[j] - out[j - 1]
        out[j] = out[j - 1] if abs(d) <= static else x[j] - math.copysign(dynamic, d)
    return out


@pytest.fixture(scope='module')
def staircase():
    t, v, x = _demand()
    band = 0.04 * np.ptp(x)
    clean = stick_slip(x, band, x[0] + 0.3 * band)
    y = clean + np.random.default_rng(3).normal(0.0, NOISE, x.size)
    return t, v, x, band, clean, y


def test_plateaus_cut_exactly_at_the_slips_and_ignore_a_noise_spike(staircase):
    _, _, _, _, clean, y = staircase
    slips = np.nonzero(np.diff(clean))[0] + 1
    spiky = y.copy()
    k = int(np.argmax(np.diff(slips))) + 1    # the middle of the longest plateau
    mid = (slips[k - 1] + slips[k]) // 2
    spiky[mid] += 6.0 * NOISE                 # a 6-sigma step up and one back down
    for rec in (y, spiky):
        p = plateaus(rec, NOISE)
        assert np.array_equal(p.edges[1:-1], slips)
        assert p.is_staircase(NOISE)
    assert plateaus(y, NOISE).scatter == pytest.approx(NOISE, rel=0.1)


def test_a_smooth_record_is_not_a_staircase():
    t, v, x = _demand()
    y = x + np.random.default_rng(0).normal(0.0, NOISE, x.size)
    assert not plateaus(y, NOISE).is_staircase(NOISE)
    assert fit_stick_slip_events(POS, t, v, y, NOISE, [CHAIN]) == []


def test_true_band_and_initial_state_lie_in_the_allowed_intervals(staircase):
    _, _, x, band, clean, y = staircase
    p = plateaus(y, NOISE)
    (b_lo, b_hi), (s_lo, s_hi) = stick_intervals(x, p.edges, p.levels, 1.0)
    assert b_lo < band < b_hi
    assert (b_hi - b_lo) < 0.05 * band
    assert s_lo <= clean[0] <= s_hi


def test_chain_and_band_are_recovered_from_a_perturbed_start(staircase):
    t, v, x, band, clean, y = staircase
    start = CHAIN * (1.0 + 0.02 * np.random.default_rng(1).standard_normal(CHAIN.size))
    assert POS.feasible(start[None, :])[0]
    fits = fit_stick_slip_events(POS, t, v, y, NOISE, [start])
    assert fits and fits[0].violations == 0
    best = fits[0]
    x_fit = POS.signal(best.chain, t, v)
    travel = np.ptp(x_fit)
    sim = stick_slip(x_fit, best.band_fraction * travel,
                     x_fit[0] + best.offset_fraction * travel)
    coef = np.polyfit(sim, y, 1)
    # every slip lands on the measured sample: the residual is the noise alone
    assert np.std(y - np.polyval(coef, sim)) < 1.1 * NOISE
    assert abs(coef[0]) * best.band_fraction * travel == pytest.approx(band, rel=0.01)


def test_bands_from_a_known_demand():
    t, v, x = _demand(120.0)
    travel = np.ptp(x)
    static, dynamic = 0.06 * travel, 0.02 * travel
    y = _he_model(x, static, dynamic) + 0.3 + np.random.default_rng(2).normal(0, NOISE, x.size)
    got = bands_from_demand(x, y, NOISE)
    assert got is not None
    assert got[0] == pytest.approx(static, rel=0.01)
    assert got[1] == pytest.approx(dynamic, abs=0.05 * static)
    assert bands_from_demand(x, x + np.random.default_rng(2).normal(0, NOISE, x.size),
                             NOISE) is None


def test_slips_of_a_few_noise_std_are_all_found():
    """Candidate steps at 3 sigma, then merging: 7-sigma slips are all found."""
    t, v, x = _demand()
    band = 7.0 * NOISE
    clean = stick_slip(x, band, x[0])
    slips = np.nonzero(np.diff(clean))[0] + 1
    y = clean + np.random.default_rng(5).normal(0.0, NOISE, x.size)
    p = plateaus(y, NOISE)
    assert slips.size > 100
    assert np.array_equal(p.edges[1:-1], slips)
    single = np.nonzero(np.abs(np.diff(y)) > 5.0 * NOISE)[0] + 1
    assert not np.array_equal(single, slips)     # one 5-sigma threshold misses some


def test_slips_below_twice_the_noise_are_not_stiction():
    from hyst_id.diagnosis.mechanisms import MECHANISMS
    from hyst_id.diagnosis.sim_compare import _implausible

    st = MECHANISMS['stiction']
    coef, span = np.array([2.0, 0.0]), (0.0, 1.0)      # 2 measurement units per position unit
    assert 'no visible slips' in st.implausible(np.array([0.002, 0.0]), coef, span, NOISE)
    assert st.implausible(np.array([0.01, 0.0]), coef, span, NOISE) == ''
    assert 'no visible slips' in _implausible('stiction', 'position', np.array([0.02, 0.8]),
                                              NOISE)
    assert _implausible('stiction', 'position', np.array([0.02, 0.3]), NOISE) == ''
    assert _implausible('dead_time', 'position', np.array([0.0]), NOISE) == ''
