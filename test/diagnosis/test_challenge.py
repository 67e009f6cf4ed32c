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

"""The challenge of a claim that gains little (:mod:`hyst_id.diagnosis.challenge`).

The wider chain search is replaced by a stand-in returning a prepared fit, so
these check the rule: who faces it, and when the claims fall.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hyst_id.diagnosis import challenge as challenge_module
from hyst_id.diagnosis import DiagnoseSettings
from hyst_id.diagnosis.challenge import challenge, CHALLENGE_FACTOR, withdrawn_note
from hyst_id.diagnosis.select import Data, FitResult

__all__: list[str] = []

SIGMA = 0.01


def _data(n=1000, n_train=700, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.05
    truth = 5.0 + np.sin(t)
    return Data(t, 9 + np.sin(t), truth + rng.normal(0, SIGMA, n), n_train,
                noise_std=SIGMA), truth


def _fit(data, prediction, n_free):
    r = data.y - prediction
    n = data.n_train
    return FitResult(ids=(), p=np.zeros(1), coef=np.zeros(1), labels=[],
                     prediction=prediction, residual=r, sse_train=float(r[:n] @ r[:n]),
                     sse_holdout=float(r[n:] @ r[n:]), n_free=n_free, er_train_percent=1.0,
                     er_holdout_percent=1.0, span=(0.0, 1.0), travel_raw=np.zeros(1))


def _fits(bias_sigmas):
    """Final model at the truth; a baseline off it by ``bias_sigmas`` noise std (a slow wave)."""
    data, truth = _data()
    wave = np.sqrt(2.0) * np.sin(0.37 * data.t_s + 0.3)
    final = _fit(data, truth, n_free=12)
    baseline = _fit(data, truth + bias_sigmas * SIGMA * wave, n_free=10)
    return data, final, baseline


def _run(monkeypatch, data, final, baseline, wider, settings=None, split_short=False):
    calls = []

    def fake_chain_fit(rec_train, spec, settings, data, ctx):
        calls.append(settings.more_starts)
        if wider is None:
            raise AssertionError('the wider search was not to run')
        return wider, []

    monkeypatch.setattr(challenge_module, 'chain_fit', fake_chain_fit)
    got = challenge(final, baseline, None, None, settings or DiagnoseSettings(), data, None,
                    split_short=split_short)
    return got, calls


def test_the_claims_fall_when_the_wider_chain_predicts_as_well(monkeypatch):
    data, final, baseline = _fits(0.7)         # baseline ~1.2 x the floor: it faces the rule
    ratio = data.judged_er_percent(baseline) / data.floor_holdout_percent
    assert 1.1 < ratio < CHALLENGE_FACTOR
    wider = _fit(data, final.prediction + 0.05 * SIGMA, n_free=10)
    got, calls = _run(monkeypatch, data, final, baseline, wider)
    assert calls == [True]                     # searched with more_starts
    assert got is not None and got[0] is wider
    assert got[1].holdout_z < 4.0 and not got[1].accepted
    note = withdrawn_note(['dead_time'], *got, data)
    assert note.startswith('dead_time accepted in the rounds and withdrawn')


def test_the_claims_stand_when_the_wider_chain_finds_nothing_better(monkeypatch):
    data, final, baseline = _fits(0.7)
    got, calls = _run(monkeypatch, data, final, baseline, baseline)
    assert calls == [True]
    assert got is None


def test_a_chain_better_on_training_only_leaves_the_claims_standing(monkeypatch):
    """The final model predicts the held-out part better: a training-only win does not count."""
    data, final, baseline = _fits(0.7)
    wider = _fit(data, baseline.prediction, n_free=10)
    wider.sse_train = 0.5 * final.sse_train      # fits the training part far better (BIC)
    got, calls = _run(monkeypatch, data, final, baseline, wider)
    assert calls == [True] and got is None


def test_the_better_of_the_wider_search_and_the_baseline_is_the_chain(monkeypatch):
    """A wider search that fits the training part worse than the baseline does not replace it."""
    data, final, baseline = _fits(0.7)
    worse = _fit(data, final.prediction + 0.05 * SIGMA, n_free=10)   # predicts as well...
    worse.sse_train = 2.0 * baseline.sse_train                         # ...but fits worse
    got, calls = _run(monkeypatch, data, final, baseline, worse)
    assert calls == [True] and got is None       # against the baseline the claims stand


def test_a_short_split_is_not_challenged(monkeypatch):
    """Rounds decided over time blocks are not overruled by the split alone."""
    data, final, baseline = _fits(0.7)
    got, calls = _run(monkeypatch, data, final, baseline, None, split_short=True)
    assert got is None and calls == []


@pytest.mark.parametrize('bias_sigmas', [2.0, 5.0])
def test_a_baseline_far_above_the_floor_is_not_challenged(monkeypatch, bias_sigmas):
    data, final, baseline = _fits(bias_sigmas)
    assert data.judged_er_percent(baseline) > CHALLENGE_FACTOR * data.floor_holdout_percent
    got, calls = _run(monkeypatch, data, final, baseline, None)
    assert got is None and calls == []


def test_a_diagnosis_with_more_starts_is_not_challenged_again(monkeypatch):
    data, final, baseline = _fits(0.7)
    got, calls = _run(monkeypatch, data, final, baseline, None,
                      DiagnoseSettings(more_starts=True))
    assert got is None and calls == []


def test_the_withdrawal_clause_says_was_or_were_and_takes_a_detail():
    from types import SimpleNamespace

    from hyst_id.diagnosis.report import _withdrawn_clause, _withdrawn_lines
    two = _withdrawn_clause(['creep', 'dead_time'])
    assert two.startswith('creep and dead_time improved on the baseline (table below) but were '
                          'withdrawn: '), two
    d = SimpleNamespace(extra={'withdrawn': ['creep']})
    assert _withdrawn_lines(d) == [f"  - {_withdrawn_clause(['creep'])}"]
    assert 'but was withdrawn' in _withdrawn_lines(d)[0]
    assert _withdrawn_lines(SimpleNamespace(extra={})) == []
    assert _withdrawn_clause(['creep'], '1.02 x').endswith('(note below; 1.02 x)')


@pytest.mark.slow
def test_a_diagnosis_whose_claims_fall_says_so(monkeypatch):
    """In the driver: no finding, verdict none, the withdrawn ids in the JSON and the report."""
    from hyst_id.diagnosis import diagnose, driver
    from hyst_id.diagnosis.select import compare
    from test_diagnose import FAST, synthetic

    seen = []

    def fall(final, baseline, rec_train, spec, settings, data, ctx, say, split_short):
        seen.append(final.ids)
        wider = replace(final, ids=())          # a chain alone that predicts as well
        return wider, compare(wider, final, data, 'final model', settings.criteria)

    monkeypatch.setattr(driver, 'challenge', fall)
    d = diagnose(synthetic('dead_time', seed=4), settings=FAST)
    assert seen == [('dead_time',)]
    assert d.verdict == 'none' and d.findings == []
    assert d.extra['withdrawn'] == ['dead_time']
    assert d.to_dict()['withdrawn'] == ['dead_time']
    text = d.report()
    assert ('verdict: none - dead_time improved on the baseline (table below) but was withdrawn: '
            'the chain alone, searched again with more data-built starts, predicts the judged '
            'held-out part as well (note below; ') in text, text
    assert 'dead_time accepted in the rounds and withdrawn at the end' in text
    assert 'final model: the same chain, from a wider search' in text
    assert 'accepted (chosen, withdrawn)' in text
