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

"""Taking accepted blocks out of a record, and re-identifying the chain there (issue 14, 4).

:meth:`Mechanism.undo` must leave exactly what the chain alone explains: for
every block of the library that can be inverted on data, a record made by the
chain with the block (no noise) and undone is fitted by the chain alone to
round-off. :func:`reidentify` searches the chain again on the undone record;
it is never worse on the training part than the fit it starts from.
"""

from __future__ import annotations

from excitations import moves_and_holds
import numpy as np
import pytest
from reference_sim import simulate as reference_simulate

from hyst_id.diagnosis.mechanisms import Context, MECHANISMS
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.refit import reidentify, undone_record
from hyst_id.diagnosis.result import DiagnoseSettings
from hyst_id.diagnosis.select import Data, evaluate, fit_model, polish, solve_linear
from hyst_id.identification.chains import chain_spec
from hyst_id.signals.noise import floor_percent

NAMES = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b', 'm_bl', 'c_bl', 'c_br')
TRUTH = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])

#: Blocks inverted on data (the others' ``undo`` is None by design: filters, end stops,
#: a replaced actuator or a map of the position are not inverted on noisy samples).
INVERTIBLE = {'dead_time', 'offset_drift', 'gain_drift', 'gain_loss', 'supply_decay', 'creep',
              'friction', 'bouc_wen', 'rate_limit'}


def _record(t):
    """Sine sweeps whose envelope covers the held-out range within the training part."""
    return 9.0 + 3.0 * np.sin(2 * np.pi * t / 10.0) * (0.7 + 0.3 * np.sin(2 * np.pi * t / 47.0))


@pytest.mark.parametrize('mech_id', sorted(MECHANISMS))
def test_undo_leaves_what_the_chain_alone_explains(mech_id):
    m = MECHANISMS[mech_id]
    t = np.arange(0.0, 60.0, 0.05)
    v = _record(t)
    ctx = Context('position', t, 840)
    spec = chain_spec('position')
    model = ComposedModel('position', [m], ctx, spec.bounds)
    theta = m.starts(ctx)[0] if m.starts(ctx) else m.null(ctx)
    p = model.pack(TRUTH, {m.id: theta})
    ev = model.evaluate(p, t, v, ctx.n_train)
    a = ev.matrix()
    coef = np.linspace(1.5, 0.5, a.shape[1]) * np.where(np.arange(a.shape[1]) % 2, -1, 1)
    coef[0] = 40.0                                  # the sensor's gain, a reading in um
    y = a @ coef
    data = Data(t_s=t, v=v, y=y, n_train=ctx.n_train)
    fit = evaluate(model, data, p)
    v_u, y_u, done = undone_record(fit, data, ctx)
    if m.id not in INVERTIBLE:
        assert done == [] and v_u is v and y_u is y
        return
    assert done == [m.id]
    base = ComposedModel('position', [], ctx, spec.bounds)
    a0 = base.evaluate(TRUTH, t, v_u, ctx.n_train).matrix()
    _, sse = solve_linear(a0, y_u)
    assert sse <= 1e-16 * float(y_u @ y_u)


@pytest.mark.parametrize('gain_id', ['gain_drift', 'gain_loss', 'supply_decay'])
def test_a_gain_in_time_undone_before_friction_leaves_the_chain_alone(gain_id):
    """The gain is divided out of friction's term too; neither undo nor undo_terms edits terms."""
    gain, friction = MECHANISMS[gain_id], MECHANISMS['friction']
    t = np.arange(0.0, 60.0, 0.05)
    v = _record(t)
    ctx = Context('position', t, 840)
    spec = chain_spec('position')
    model = ComposedModel('position', [friction, gain], ctx, spec.bounds)
    thetas = {m.id: m.starts(ctx)[0] for m in (friction, gain)}
    p = model.pack(TRUTH, thetas)
    a = model.evaluate(p, t, v, ctx.n_train).matrix()
    coef = np.linspace(1.5, 0.5, a.shape[1])
    coef[0] = 3.0
    y = a @ coef
    data = Data(t_s=t, v=v, y=y, n_train=ctx.n_train)
    fit = evaluate(model, data, p)
    before = model.evaluate(fit.p, t, v, ctx.n_train).matrix() * fit.coef
    v_u, y_u, done = undone_record(fit, data, ctx)
    assert sorted(done) == sorted([gain_id, 'friction'])
    base = ComposedModel('position', [], ctx, spec.bounds)
    a0 = base.evaluate(TRUTH, t, v_u, ctx.n_train).matrix()
    _, sse = solve_linear(a0, y_u)
    assert sse <= 1e-16 * float(y_u @ y_u)
    terms = dict(zip(fit.labels, before.T))
    kept = {k: c.copy() for k, c in terms.items()}
    theta = model.theta(fit.p, gain_id)
    assert gain.undo(theta, t, v, y, terms, ctx) is not None
    assert all(np.array_equal(terms[k], kept[k]) for k in kept)    # undo leaves them be
    out = gain.undo_terms(theta, t, terms, ctx)
    assert out is not terms and all(np.array_equal(terms[k], kept[k]) for k in kept)
    assert friction.undo_terms(theta, t, terms, ctx) is not terms
    assert not np.allclose(out['friction:0'], terms['friction:0'])


