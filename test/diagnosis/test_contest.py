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

"""Contests after re-identification (issue 14): the rule, then a recording that needs it.

The round's winner is picked on fits made around the current chain; when its
re-identified chain stays well above the floor, the best accepted runners-up
are re-identified too and one that then predicts the judged held-out part
clearly better takes the round (the blind family's #42: a gain drift whose
pivot lies far from the travel led to ``offset_drift`` at 5 x the floor).
"""

from __future__ import annotations

from pathlib import Path
import sys
from types import SimpleNamespace

import pytest

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis import refit
from hyst_id.diagnosis.report import _alternative_lines
from hyst_id.diagnosis.select import Criteria
from hyst_id.io.recording import Recording

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))
import blind_family  # noqa: E402, I100

__all__: list[str] = []

#: #42's final held-out error over the floor: 1.02 x unperturbed (see the test's docstring)
FINAL_WITHIN = 1.3

FLOOR = 0.1


def _comp(mech: str, local: float, after: float, accepted: bool = True) -> SimpleNamespace:
    return SimpleNamespace(mechanism=mech, accepted=accepted,
                           fit=SimpleNamespace(judged=local, after=after))


@pytest.fixture
def calls(monkeypatch):
    """``reidentify`` replaced: a fit's ``after`` becomes its judged error; calls recorded."""
    seen: list[float] = []

    def fake(fit, data, ctx, spec, settings, *, floor_train_percent, say=None):
        seen.append(fit.judged)
        return SimpleNamespace(judged=fit.after, after=fit.after)

    monkeypatch.setattr(refit, 'reidentify', fake)
    return seen


DATA = SimpleNamespace(floor_holdout_percent=FLOOR, judged_er_percent=lambda fit: fit.judged)
SETTINGS = SimpleNamespace(criteria=Criteria())


def _contest(winner, *others):
    return refit.contest(winner, [winner, *others], DATA, None, None, SETTINGS,
                         floor_train_percent=FLOOR)


def test_a_winner_that_reaches_the_floor_is_not_contested(calls):
    w, r = _comp('offset_drift', 0.9, 1.4 * FLOOR), _comp('gain_drift', 1.0, 1.0 * FLOOR)
    chosen, record = _contest(w, r)
    assert chosen is w and record == [] and calls == [0.9]
    assert w.fit.judged == pytest.approx(1.4 * FLOOR)     # the re-identified fit is kept


def test_a_runner_up_that_re_identifies_clearly_better_takes_the_round(calls):
    w, r = _comp('offset_drift', 0.9, 5.0 * FLOOR), _comp('gain_drift', 1.43, 1.02 * FLOOR)
    chosen, record = _contest(w, r)
    assert chosen is r and chosen.fit.judged == pytest.approx(1.02 * FLOOR)
    assert [c['mechanism'] for c in record] == ['offset_drift', 'gain_drift']
    assert record[0]['er_judged_after_percent'] == pytest.approx(5.0 * FLOOR)


def test_each_runner_ups_re_identification_is_announced(calls):
    w, r = _comp('offset_drift', 0.9, 5.0 * FLOOR), _comp('gain_drift', 1.43, 1.02 * FLOOR)
    said: list[str] = []
    refit.contest(w, [w, r], DATA, None, None, SETTINGS, floor_train_percent=FLOOR,
                  say=said.append)
    assert said == ['offset_drift re-identified stays at 5 x the floor: re-identifying '
                    'gain_drift to compare']


def test_a_runner_up_within_the_tie_ratio_does_not(calls):
    w, r = _comp('offset_drift', 0.9, 5.0 * FLOOR), _comp('gain_drift', 1.0, 4.7 * FLOOR)
    chosen, record = _contest(w, r)
    assert chosen is w and len(record) == 2


def test_a_winner_re_identified_into_implausible_values_keeps_its_local_fit(
        calls, monkeypatch):
    """A new user's gain_loss re-identified to its slowest rate was the verdict; not now."""
    monkeypatch.setattr(refit, 'implausible_after',
                        lambda c, data, ctx: 'at its slowest rate' if c.fit.judged == 0.3 else '')
    w = _comp('gain_loss', 0.9, 0.3)
    local = w.fit
    chosen, record = _contest(w)
    assert chosen is w and chosen.fit is local and calls == [0.9]


def test_only_accepted_close_runners_up_contest_and_at_most_two(calls):
    w = _comp('a', 1.0, 5.0 * FLOOR)
    far = _comp('far', 2.5, 0.5 * FLOOR)                  # beyond CONTEST_RATIO
    rejected = _comp('rejected', 1.1, 0.5 * FLOOR, accepted=False)
    near = [_comp(f'n{k}', 1.0 + 0.1 * k, 4.0 * FLOOR) for k in range(3, 0, -1)]
    chosen, record = _contest(w, far, rejected, *near)
    assert [c['mechanism'] for c in record] == ['a', 'n1', 'n2']
    assert chosen.mechanism == 'n1'


def test_the_report_names_the_former_leader():
    f = SimpleNamespace(mechanism='gain_drift', er_holdout_after_percent=0.15, alternatives=[
        {'mechanism': 'offset_drift', 'kind': 'contested', 'er_holdout_after_percent': 0.9,
         'er_judged_after_percent': 0.72}])
    line = ' '.join(_alternative_lines(f))
    assert 'offset_drift led' in line and 'gain_drift predicts' in line and '0.72' in line


@pytest.mark.slow
def test_the_blind_familys_far_pivot_gain_drift_is_named_after_the_contest():
    """#42: without the contest ``offset_drift`` at 5.0 x the floor; with it 1.02 x."""
    case = blind_family.draw(42)
    assert case['effects'] == ['gain_drift']
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                    source='blind #42')
    d = diagnose(rec, settings=DiagnoseSettings())
    assert d.verdict == 'gain_drift', [f.mechanism for f in d.findings]
    j = d.extra['judged_holdout']
    assert j['final_er_percent'] < FINAL_WITHIN * j['noise_floor_percent']
    assert any(a.get('kind') == 'contested' and a['mechanism'] == 'offset_drift'
               for a in d.findings[0].alternatives)
