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

"""The search subset of a long record (``IdentifySettings.search_samples``)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from reference_sim import backlash, first_order_sensor, hysteresis

from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import chain_spec
from hyst_id.identification.driver import search_subset
from hyst_id.io.recording import Recording

PAPER_H = (1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0)


def _command(n: int, dt_s: float = 0.001, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) * dt_s
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0.0, 6.0)
    v = 9.0 + 2.0 * np.sin(2 * np.pi * t / 10.0) + 0.6 * np.sin(2 * np.pi * t / 1.7 + phase)
    return t, np.round(v, 4)                    # quantised: flat stretches at the extremes


def test_short_records_and_noisy_commands_use_every_sample():
    t, v = _command(5000)
    assert search_subset(v, 5000) is None and search_subset(v, 0) is None
    noisy = v + np.random.default_rng(1).normal(0.0, 0.01, v.size)
    assert search_subset(noisy, 1000) is None      # reversals alone are most samples


@pytest.mark.parametrize('seed', range(4))
def test_the_subset_keeps_every_extreme_and_the_command_is_monotone_between(seed):
    t, v = _command(60000, seed=seed)
    idx = search_subset(v, 6000)
    assert idx[0] == 0 and idx[-1] == v.size - 1 and np.all(np.diff(idx) > 0)
    assert idx.size < 0.2 * v.size
    for a, b in zip(idx[:-1], idx[1:]):
        step = np.diff(v[a:b + 1])
        assert not (np.any(step > 0) and np.any(step < 0)), (a, b)


@pytest.mark.parametrize('seed', range(3))
def test_a_rate_independent_chain_is_exact_on_the_subset(seed):
    """H and B (reference simulator and the package's chain) give the same output there."""
    t, v = _command(60000, seed=seed)
    idx = search_subset(v, 6000)
    ref_full = backlash(hysteresis(v, *PAPER_H), 1.0, -0.25, 0.25)
    ref_sub = backlash(hysteresis(v[idx], *PAPER_H), 1.0, -0.25, 0.25)
    np.testing.assert_allclose(ref_sub, ref_full[idx], rtol=0, atol=1e-9)
    spec = chain_spec('position')
    x = np.array([*PAPER_H, 1.0, -0.25, 0.25])
    np.testing.assert_allclose(spec.simulate(x, t[idx], v[idx]), spec.simulate(x, t, v)[idx],
                               rtol=0, atol=1e-9)


def _recording(channel: str, seed: int) -> Recording:
    t, v = _command(40000, seed=seed)
    y = backlash(hysteresis(v, *PAPER_H), 1.0, -0.25, 0.25)
    if channel == 'pressure':
        y = first_order_sensor(t, y, 0.8)
    y = 30.0 * y + np.random.default_rng(seed + 10).normal(0.0, 0.004 * 30.0 * np.ptp(y), t.size)
    return Recording(t, v, y, channel, 'mA', 'kPa', f'{channel} #{seed}')


@pytest.mark.slow
@pytest.mark.parametrize('channel', [
    pytest.param('position', marks=pytest.mark.thorough), 'pressure'])
def test_identify_on_the_subset_matches_every_sample(channel):
    """%e_r with the search on 8,000 of 40,000 samples within 1.05 x of the full-rate search.

    Every refinement and the reported %e_r use all samples in both runs. The bound is
    the issue's criterion for any decimation; ``bench/record_scale.py`` measured 1.0000 on
    position and pressure at 20,000, 60,000 and 120,000 samples (ten seeds). On this
    test's recordings, unperturbed and under the round-off probe 1: ratio 1.0000 and
    1.0022 (position) / 1.0026 (pressure) x the floor on both. Position is in the
    thorough tier: there the chain is rate-independent and the subset exact
    (``test_a_rate_independent_chain_is_exact_on_the_subset``); pressure's sensor
    lag makes it an approximation, checked here by default.
    """
    rec = _recording(channel, 0)
    idx = search_subset(rec.command, 8000)
    assert idx is not None and idx.size < 0.3 * rec.t_s.size   # the subset is really used
    base = IdentifySettings(seeds=(0, 1, 2))
    sub = identify(rec, settings=replace(base, search_samples=8000))
    full = identify(rec, settings=replace(base, search_samples=0))
    assert sub.er_percent <= 1.05 * full.er_percent, (sub.er_percent, full.er_percent)
    assert sub.er_percent < 1.1 * sub.noise_floor_percent
