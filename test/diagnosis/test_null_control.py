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

"""The null control: a block that only carried a chain refit is not claimed.

On a clean recording from the reference simulator, a baseline stopped short
of its optimum makes any block look like physics (the block's fit polishes
the chain too); refitted without the block from the block's own chain, the
baseline does as well, and :func:`recheck` withdraws the acceptance. With a
real offset drift in the data the block survives the control. Bounds from
``bench/null_control_spread.py`` (8 noise seeds x 4 round-off conditions):
refit SSE / baseline SSE 0.015-0.016 (bound 0.5), refit held-out / floor
0.98-1.11 (bound 1.5), withdrawn 32/32 without drift and 0/32 with it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from reference_sim import simulate as reference_simulate

from hyst_id.diagnosis.control import drop_superseded, equivalent_chain, null_control
from hyst_id.diagnosis.control import recheck
from hyst_id.diagnosis.mechanisms import Context, MECHANISMS
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.select import compare, Criteria, Data, evaluate, fit_model, polish
from hyst_id.identification.chains import chain_spec
from hyst_id.signals.excitation import multisine

NAMES = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b', 'm_bl', 'c_bl', 'c_br')
TRUTH = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])
#: an under-converged baseline: the right line and the top line off
OFF = TRUTH + np.array([0.0, 0.0, 0.02, 0.0, 0.0, 0.15, 0.0, 0.0, 0.0, 0.0, 0.0])


def make_case(drift: float, seed: int = 3):
    """Data, base model, the offset-drift block and the model with it (noise ``seed``)."""
    t = np.arange(0.0, 120.0, 0.05)
    v = multisine(t, amplitude_ma=1.8)
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, v)
    sigma = 0.004 * np.ptp(x)
    y = x + drift * np.ptp(x) * t / t[-1] + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    n = int(0.7 * t.size)
    ctx = Context('position', t, n)
    data = Data(t_s=t, v=v, y=y, n_train=n, noise_std=sigma)
    base = ComposedModel('position', [], ctx, chain_spec('position').bounds)
    m = MECHANISMS['offset_drift']
    model = ComposedModel('position', [m], ctx, chain_spec('position').bounds)
    return data, base, m, model


@pytest.mark.parametrize('drift, withdrawn', [(0.0, 1), (0.05, 0)])
def test_a_block_that_only_carried_the_refit_is_withdrawn(drift, withdrawn):
    data, base, m, model = make_case(drift)
    start = OFF if drift == 0.0 else TRUTH
    current = evaluate(base, data, start)
    fit = fit_model(model, data, model.pack(start, {}), m, budget=600)
    comp = compare(current, fit, data, m.id, Criteria())
    assert comp.accepted, comp       # against the current baseline it looks like physics
    null = null_control(comp, current, data, max_nfev=1200)
    if withdrawn:
        assert null is not None and null.sse_train < 0.5 * current.sse_train
        assert null.er_holdout_percent < 1.5 * data.floor_holdout_percent
    if null is not None:
        assert recheck([comp], null, data, Criteria()) == withdrawn
    assert comp.accepted == (not withdrawn), comp.status


def _two_blocks(effects: str, seed: int = 3, probe: int | None = None):
    """A record with two effects and the model with two blocks fitted from the truth.

    ``'gain'``: a gain growing 0.08 %/s about a zero 8 travel units away, fitted with
    ``offset_drift`` (accepted first) and ``gain_drift``; a free gain pivot makes the
    ramp redundant. ``'delay+drift'``: a 0.3 s dead time and an offset ramp of 5 % of
    the span, fitted with both blocks, each needed. ``probe`` perturbs the measurement
    by 1e-12 relative (another CPU's last bits).
    """
    t = np.arange(0.0, 120.0, 0.05)
    v = multisine(t, amplitude_ma=1.8)
    ctx = Context('position', t, int(0.7 * t.size))
    if effects == 'gain':
        x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, v)
        y = 30.0 * (x + 8.0) * (1.0 + 0.0008 * t)
        ids, thetas = ('offset_drift', 'gain_drift'), {'gain_drift': [0.0008]}
    else:
        x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, np.interp(t - 0.3, t, v))
        y = x + 0.05 * np.ptp(x) * t / t[-1]
        ids, thetas = ('dead_time', 'offset_drift'), {'dead_time': [0.3]}
    sigma = 0.004 * np.ptp(y)
    y = y + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    if probe is not None:
        y = y * (1.0 + 1e-12 * np.random.default_rng([probe, seed]).standard_normal(y.size))
    data = Data(t_s=t, v=v, y=y, n_train=ctx.n_train, noise_std=sigma)
    model = ComposedModel('position', [MECHANISMS[i] for i in ids], ctx,
                          chain_spec('position').bounds)
    p = polish(model, data, model.pack(TRUTH, thetas), max_nfev=1200)[0]
    return data, ids, evaluate(model, data, p)


@pytest.mark.parametrize('effects, dropped', [('gain', ['offset_drift']),
                                              ('delay+drift', [])])
def test_a_block_the_others_make_redundant_is_withdrawn_at_the_end(effects, dropped):
    data, order, current = _two_blocks(effects)
    final, out = drop_superseded(current, list(order), data, Criteria(), max_nfev=1200)
    assert out == dropped
    assert set(final.ids) == set(order) - set(dropped)
    assert final.er_holdout_percent < 1.2 * data.floor_holdout_percent


def _held_out_off(fit, data, shift):
    """``fit`` with its held-out prediction moved by ``shift``: a chain as good on training."""
    pred = fit.prediction.copy()
    pred[data.n_train:] += shift
    res = data.y - pred
    ho = res[data.n_train:]
    return replace(fit, prediction=pred, residual=res, sse_holdout=float(ho @ ho))


def equivalent_case(shift_sigmas: float, seed: int = 3, probe: int | None = None):
    """The rule on a clean record against a chain as good on training, off on held-out.

    The current model is the truth's polish with its held-out prediction moved by
    ``shift_sigmas`` noise std; an ``offset_drift`` fit from the truth is the only
    candidate. ``probe`` perturbs the measurement by 1e-12 relative (another CPU's
    last bits). Returns the data, the current model, the gain the shift costs on the
    judged held-out samples, and what :func:`equivalent_chain` returns.
    """
    data, base, m, model = make_case(0.0, seed)
    if probe is not None:
        data.y = data.y * (1.0 + 1e-12 * np.random.default_rng([probe, seed]).standard_normal(
            data.y.size))
    truth = evaluate(base, data, polish(base, data, TRUTH, max_nfev=1200)[0])
    current = _held_out_off(truth, data, shift_sigmas * data.noise_std)
    fit = fit_model(model, data, model.pack(TRUTH, {}), m, budget=600)
    comp = compare(current, fit, data, m.id, Criteria())
    gain = 1.0 - data.judged_er_percent(truth) / data.judged_er_percent(current)
    return data, current, gain, equivalent_chain([comp], current, data, Criteria(),
                                                 max_nfev=1200)


@pytest.mark.parametrize('shift_sigmas, chosen', [(0.0, False), (0.2, False), (3.0, True)])
def test_an_equally_good_chain_that_predicts_better_is_chosen(shift_sigmas, chosen):
    """With no block accepted, an equally good chain that predicts held-out better is chosen.

    The chain the block's fit found replaces one that fits training as well and misses
    held-out by ``shift_sigmas`` noise std (3: chosen; 0 and 0.2, below the acceptance
    test's 5 % gain: kept). Spread from ``bench/null_control_spread.py`` (8 noise seeds x
    4 round-off conditions): a shift of 0.2 std costs 0.4-3.1 % held-out gain (criterion
    5 %), never chosen; 3 std chosen 32/32 with the refit at 0.98-1.04 x the floor (bound
    1.2) and its training BIC -4.7 to +5.1 against the current one (bound +10, the
    criteria's ``bic_drop``; with +2 the test's own seed failed under round-off probe 2).
    """
    data, current, _, other = equivalent_case(shift_sigmas)
    assert (other is not None) == chosen
    if chosen:
        n = data.n_train
        assert other.ids == current.ids
        assert other.bic(n) <= current.bic(n) + Criteria().bic_drop
        assert other.er_holdout_percent < 1.2 * data.floor_holdout_percent