def _drifting(seed: int):
    """Moves and holds read through a gain growing about a distant zero (the blind family's #42).

    The fit of a drift block warm-started from a chain that the drift biased stops short of
    the floor there; the chain re-identified with the drift taken out does not.
    """
    t = np.arange(0.0, 100.0, 0.05)
    rng = np.random.default_rng(seed)
    v = moves_and_holds(rng, t, dwell_s=4.0, move_s=0.5, n_levels=25, lo=6.5, hi=11.5)
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, v)
    y = 30.0 * (x + 8.0) * (1.0 + 0.0008 * t)
    sigma = 0.003 * np.ptp(y)
    y = y + rng.normal(0.0, sigma, t.size)
    n = int(0.7 * t.size)
    return t, v, y, n, sigma


#: Noise seeds of :func:`_drifting` whose local fit stopped short (``python bench/refit_spread.py
#: --seeds 8 --probes 1``: 1.8-7.8 x the training floor on seeds 1, 4, 5, 6 unperturbed, on 1
#: and 5 also under the probe); re-identified: 0.968-1.009 x everywhere.
STUCK_SEEDS = (1, 4, 5)
#: The chain the drift-free fit would start from, biased as a drift biases it.
BIASED = TRUTH + np.array([0.0, 0.0, 0.02, 0.0, 0.0, 0.15, 0.0, 0.0, 0.0, 0.0, 0.0])


#: A local fit above this many training floors counts as stopped short.
REFIT_ABOVE_TEST = 1.5


def _local_fit(seed: int, probe: int | None = None):
    """The gain drift block fitted locally from a chain polished from :data:`BIASED`.

    ``probe`` perturbs the measurement by 1e-12 relative (another CPU's last bits).
    """
    t, v, y, n, sigma = _drifting(seed)
    if probe is not None:
        y = y * (1.0 + 1e-12 * np.random.default_rng([probe, seed]).standard_normal(y.size))
    ctx = Context('position', t, n)
    data = Data(t_s=t, v=v, y=y, n_train=n, noise_std=sigma)
    spec = chain_spec('position')
    base = ComposedModel('position', [], ctx, spec.bounds)
    baseline = evaluate(base, data, polish(base, data, BIASED, max_nfev=1200)[0])
    m = MECHANISMS['gain_drift']
    model = ComposedModel('position', [m], ctx, spec.bounds)
    local = fit_model(model, data, model.pack(baseline.p, {}), m, budget=600)
    return data, ctx, spec, local, floor_percent(y[:n], sigma)


@pytest.mark.slow
@pytest.mark.parametrize('seed', STUCK_SEEDS)
def test_a_drift_block_reidentified_reaches_the_floor(seed):
    data, ctx, spec, local, floor = _local_fit(seed)
    said: list[str] = []
    again = reidentify(local, data, ctx, spec, DiagnoseSettings(), floor_train_percent=floor,
                       say=said.append)
    assert said and said[0] == ('re-identifying the chain with GAASS seeds on the record '
                                'with gain_drift undone')
    assert again.sse_train <= local.sse_train
    assert again.er_train_percent <= 1.1 * floor, (local.er_train_percent / floor,
                                                   again.er_train_percent / floor)
    rate = float(again.model.theta(again.p, 'gain_drift')[0])
    assert rate == pytest.approx(0.0008, rel=0.1)


@pytest.mark.slow
def test_the_drift_seeds_do_stop_short_locally():
    """The recovery test exercises the re-identification: the local fit alone stops short."""
    short = []
    for seed in STUCK_SEEDS:
        _, _, _, local, floor = _local_fit(seed)
        short.append(local.er_train_percent / floor)
    assert max(short) > REFIT_ABOVE_TEST, short


@pytest.mark.parametrize('blocks', [(), ('sensor_lag',), ('gain_drift',)])
def test_what_cannot_be_or_need_not_be_reidentified_is_returned_as_it_is(blocks):
    """No block, no invertible block, or a fit already within the floor: nothing to search."""
    t = np.arange(0.0, 60.0, 0.05)
    v = _record(t)
    ctx = Context('position', t, 840)
    spec = chain_spec('position')
    model = ComposedModel('position', [MECHANISMS[b] for b in blocks], ctx, spec.bounds)
    y = 30.0 * reference_simulate('position', dict(zip(NAMES, TRUTH)), t, v)
    y = y + np.random.default_rng(0).normal(0.0, 0.01, t.size)
    data = Data(t_s=t, v=v, y=y, n_train=ctx.n_train, noise_std=0.01)
    fit = evaluate(model, data, model.pack(TRUTH, {}))
    floor = floor_percent(y[:ctx.n_train], 0.01)
    # far from the floor (a 0.01 floor), yet nothing to undo; or within a generous one
    tight = 0.01 * floor if blocks != ('gain_drift',) else 2.0 * fit.er_train_percent
    assert reidentify(fit, data, ctx, spec, DiagnoseSettings(),
                      floor_train_percent=tight) is fit
