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

"""``ChainSpec.residual_function``: refine's fast path gives :meth:`residual`'s very numbers."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hyst_id.identification.chains import chain_spec, ChainResiduals, CHANNELS
from hyst_id.identification.refine import refine
from hyst_id.models.registry import FAMILIES


def _feasible_draws(spec, rng, n=5):
    lo, hi = spec.bounds[:, 0], spec.bounds[:, 1]
    pop = lo + (hi - lo) * rng.random((20000, spec.n_params))
    ok = pop[spec.feasible(pop)]
    assert ok.shape[0] >= n, 'the bounds hold too few feasible sets to test'
    return ok[:n]


def _recording(rng, uniform):
    t = np.cumsum(np.full(300, 0.05) if uniform else rng.uniform(0.03, 0.07, 300))
    v = 9.0 + 2.0 * np.sin(2 * np.pi * t / 5.0) * np.exp(-t / 30.0)
    return t, v, 3.0 * v + 5.0 + rng.normal(0.0, 0.1, t.size)


@pytest.mark.parametrize('channel', CHANNELS)
@pytest.mark.parametrize('family', sorted(FAMILIES))
@pytest.mark.parametrize('initial', ['rising', 'falling'])
def test_the_fast_residual_is_the_checked_one_bit_for_bit(channel, family, initial):
    rng = np.random.default_rng([7, CHANNELS.index(channel), len(family), len(initial)])
    for hold in ('before', 'after'):
        for calibration in (None, (2.5, -1.0)):
            spec = replace(chain_spec(channel, family=family, initial=initial,
                                      calibration=calibration), hold=hold)
            for uniform in (True, False):
                t, v, y = _recording(rng, uniform)
                fast = spec.residual_function(t, v, y)
                pop = _feasible_draws(spec, rng)
                checked = [spec.residual(p, t, v, y) for p in pop]
                for p, r in zip(pop, checked):
                    assert np.array_equal(fast(p), r)
                # many sets with H run once; a row marked infeasible gives None
                ok = np.ones(pop.shape[0], dtype=bool)
                ok[1] = False
                together = fast.rows(pop, ok)
                assert together[1] is None
                for i in (0, *range(2, pop.shape[0])):
                    assert np.array_equal(together[i], checked[i])


def test_refine_still_lowers_the_cost_from_a_feasible_start():
    rng = np.random.default_rng(3)
    spec = chain_spec('pressure')
    t, v, _ = _recording(rng, True)
    truth = _feasible_draws(spec, rng, 1)[0]
    y = spec.simulate(truth, t, v, (1.0, 0.0)) + rng.normal(0.0, 0.01, t.size)
    start = _feasible_draws(spec, rng, 1)[0]
    cost = spec.cost_function(t, v, y)
    x, f, nfev = refine(spec, start, t, v, y, max_nfev=600)
    assert f <= float(cost(start[None, :])[0]) and nfev > 0
    assert f == pytest.approx(float(cost(x[None, :])[0]))


@pytest.mark.parametrize('channel', CHANNELS)
@pytest.mark.parametrize('initial', ['rising', 'falling'])
def test_refine_gives_the_same_bits_with_its_jacobian_points_evaluated_together(
        channel, initial, monkeypatch):
    import hyst_id.identification.refine as refine_module
    if not refine_module._TAKES_WORKERS:
        pytest.skip('this scipy has no least_squares(workers=...): refine polishes one by one')
    rng = np.random.default_rng([11, CHANNELS.index(channel), len(initial)])
    spec = chain_spec(channel, initial=initial)
    t, v, _ = _recording(rng, False)
    truth, start = _feasible_draws(spec, rng, 2)
    y = spec.simulate(truth, t, v, (1.0, 0.0)) + rng.normal(0.0, 0.01, t.size)
    batches = []
    rows = ChainResiduals.rows
    monkeypatch.setattr(ChainResiduals, 'rows',
                        lambda self, pop, ok: batches.append(len(pop)) or rows(self, pop, ok))
    together = refine(spec, start, t, v, y, max_nfev=800)
    assert batches and max(batches) == spec.n_params    # a Jacobian's points at once
    monkeypatch.setattr(refine_module, '_TAKES_WORKERS', False)
    n_batches = len(batches)
    alone = refine(spec, start, t, v, y, max_nfev=800)
    assert len(batches) == n_batches                    # point by point
    np.testing.assert_array_equal(together[0], alone[0])
    assert together[1:] == alone[1:] and together[2] > 20
