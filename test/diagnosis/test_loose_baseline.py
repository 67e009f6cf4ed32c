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

"""A diagnosis's baseline over loops whose output jumps (:mod:`hyst_id.diagnosis.loose_baseline`).

The recording is clean (noise only) and made apart from the package
(``test/improper_chain.py``, the reference simulator): every block a diagnosis
claims on it is a false claim. Its proper baseline stops near 5 x the floor
(``python bench/improper_loops.py --diagnose --indices 9``).
"""

from __future__ import annotations

import json
from types import SimpleNamespace

from improper_chain import improper_csv, improper_recording, X
import numpy as np
import pytest

from hyst_id.cli import main
from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis import loose_baseline as loose_module
from hyst_id.diagnosis.export import compensator_set
from hyst_id.diagnosis.loose_baseline import loose_baseline, LOOSE_FROM, LOOSE_NEAR, LOOSE_RETRY
from hyst_id.diagnosis.mechanisms.base import Context
from hyst_id.diagnosis.select import Data
from hyst_id.errors import InvalidParametersError
from hyst_id.identification.chains import chain_spec
from hyst_id.signals.noise import floor_percent

SETTINGS = DiagnoseSettings(workers=1)

#: Final held-out %e_r over the floor bounded by the test: 0.909-1.036 over noise seeds 0-5,
#: each unperturbed and under round-off probes 1 and 2, every one ``none`` with an improper
#: loop (``python bench/improper_loops.py --test-record 0 1 2 3 4 5 --diagnose``), with margin.
FINAL_BOUND = 1.2


@pytest.fixture(scope='module')
def diagnosis():
    return diagnose(improper_recording(0)[0], settings=SETTINGS)


def test_a_clean_improper_loop_is_diagnosed_none_over_such_loops(diagnosis):
    d = diagnosis
    assert d.verdict == 'none' and not d.findings, (d.verdict, d.notes[:1])
    assert d.notes[0].startswith("the chain's loop is not a proper one"), d.notes[:1]
    assert 'A ' in d.notes[0] and 'compensator refuses' in d.notes[0]
    assert d.to_dict()['proper_loop'] is False
    assert d.final.er_holdout_percent < FINAL_BOUND * d.noise_floor_percent
    assert not d.final.model.spec.proper


def test_the_compensator_set_of_an_improper_loop_is_refused(diagnosis):
    with pytest.raises(InvalidParametersError):
        compensator_set(diagnosis)


def test_the_cli_refuses_a_compensator_file_for_it_and_says_why(tmp_path, capsys):
    csv = tmp_path / 'run.csv'
    improper_csv(1, csv)
    out, params = tmp_path / 'd.json', tmp_path / 'set.yaml'
    assert main(['diagnose', str(csv), '--quiet', '--workers', '1', '--json', str(out),
                 '--params-out', str(params)]) == 2
    err = capsys.readouterr().err
    assert 'not a proper one' in err and '--proper-loops --params-out' in err
    assert not params.exists()
    doc = json.loads(out.read_text())           # the report is written before the refusal
    assert doc['verdict'] == 'none' and doc['proper_loop'] is False


class _Searched(Exception):
    pass


def _stand_in(er_train_percent: float, er_holdout_percent: float) -> SimpleNamespace:
    """A proper baseline as :func:`loose_baseline` reads it."""
    spec = SimpleNamespace(proper=True, family=SimpleNamespace(id='tk'))
    return SimpleNamespace(model=SimpleNamespace(spec=spec, mechanisms=(), initial='rising',
                                                 hold='before'),
                           er_train_percent=er_train_percent,
                           er_holdout_percent=er_holdout_percent)


@pytest.mark.parametrize('train, held_out, loose_loops, searched', [
    (5.0, 1.0, True, True), (1.0, 5.0, True, True), (5.0, 5.0, False, False),
    (0.9 * LOOSE_FROM, 0.9 * LOOSE_FROM, True, False)])
def test_the_loose_search_runs_only_when_asked_and_above_the_floor(
        monkeypatch, train, held_out, loose_loops, searched):
    """Off (``loose_loops``, ``--proper-loops``) or with a baseline near its floor: not run."""
    def search(*args, **kwargs):
        raise _Searched
    monkeypatch.setattr(loose_module, 'identify', search)
    rec, sigma = improper_recording(0)
    n = 1000
    y = rec.measurement
    data = Data(t_s=rec.t_s, v=rec.command, y=y, n_train=n, noise_std=sigma)
    best = _stand_in(train * floor_percent(y[:n], sigma), held_out * floor_percent(y[n:], sigma))
    settings = DiagnoseSettings(workers=1, loose_loops=loose_loops)
    spec = chain_spec('position')
    if searched:
        with pytest.raises(_Searched):
            loose_baseline(rec, spec, settings, data, Context('position', rec.t_s, n), best)
    else:
        assert loose_baseline(rec, spec, settings, data, Context('position', rec.t_s, n),
                              best) == (best, '')


@pytest.mark.parametrize('quick, wider, proper, retried, kept', [
    (1.0, None, 5.0, False, 1.0),   # at the floor: no second search
    (1.5, 1.0, 5.0, True, 1.0),     # near it (#22 of the bench: 1.49 x): searched wider
    (1.5, 1.7, 5.0, True, None),    # the wider search no better: the quick fit, too far
    (3.0, None, 5.0, False, None),  # far off: physics the loop lacks, no second search
    # far off, but under half the proper fit's (cmaes_review 2:r8: 2.29 x against 11 x)
    (2.3, 1.0, 11.0, True, 1.0),
    (2.6, 1.0, 5.0, False, None),   # over half of it: no second search
    # at the floor where the proper loop is 1.1 x above (cmaes_review 1:r6: 1.09 x, 1.32 x)
    (1.09, None, 1.32, False, 1.09),
    (1.15, None, 1.25, False, None),    # above 1.1 x, not clearly better: the proper stays
])
def test_a_quick_loose_fit_near_the_floor_is_searched_again_wider(
        monkeypatch, quick, wider, proper, retried, kept):
    rec, sigma = improper_recording(0)
    n = 1000
    y = rec.measurement
    floor = floor_percent(y[:n], sigma)
    calls = []

    def fit_of(*args, global_runs):
        calls.append(global_runs)
        ratio = quick if global_runs == 0 else wider
        return SimpleNamespace(er_train_percent=ratio * floor, er_holdout_percent=ratio * floor,
                               p=np.array(X, dtype=float))
    monkeypatch.setattr(loose_module, '_loose_fit', fit_of)
    data = Data(t_s=rec.t_s, v=rec.command, y=y, n_train=n, noise_std=sigma)
    best = _stand_in(proper * floor, proper * floor)
    fit, note = loose_baseline(rec, chain_spec('position'), SETTINGS, data,
                               Context('position', rec.t_s, n), best)
    assert calls == ([0, 2] if retried else [0])
    assert LOOSE_NEAR < LOOSE_RETRY
    if kept is None:
        assert fit is best and note == ''
    else:
        assert fit.er_train_percent == kept * floor and 'not a proper one' in note
