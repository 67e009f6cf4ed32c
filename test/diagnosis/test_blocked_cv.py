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

"""Blocked cross-validation: each time block predicted by a refit on the others.

These tests check the machinery (the block's outputs never reach its fit, the
judged rows, the comparison) on records the composed model itself makes; what
it says on records of the independent reference simulator is in
``test_blind_calls.py`` and ``docs/diagnosis.md``.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from hyst_id.diagnosis.blocked_cv import (
    block_predictions, BlockedCV, compare_blocked, confirm, confirmed, split_record, summary)
from hyst_id.diagnosis.mechanisms import Context, MECHANISMS
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.report import _alternative_lines
from hyst_id.diagnosis.select import Comparison, Data, evaluate
from hyst_id.errors import ConfigError
from hyst_id.identification.chains import chain_spec
from hyst_id.signals.excitation import multisine

__all__: list[str] = []

CHAIN = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])
NOISE = 0.005


def _record(amplitude_ma: np.ndarray | float = 1.8, delay_s: float = 0.2, seed: int = 0,
            sweep_s: float = 0.0):
    t = np.arange(0.0, 120.0, 0.05)
    v = multisine(t, amplitude_ma=1.8) * np.ones_like(t)
    v = 9.0 + (v - 9.0) * amplitude_ma if np.ndim(amplitude_ma) else v
    first = t < sweep_s           # a large sine first: it sweeps the whole command range
    v[first] = 9.0 + 2.2 * np.sin(2.0 * np.pi * t[first] / sweep_s) if sweep_s else v[first]
    ctx = Context('position', t, int(0.7 * t.size))
    delayed = ComposedModel('position', [MECHANISMS['dead_time']], ctx,
                            chain_spec('position').bounds)
    p_true = np.concatenate([CHAIN, [delay_s]])
    y = delayed.evaluate(p_true, t, v, ctx.n_train).matrix()[:, 0]
    y = y + np.random.default_rng(seed).normal(0.0, NOISE, t.size)
    data = Data(t_s=t, v=v, y=y, n_train=ctx.n_train, noise_std=NOISE)
    plain = ComposedModel('position', [], ctx, chain_spec('position').bounds)
    return data, evaluate(plain, data, CHAIN), evaluate(delayed, data, p_true)


def test_a_model_against_itself_is_neither_better_nor_worse():
    data, plain, _ = _record()
    a = block_predictions(plain, data)
    cv = compare_blocked(a, a, data)
    assert cv.better == 0 and cv.worse == 0 and cv.z == [0.0] * 4
    np.testing.assert_array_equal(cv.er_a_percent, cv.er_b_percent)
    assert len(a.bounds) == 4 and a.bounds[0][0] == 0 and a.bounds[-1][1] == data.y.size


def test_the_true_block_is_confirmed_in_every_block():
    data, plain, delayed = _record()
    cv = confirm(plain, delayed, data)
    assert cv['blocks'] == 3 and cv['n_judged'][0] == 0    # the first quarter: not swept
    assert cv['n_unswept'][0] + cv['n_extrapolated'][0] == 600
    assert 'before the command swept the range' in summary(cv)
    assert cv['better'] == 3 and cv['worse'] == 0, cv
    assert all(b < 0.8 * a for a, b in zip(cv['er_a_percent'][1:], cv['er_b_percent'][1:]))
    back = confirm(delayed, plain, data)     # the other way round: worse everywhere
    assert back['better'] == 0 and back['worse'] == 3
    assert 'better in 3, worse in 0' in summary(cv)
    assert confirmed(cv) and not confirmed(back) and confirmed({})


def test_the_first_block_is_judged_once_the_command_has_swept_its_range():
    data, plain, delayed = _record(sweep_s=10.0)
    p = block_predictions(delayed, data)
    assert 0 < p.judged[0].size < p.bounds[0][1]
    first = int(p.judged[0][0])
    rest = data.v[p.bounds[1][0]:]
    assert 2.0 < data.t_s[first] < 10.0     # after the sine's trough, 3/4 of its period
    margin = 0.02 * np.ptp(rest)       # block_predictions' tol
    assert data.v[:first + 1].min() <= rest.min() + margin
    assert data.v[:first + 1].max() >= rest.max() - margin
    assert not (data.v[:first].min() <= rest.min() + margin
                and data.v[:first].max() >= rest.max() - margin)
    cv = confirm(plain, delayed, data)
    assert cv['blocks'] == 4 and cv['better'] == 4 and cv['worse'] == 0, cv


def test_a_block_s_outputs_never_reach_its_fit():
    """Through the residuals and the linear solve; both runs start from the same values.

    (The start itself comes from a fit on the training part: the module's
    docstring says what that means for the first blocks.)
    """
    data, _, delayed = _record()
    before = block_predictions(delayed, data)
    a, b = before.bounds[2]
    spoiled = Data(t_s=data.t_s, v=data.v, y=data.y.copy(), n_train=data.n_train,
                   noise_std=data.noise_std)
    spoiled.y[a:b] += 5.0        # a gross error inside block 3 only
    after = block_predictions(delayed, spoiled)
    np.testing.assert_allclose(after.prediction[a:b], before.prediction[a:b], rtol=0,
                               atol=1e-9)
    assert not np.allclose(after.prediction[:a], before.prediction[:a], rtol=0, atol=1e-9)


def test_commands_outside_the_fitted_range_are_reported_apart():
    t = np.arange(0.0, 120.0, 0.05)
    grow = np.where(t > 90.0, 1.5, 1.0)   # the last block's command goes beyond the others'
    data, plain, delayed = _record(amplitude_ma=grow)
    p = block_predictions(delayed, data)
    assert p.n_extrapolated[1:3] == [0, 0]
    assert p.n_extrapolated[3] > 0
    a, b = p.bounds[3]
    assert p.judged[3].size + p.n_extrapolated[3] == b - a
    cv = confirm(plain, delayed, data)
    assert cv['n_extrapolated'][3] == p.n_extrapolated[3]
    assert 'outside the fitted command range not judged' in summary(cv)


@pytest.mark.parametrize('n_blocks', [3, 5])
def test_any_number_of_blocks_covers_the_record(n_blocks):
    data, plain, _ = _record()
    p = block_predictions(plain, data, n_blocks=n_blocks, max_nfev=5)
    assert len(p.bounds) == n_blocks
    assert all(p.bounds[k][1] == p.bounds[k + 1][0] for k in range(n_blocks - 1))
    assert (sum(j.size for j in p.judged) + sum(p.n_extrapolated) + sum(p.n_unswept)
            == data.y.size)


@pytest.mark.parametrize('n_blocks', [1, 0, 10_000])
def test_an_impossible_number_of_blocks_is_a_config_error(n_blocks):
    data, plain, _ = _record()
    with pytest.raises(ConfigError, match='blocks'):
        block_predictions(plain, data, n_blocks=n_blocks)


def test_diagnostics_say_when_a_finding_is_not_confirmed():
    from hyst_id.live.documents import diagnosis_statuses

    def doc(better, worse):
        return {'verdict': 'unknown', 'findings': [{
            'mechanism': 'dead_time', 'explanation': 'a delay',
            'blocked_cv': {'blocks': 4, 'better': better, 'worse': worse}}]}

    (_, _, message, values), = diagnosis_statuses(doc(1, 3))
    assert values['confirmed'] == 'false' and message.startswith('not confirmed')
    assert values['blocked_cv'] == 'better in 1, worse in 3 of 4 time blocks'
    (_, _, message, values), = diagnosis_statuses(doc(3, 1))
    assert 'confirmed' not in values and message == 'a delay'
    assert not confirmed({'better': 2, 'worse': 2}) and confirmed({'better': 3, 'worse': 1})
    assert confirmed({'better': 0, 'worse': 1})      # one block is not enough against it
    assert confirmed({'blocks': 0}) and confirmed({'worse': None, 'better': None})


def _comparison(name, fit):
    return Comparison(mechanism=name, fit=fit, delta_bic=0.0, holdout_z=0.0, gain=0.0,
                      accepted=True, status='accepted')


def _short_split(data, n_judged):
    """The same record, its split judging only the first ``n_judged`` held-out samples."""
    return Data(t_s=data.t_s, v=data.v, y=data.y, n_train=data.n_train,
                noise_std=data.noise_std, judged=np.arange(data.n_train, data.n_train + n_judged))


def test_time_blocks_decide_a_round_only_when_the_split_judged_too_little():
    full, plain, delayed = _record()
    short = _short_split(full, 60)            # 60 of 720 held-out samples
    assert not BlockedCV(full).split_short and BlockedCV(short).split_short
    wrong, right = _comparison('creep', plain), _comparison('dead_time', delayed)
    # the split's winner stands when the split judged most of its held-out part
    assert BlockedCV(full).decide(wrong, [right]) == (wrong, {})
    cv = BlockedCV(short)
    chosen, record = cv.decide(wrong, [right])
    assert chosen is right and record['over'] == 'creep'
    assert record['better'] == record['blocks'] == 3 and record['worse'] == 0
    assert cv.decide(right, [wrong]) == (right, {})       # never towards the worse model
    assert cv.decide(right, []) == (right, {})
    assert cv.beats(plain, delayed) is not None and cv.beats(delayed, plain) is None
    assert cv.beats(plain, plain) is None                 # the same model is not better
    alt = split_record(wrong, right, short, record)
    assert alt['kind'] == 'split' and (alt['n_judged'], alt['n_holdout']) == (60, 720)
    finding = SimpleNamespace(mechanism='dead_time', alternatives=[alt],
                              er_holdout_after_percent=right.fit.er_holdout_percent)
    line, = _alternative_lines(finding)
    assert 'a judgement call: creep was the choice of the judged held-out samples' in line
    assert line.count(' against ') == 3          # the three judged quarters' %e_r
    assert 'the split judged only 60 of 720' in line
    assert 'dead_time predicts all 3 judged blocks better' in line
    from hyst_id.io.jsonable import jsonable
    from hyst_id.live.documents import diagnosis_statuses
    doc = {'verdict': 'dead_time', 'findings': [{
        'mechanism': 'dead_time', 'explanation': 'a delay', 'alternatives': jsonable([alt])}]}
    (_, _, _, values), = diagnosis_statuses(doc)
    assert values['judgement_call'] == 'creep'
