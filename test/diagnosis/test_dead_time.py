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

"""A delay under one sample interval is not claimed as a transport delay.

A new user's review (docs/reliability.md section 10): a sum of plays behind a
tanh map, driven by a chirp, was given ``dead_time`` 0.005 s = 0.50 samples,
and the compensator an ``augment.dead_time_s``; the recording had no delay.
Interpolated between samples, a half-sample delay averages each command with
the one before (a smoothing that soaks up misfit). The chain here is the
reference's (``test/reference_sim``), fitted at its true values.
"""

from __future__ import annotations

import numpy as np
import pytest
from reference_sim import simulate as reference_simulate

from hyst_id.diagnosis.locate import locate
from hyst_id.diagnosis.mechanisms import Context, get_mechanisms
from hyst_id.diagnosis.mechanisms.dead_time import MIN_DELAY_SAMPLES
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.result import DiagnoseSettings
from hyst_id.diagnosis.select import Data, evaluate
from hyst_id.diagnosis.trial import try_mechanism
from hyst_id.identification.chains import chain_spec
from hyst_id.signals.excitation import multisine

__all__: list[str] = []

NAMES = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b', 'm_bl', 'c_bl', 'c_br')
TRUTH = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])
DT_S = 0.05


def test_the_rule_reads_the_delay_in_sample_intervals():
    m = get_mechanisms(('dead_time',), channel='position')[0]
    ctx = Context('position', np.arange(0.0, 10.0, DT_S), 140)
    assert 'sample intervals' in m.implausible(np.array([0.5 * DT_S]), None, (0, 1), 0.1, ctx)
    # either side of the rule, not on it (the median interval carries round-off)
    assert 'sample intervals' in m.implausible(np.array([0.7 * DT_S]), None, (0, 1), 0.1, ctx)
    assert m.implausible(np.array([0.9 * DT_S]), None, (0, 1), 0.1, ctx) == ''
    assert MIN_DELAY_SAMPLES == 0.8
    assert m.implausible(np.array([3.0 * DT_S]), None, (0, 1), 0.1, ctx) == ''


@pytest.mark.parametrize('seed', [0, 1])
@pytest.mark.parametrize('shift, noise', [('half', 0.001), ('half', 0.004), ('one', 0.004)])
def test_a_half_sample_is_never_claimed_and_one_sample_is_not_refused(seed, shift, noise):
    """The fitted delay on each side of the rule, with margin, and what the round says.

    Measured over 8 noise seeds: the half sample fitted 0.50-0.52 intervals (noise
    0.1 % of the span) and 0.49-0.56 (0.4 %); one sample 0.99-1.06 (0.4 %) and
    1.00-1.02 (0.1 %). Whether the one-sample block is then accepted or 'training
    only' varies with the seed (6 of 8 accepted at 0.4 %); the rule never refuses it
    (``python bench/dead_time_samples.py``).
    """
    t = np.arange(0.0, 2000 * DT_S, DT_S)
    v = multisine(t, amplitude_ma=1.8)
    seen = 0.5 * (v + np.r_[v[0], v[:-1]]) if shift == 'half' else np.r_[v[0], v[:-1]]
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, seen)
    sigma = noise * np.ptp(x)
    y = x + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    n = int(0.7 * t.size)
    ctx = Context('position', t, n)
    data = Data(t_s=t, v=v, y=y, n_train=n, noise_std=sigma)
    current = evaluate(ComposedModel('position', [], ctx, chain_spec('position').bounds),
                       data, TRUTH)
    loc = locate(t, v, y, current.prediction, sigma, n, None)
    m = get_mechanisms(('dead_time',), channel='position')[0]
    comp = try_mechanism(m, current, data, ctx, DiagnoseSettings(fit_budget=300), loc, [])
    samples = float(comp.fit.model.theta(comp.fit.p, 'dead_time')[0]) / DT_S
    if shift == 'half':
        assert 0.4 < samples < 0.7, samples
        assert not comp.accepted, comp.status
    else:
        assert 0.9 < samples < 1.15, samples
        assert 'averages neighbouring commands' not in comp.status, comp.status
