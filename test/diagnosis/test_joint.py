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

"""The joint search of a candidate block with the chain (``diagnosis/joint.py``, issue 14).

The recordings are the independent reference simulator's: a dead time on the
reference chain (``reference_sim``), and blind #175 of ``bench/blind_family.py``
(friction on a pressure reading, random steps, where the local fit stops in
the basin of a chain whose loop has absorbed the band).
"""

from __future__ import annotations

from pathlib import Path
import sys

import numpy as np
import pytest
from reference_sim import backlash, hysteresis

from hyst_id.diagnosis import diagnose, DiagnoseSettings, trial
from hyst_id.diagnosis.joint import JOINT_ABOVE, joint_search, worth_searching
from hyst_id.diagnosis.locate import locate
from hyst_id.diagnosis.mechanisms.base import Context
from hyst_id.diagnosis.mechanisms.registry import MECHANISMS
from hyst_id.diagnosis.model import ComposedModel
from hyst_id.diagnosis.select import Data, evaluate
from hyst_id.identification.chains import chain_spec
from hyst_id.io.recording import Recording
from hyst_id.signals.noise import floor_percent

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))
import blind_family  # noqa: E402, I100

__all__: list[str] = []

CHAIN = np.array([1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15])
NOISE = 0.01


def _delayed_record(seed: int = 0):
    """The reference chain behind a 0.3 s delay, 50 Hz, and the delay model."""
    t = np.arange(0.0, 60.0, 0.02)
    v = 9.0 + 2.0 * np.sin(2 * np.pi * t / 7.0) + 0.4 * np.sin(2 * np.pi * t / 2.3 + 1.0)
    d = int(round(0.3 / 0.02))
    vd = np.concatenate([np.full(d, v[0]), v[:-d]])
    x = backlash(hysteresis(vd, *CHAIN[:8]), *CHAIN[8:])
    y = 3.0 * np.asarray(x) + 1.0 + np.random.default_rng(seed).normal(0.0, NOISE, t.size)
    ctx = Context('position', t, int(0.7 * t.size))
    model = ComposedModel('position', [MECHANISMS['dead_time']], ctx,
                          chain_spec('position').bounds)
    data = Data(t_s=t, v=v, y=y, n_train=ctx.n_train, noise_std=NOISE)
    return data, model


def test_the_search_reaches_the_floor_from_a_start_off_it_and_repeats_itself():
    """From the delay at a tenth of the truth, unpolished (92.5 x the training floor).

    Measured at 150 generations on noise seeds 0-3: 1.112-1.119 x the floor, the delay
    0.3009-0.3012 s (at 60 generations seed 3 stayed at 29.7 x with 0.47 s); seed 1 with
    its measurement perturbed by 1e-14 relative in four streams (another CPU's last bits
    change the search's path): 1.002-1.113 x, 0.3002-0.3012 s. The bounds sit outside.
    """
    data, model = _delayed_record(seed=1)
    start = evaluate(model, data, np.concatenate([CHAIN, [0.03]]))
    floor = floor_percent(data.y[:data.n_train], NOISE)
    assert start.er_train_percent > 50 * floor
    assert joint_search(start, data, generations=0, polish_nfev=400) is start
    got = joint_search(start, data, generations=150, polish_nfev=400)
    assert got is not start and got.sse_train < start.sse_train
    assert got.er_train_percent < 1.3 * floor
    assert got.p[-1] == pytest.approx(0.3, abs=0.005)
    # the same stream gives the same answer
    again = joint_search(start, data, generations=150, polish_nfev=400)
    np.testing.assert_array_equal(again.p, got.p)


def test_a_round_judges_its_leaders_again_on_their_searched_fits(monkeypatch):
    """The wiring of ``trial._search_leaders``, the search replaced by a known better fit."""
    data, model = _delayed_record(seed=1)
    plain = ComposedModel('position', [], model.ctx, chain_spec('position').bounds)
    current = evaluate(plain, data, CHAIN)
    local = evaluate(model, data, np.concatenate([CHAIN, [0.2]]))
    better = evaluate(model, data, np.concatenate([CHAIN, [0.3]]))
    searched = []

    def fake(fit, data, *, generations, polish_nfev, should_stop=None):
        searched.append((fit, generations))
        return better

    monkeypatch.setattr(trial, 'joint_search', fake)
    settings = DiagnoseSettings(workers=1, joint_generations=300)
    m = MECHANISMS['dead_time']
    loc = locate(data.t_s, data.v, data.y, current.prediction, NOISE, data.n_train, 7.0)
    comp = trial.judge(m, current, local, data, model.ctx, settings, loc)
    assert comp.accepted
    comp.screened = 'kept'
    said: list[str] = []
    got = {0: comp}
    trial._search_leaders(got, [m], current, data, model.ctx, settings, loc, said.append)
    assert [g for _, g in searched] == [300] and searched[0][0] is local
    assert got[0].fit is better and got[0].screened == 'kept' and got[0].accepted
    assert any(line.startswith('dead_time: searched') for line in said), said
    # a searched fit no better on training is not taken
    monkeypatch.setattr(trial, 'joint_search', lambda fit, *a, **k: local)
    got = {0: comp}
    trial._search_leaders(got, [m], current, data, model.ctx, settings, loc, said.append)
    assert got[0] is comp
    # none: nothing searched
    searched.clear()
    monkeypatch.setattr(trial, 'joint_search', fake)
    trial._search_leaders(got, [m], current, data, model.ctx,
                          DiagnoseSettings(workers=1, joint_generations=0), loc, said.append)
    assert not searched and got[0] is comp


def test_only_a_fit_that_found_something_and_stays_above_the_floor_is_searched():
    data, model = _delayed_record()
    true = evaluate(model, data, np.concatenate([CHAIN, [0.3]]))
    off = evaluate(model, data, np.concatenate([CHAIN, [0.2]]))
    floor = floor_percent(data.y[:data.n_train], NOISE)
    assert true.er_train_percent < JOINT_ABOVE * floor < off.er_train_percent
    assert not worth_searching(true, -500.0, data, 10.0)     # at the floor
    assert worth_searching(off, -500.0, data, 10.0)
    assert not worth_searching(off, -5.0, data, 10.0)        # found nothing
    assert not worth_searching(off, 20.0, data, 10.0)


@pytest.mark.slow
@pytest.mark.thorough     # 80 s, for an option that is off by default
def test_friction_behind_a_slow_pressure_sensor_is_found_by_the_joint_search():
    """Blind #175: friction alone (8 % of the span), pressure sensor 5.8 s, random steps.

    Without the search its first round went to ``gain_drift`` (the friction fit stopped
    at a force a fifth of the truth, 7.2 x the held-out floor: ``python
    bench/joint_search.py``) unperturbed, and the final model, ``gain_drift`` + friction,
    stopped at 4.86 x (under round-off probe 1 the local fit already finds friction: that
    the search is what moves it depends on the last bits, that it ends right does not);
    with it friction is the only finding. Measured: final
    held-out 1.59 x the floor unperturbed, 1.15 x under round-off probe 1 and 1.54 x
    under probe 2; the bound sits above.
    """
    case = blind_family.draw(175)
    assert case['effects'] == ['friction']
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                    source='blind #175')
    d = diagnose(rec, settings=DiagnoseSettings(workers=1, joint_generations=300))
    assert [f.mechanism for f in d.findings] == ['friction'], d.report()
    assert d.final.er_holdout_percent < 2.5 * d.noise_floor_percent, d.report()
