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

"""A record whose chain starts on the falling boundary is diagnosed in it.

``identify`` chooses the initial state from the data; a diagnosis had always run
on the rising boundary (its composed model knew no other), so a record whose
actuator came down from above before it started was missed at its start and the
miss was dressed as physics: an independent reviewer's clean record (coloured
noise and mains hum, the actuator near its falling edge) was called
``offset_drift``, and the reference simulator's falling start under coloured
noise (seed 0 below) ``bouc_wen``. The data come from ``test/reference_sim``
(written apart from the package) with ``initial='falling'``.
"""

from __future__ import annotations

import numpy as np
import pytest
from reference_sim import simulate as reference_simulate
from scipy.signal import lfilter

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.mechanisms import get_mechanisms
from hyst_id.diagnosis.mechanisms.base import Context
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.select import Data, evaluate
from hyst_id.errors import ConfigError
from hyst_id.identification.chains import chain_spec
from hyst_id.io.recording import Recording

NAMES = chain_spec('position').names
TRUTH = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])
SETTINGS = DiagnoseSettings(workers=1)


def _sine(initial: str, seed: int) -> Recording:
    """A sine that starts mid-range going down (40 s, 2,000 samples), noise 0.3 % of the span."""
    t = np.arange(2000) * 0.02
    v = 10.0 + 3.5 * np.sin(2 * np.pi * t / 8.0 + np.pi) * (0.6 + 0.4 * np.cos(2 * np.pi * t / 40))
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, v, initial=initial)
    y = x + np.random.default_rng(seed).normal(0.0, 0.003 * np.ptp(x), x.size)
    return Recording(t, v, y, 'position')


@pytest.mark.parametrize('initial', ['rising', 'falling'])
def test_the_composed_model_starts_on_either_boundary_as_the_reference(initial):
    rec = _sine(initial, 0)
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), rec.t_s, rec.command,
                           initial=initial)
    ctx = Context('position', rec.t_s, 1400)
    model = ComposedModel('position', [], ctx, chain_spec('position').bounds, initial=initial)
    fit = evaluate(model, Data(t_s=rec.t_s, v=rec.command, y=x, n_train=1400,
                               noise_std=1e-9), TRUTH)
    np.testing.assert_allclose(fit.prediction, x, atol=1e-9 * np.ptp(x))


def test_a_falling_start_leaves_out_the_blocks_that_start_the_actuator_rising():
    ctx = Context('position', np.arange(100) * 0.1, 70)
    rate = [m for m in get_mechanisms(None, channel='position') if m.stage == 'actuator']
    assert {m.id for m in rate} == {'rate_dependence', 'loop_shape'}
    with pytest.raises(ConfigError, match='start it rising: rate_dependence'):
        ComposedModel('position', rate[:1], ctx, chain_spec('position').bounds,
                      initial='falling')


@pytest.mark.parametrize('initial', ['rising', 'falling'])
def test_the_diagnosis_runs_on_the_boundary_the_record_starts_on(initial):
    d = diagnose(_sine(initial, 0), settings=SETTINGS)
    assert d.verdict == 'none' and not d.findings, (d.verdict, d.notes)
    assert d.to_dict()['initial'] == initial
    said = [n for n in d.notes if n.startswith('the chain starts on the falling boundary')]
    assert len(said) == (initial == 'falling'), d.notes
    if said:
        assert 'rate_dependence, loop_shape, which start the actuator rising, not tried' in said[0]


@pytest.mark.slow
@pytest.mark.parametrize('seed', [0, 1])
def test_a_falling_start_under_coloured_noise_claims_no_physics(seed):
    """Random steps, AR(1) noise (pole 0.9) and a tone at a quarter of the sampling rate.

    Before: seed 0 ``bouc_wen``, seed 1 ``unknown``; now ``unknown`` on both (the floor,
    from sample-to-sample changes, is too low for coloured noise) and no block claimed.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(3000) * 0.01
    v = np.repeat(np.r_[10.0, rng.uniform(5.5, 14.5, 40)], 75)[:t.size]
    v = np.convolve(np.r_[np.full(20, v[0]), v], np.ones(20) / 20, 'valid')[:t.size]
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, v, initial='falling')
    e = lfilter([0.1], [1, -0.9], rng.standard_normal(t.size))
    e = 0.004 * np.ptp(x) * e / e.std() + 0.003 * np.ptp(x) * np.sin(2 * np.pi * 25 * t + 0.3)
    d = diagnose(Recording(t, v, x + e, 'position'), settings=SETTINGS)
    assert not d.findings and d.verdict in ('none', 'unknown'), (d.verdict, d.notes)
    assert d.to_dict()['initial'] == 'falling'
