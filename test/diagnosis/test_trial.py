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

"""A round's candidate fits are the same in worker processes as in one process.

:func:`hyst_id.diagnosis.trial.try_all` hands the mechanisms to workers (the
costliest first) when ``settings.workers`` is not 1; each fit is computed as
in one process and the comparisons come back in the order given, so the
round, and with it the diagnosis, does not depend on the number of workers.
Exact equality is asserted: the same arithmetic runs in either case.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from reference_sim import simulate as reference_simulate

from hyst_id.diagnosis import trial
from hyst_id.diagnosis.locate import locate
from hyst_id.diagnosis.mechanisms import Context, get_mechanisms
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.result import DiagnoseSettings
from hyst_id.diagnosis.select import Data, evaluate
from hyst_id.diagnosis.trial import polish_all, try_all
from hyst_id.identification.chains import chain_spec
from hyst_id.identification.workers import map_in_processes
from hyst_id.signals.excitation import multisine

NAMES = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b', 'm_bl', 'c_bl', 'c_br')
TRUTH = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])


def delayed_case(seed: int = 4, probe: int | None = None):
    """A 0.2 s dead time before the reference chain: data, context, the chain alone, located.

    ``probe`` perturbs the measurement by 1e-12 relative (another CPU's last bits).
    """
    t = np.arange(0.0, 60.0, 0.05)
    v = multisine(t, amplitude_ma=1.8)
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, np.interp(t - 0.2, t, v))
    sigma = 0.004 * np.ptp(x)
    y = x + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    if probe is not None:
        y = y * (1.0 + 1e-12 * np.random.default_rng([probe, seed]).standard_normal(y.size))
    n = int(0.7 * t.size)
    ctx = Context('position', t, n)
    data = Data(t_s=t, v=v, y=y, n_train=n, noise_std=sigma)
    current = evaluate(ComposedModel('position', [], ctx, chain_spec('position').bounds),
                       data, TRUTH)
    return data, ctx, current, locate(t, v, y, current.prediction, sigma, n, None)


def test_a_round_in_two_processes_equals_the_round_in_one():
    """Equal comparisons, in order; the dead time is accepted (a round that decides).

    ``bench/trial_spread.py`` (8 noise seeds x 4 round-off conditions): the
    dead-time block's held-out z 74.6-78.2 (criterion 4), training delta BIC
    -2613 to -2498 (criterion -10), accepted 32/32.
    """
    data, ctx, current, loc = delayed_case()
    mechs = get_mechanisms(('offset_drift', 'dead_time', 'sensor_lag', 'saturation'),
                           channel='position')
    settings = DiagnoseSettings(fit_budget=300)
    lines: list[str] = []
    rounds = [try_all(mechs, current, data, ctx, replace(settings, workers=w), loc, [],
                      lines.append) for w in (1, 2)]
    assert [c.mechanism for c in rounds[1]] == [m.id for m in mechs]
    for one, two in zip(*rounds):
        assert (one.mechanism, one.status, one.accepted) == (two.mechanism, two.status,
                                                             two.accepted)
        np.testing.assert_array_equal(one.fit.p, two.fit.p)
        assert one.fit.sse_train == two.fit.sse_train
        assert one.holdout_z == two.holdout_z
    assert any('in 2 processes' in line for line in lines)
    assert next(c for c in rounds[1] if c.mechanism == 'dead_time').accepted


def test_the_baseline_polishes_in_two_processes_equal_those_in_one(monkeypatch):
    t = np.arange(0.0, 40.0, 0.05)
    v = multisine(t, amplitude_ma=1.8)
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, v)
    sigma = 0.004 * np.ptp(x)
    y = x + np.random.default_rng(5).normal(0.0, sigma, t.size)
    ctx = Context('position', t, int(0.7 * t.size))
    data = Data(t_s=t, v=v, y=y, n_train=ctx.n_train, noise_std=sigma)
    model = ComposedModel('position', [], ctx, chain_spec('position').bounds)
    starts = [TRUTH * f for f in (0.97, 1.0, 1.03)]
    pairs = [(model, x0) for x0 in starts]
    calls = []

    def spy(fn, args, n, **kw):
        calls.append(n)
        return map_in_processes(fn, args, n, **kw)

    monkeypatch.setattr(trial, 'map_in_processes', spy)
    one, two = (polish_all(pairs, data, 200, w) for w in (1, 2))
    assert calls == [2]                 # one process: no pool; two: one pool of two
    for a, b in zip(one, two):
        np.testing.assert_array_equal(a[0], b[0])
        assert a[1:] == b[1:]


def test_a_family_swaps_search_comes_back_from_its_worker_and_is_not_repeated(monkeypatch):
    """The swap's quick search, made in a worker, serves the next round in the parent.

    After a round in two processes the parent holds the search
    (:func:`hyst_id.diagnosis.baseline.remember`); the same trial again, with
    any new search made to fail, gives the same fit to the last bit.
    """
    from hyst_id.diagnosis import baseline

    data, ctx, current, loc = delayed_case()
    mechs = get_mechanisms(('loop_shape', 'dead_time'), channel='position')
    settings = DiagnoseSettings(fit_budget=200)
    first = try_all(mechs, current, data, ctx, replace(settings, workers=2), loc, [])
    assert len(baseline.quick_memo()) == 1      # carried home from the worker

    def no_search(*args, **kwargs):
        raise AssertionError('the quick search ran again')

    monkeypatch.setattr(baseline, 'baseline_starts', no_search)
    again = try_all(mechs[:1], current, data, ctx, replace(settings, workers=1), loc, [])
    np.testing.assert_array_equal(again[0].fit.p, first[0].fit.p)
    assert again[0].fit.sse_train == first[0].fit.sse_train


def test_a_block_that_fits_as_another_is_judged_on_that_fit_made_once(monkeypatch):
    """``bouc_wen`` fits as ``friction``: in a round with both, the fit is made once.

    Its comparison is the one its own fit gives (the same arithmetic under another name),
    judged in its own sense; ``friction``'s is unchanged.
    """
    data, ctx, current, loc = delayed_case()
    both = get_mechanisms(('friction', 'bouc_wen'), channel='position')
    settings = DiagnoseSettings(fit_budget=200, workers=1)
    alone = [try_all([m], current, data, ctx, settings, loc, [])[0] for m in both]
    fitted, lines = [], []
    real = trial.try_mechanism

    def counted(m, *args):
        fitted.append(m.id)
        return real(m, *args)

    monkeypatch.setattr(trial, 'try_mechanism', counted)
    round_ = try_all(both, current, data, ctx, settings, loc, [], lines.append)
    assert fitted == ['friction']
    assert any('bouc_wen: the fit of friction' in line for line in lines)
    for own, shared in zip(alone, round_):
        assert (own.mechanism, own.status, own.accepted) == (shared.mechanism, shared.status,
                                                             shared.accepted)
        np.testing.assert_array_equal(own.fit.p, shared.fit.p)
        np.testing.assert_array_equal(own.fit.coef, shared.fit.coef)
        assert own.fit.labels == shared.fit.labels and own.holdout_z == shared.holdout_z
    assert 'bouc_wen:0' in round_[1].fit.labels and round_[1].fit.model.ids[-1] == 'bouc_wen'


def test_the_words_take_the_training_measurements_median_not_the_fits():
    """``driver._info`` passes on the median the driver took of the measurement.

    It had taken the fitted prediction's, where the supply decay's doubt
    (``trial.judge``) reads the measurement's
    (``test_time_gain_words.py::test_the_doubt_and_the_words_read_the_same_middle``).
    """
    from hyst_id.diagnosis.driver import _info

    data, ctx, current, _ = delayed_case()
    measured = float(np.median(data.y[:data.n_train]))
    ctx.extra['readings_median'] = measured
    assert float(np.median(current.prediction[:data.n_train])) != measured
    assert _info(current, ctx, data.v)['readings_median'] == measured
