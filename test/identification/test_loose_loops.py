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

"""Loops the paper's constraints admit and a proper loop's corner order does not.

An independent reviewer drew random chains under the paper's constraints,
simulated them with its own code, and ``identify`` stopped well above the noise
floor on those whose corners were out of order (the output jumps at some
reversals), where a plain CMA-ES over the paper's set reached it. The data here
come from ``test/reference_sim`` (written apart from the package), which
simulates such loops as the paper's step rule does.
"""

from __future__ import annotations

from dataclasses import replace
import json

from improper_chain import far_recording, H, IMPROPER, improper_csv, improper_recording, X
import numpy as np
import pytest
from reference_sim import simulate as reference_simulate
import yaml

from hyst_id.cli import main
from hyst_id.compensation import InverseModel
from hyst_id.errors import InvalidParametersError
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import chain_spec
from hyst_id.identification.loose_phase import (
    kept_loose,
    LOOSE_GAIN,
    loose_retry,
    LOOSE_WITHIN,
)
from hyst_id.identification.quality import fit_follows, orientation_warnings
from hyst_id.identification.result import Identification
from hyst_id.models.registry import get_family
from hyst_id.models.tk import check_hysteresis, loop_corners, loop_is_proper


def test_the_paper_set_admits_a_loop_the_proper_set_refuses():
    corners = {k: v[0] for k, v in loop_corners(H).items()}
    assert corners['A'] > corners['B'] and corners['D'] > corners['C']
    assert not loop_is_proper(*H)
    proper = chain_spec('position')
    loose = replace(proper, proper=False)
    assert not proper.feasible(X[None, :])[0]
    assert loose.feasible(X[None, :])[0]
    with pytest.raises(InvalidParametersError, match='not proper'):
        proper.check(X)
    np.testing.assert_array_equal(loose.check(X), X)
    np.testing.assert_array_equal(check_hysteresis(H, proper=False), H)
    # a slope rule still holds in the paper's set
    bad = list(H)
    bad[2] = 2.0
    assert not loose.feasible(np.array(bad + list(X[8:]))[None, :])[0]


@pytest.mark.parametrize('delta', [-40.0, -8.0, 0.0, 8.0, 40.0])
def test_the_loose_set_keeps_every_output_shift_of_a_loop(delta):
    """An output shift is the same chain (profiled calibration); ``c_l < c_r`` is not kept by it.

    ``bench/improper_loops.py`` #16 and #19: with ``m_l != m_r`` the rule cut shifts of the
    true loop out of the loose search, and identify stopped at 1.12-1.23 x.
    """
    from hyst_id.identification.gauge import affine_map_output
    x = np.array(X, dtype=float)
    x[1] = 1.6 * x[0]                       # m_r != m_l: the shift moves c_l, c_r apart
    shifted = affine_map_output(x, 1.0, delta)
    loose = replace(chain_spec('position'), proper=False, domain_source='auto')
    assert loose.feasible(shifted[None, :])[0]
    # the paper's own frame (its domains) keeps the paper's c_l < c_r
    paper = replace(loose, domain_source='paper')
    assert paper.feasible(shifted[None, :])[0] == (shifted[4] < shifted[5])


def test_the_package_simulates_such_a_loop_as_the_reference_does():
    t = np.arange(600) * 0.05
    v = 9.0 + 2.0 * np.exp(-t / 20) * np.sin(2 * np.pi * t / 6)
    spec = replace(chain_spec('position', calibration=(1.0, 0.0)), proper=False)
    np.testing.assert_allclose(spec.simulate(X, t, v), reference_simulate('position', IMPROPER,
                                                                          t, v), atol=1e-12)


def test_the_compensator_refuses_an_improper_loop_in_words():
    with pytest.raises(InvalidParametersError, match='not proper'):
        InverseModel.from_vector(X, 1.0, 'tk')


def test_a_diagnosis_baseline_searches_proper_loops_only():
    from hyst_id.diagnosis.baseline import identify_base
    from hyst_id.diagnosis.result import DiagnoseSettings
    assert IdentifySettings().loose_loops
    assert IdentifySettings(**identify_base(DiagnoseSettings())).loose_loops is False


#: A proper loop (the paper's induced hysteresis with a small backlash).
PROPER = [1.01, 1.05, 0.10, 0.15, -0.25, 0.50, 14.0, 7.0, 1.0, -0.15, 0.15]


def _ident(er: float, floor: float = 1.0, params: list | None = None) -> Identification:
    """A stand-in result (proper loop unless ``params`` say otherwise)."""
    spec = chain_spec('position')
    x = params if params is not None else PROPER
    return Identification(channel='position', names=spec.names,
                          params=dict(zip(spec.names, x)), params_mean={}, output_sign=1.0,
                          er_percent=er, er_mean_params_percent=er,
                          noise_floor_percent=floor, runs=[], bounds=spec.bounds,
                          domain_source='auto', settings=IdentifySettings(), other_nfev=7)


#: the loose set, two seeds, no restarts, global phase or hops, not reported as progress
PROBE = (False, False, 2, 0, 0, 0, True)
FULL = (False, False, len(IdentifySettings().seeds), IdentifySettings().restarts,
        IdentifySettings().global_runs, IdentifySettings().hops, False)


@pytest.mark.parametrize('er, probe_er, settings, runs', [
    (1.05, None, IdentifySettings(), []),                            # at the floor
    (3.0, None, IdentifySettings(loose_loops=False), []),            # asked not to
    (3.0, None, IdentifySettings(global_runs=0), []),                # a short probe
    (3.0, None, IdentifySettings(), [FULL]),
    # far off: a quick look first, the full search only when it comes within reach
    (LOOSE_WITHIN + 20.0, LOOSE_WITHIN + 1.0, IdentifySettings(), [PROBE]),
    (LOOSE_WITHIN + 20.0, 3.0, IdentifySettings(), [PROBE, FULL]),  # cmaes_review 1:r1
])
def test_the_loose_search_runs_only_above_the_floor_and_within_reach(er, probe_er, settings,
                                                                     runs):
    calls = []

    def run(spec, plain, quiet):
        calls.append((spec.proper, plain.loose_loops, len(plain.seeds), plain.restarts,
                      plain.global_runs, plain.hops, quiet))
        return _ident(probe_er if plain.global_runs == 0 else er, params=list(X))
    proper_fit = _ident(er)
    kept = loose_retry(proper_fit, chain_spec('position'), settings, run)
    assert calls == runs
    assert kept is proper_fit and kept.other_nfev == 7 + 7 * len(runs)  # every evaluation


def test_a_loose_fit_is_kept_only_when_clearly_better_and_says_so():
    proper_fit = _ident(3.0)

    def better(spec, plain, quiet):
        return _ident(1.0, params=list(X))
    kept = loose_retry(proper_fit, chain_spec('position'), IdentifySettings(), better)
    assert not kept.proper and kept.other_nfev == 7 + 7
    assert kept.proper_alternative is proper_fit    # what --params-out writes
    assert kept.warnings[0].startswith('the loop that fits is not a proper one')
    assert 'A 7.86 > B 7.35' in kept.warnings[0] and 'compensator refuses' in kept.warnings[0]

    def barely(spec, plain, quiet):
        return _ident(3.0 * LOOSE_GAIN * 1.01, params=list(X))
    same = loose_retry(_ident(3.0), chain_spec('position'), IdentifySettings(), barely)
    assert same.proper and same.er_percent == 3.0 and same.other_nfev == 7 + 7
    assert same.proper_alternative is None


@pytest.mark.parametrize('proper, loose, kept', [
    (3.0, 2.39, True),      # below LOOSE_GAIN x the proper fit
    (3.0, 2.41, False),
    (1.23, 0.99, True),     # at the floor where the proper fit is 1.1 x above it (#19)
    (1.23, 1.12, False),    # above the floor (1.1 x): the gain rule alone, not met
    (1.15, 1.08, False),    # at the floor, but the proper fit less than 1.1 x above it
])
def test_a_loose_fit_at_the_floor_is_kept_where_the_proper_one_is_not(proper, loose, kept):
    assert kept_loose(loose, proper, 1.0, IdentifySettings().global_factor) is kept


def test_a_loose_search_that_finds_a_better_proper_loop_reports_it_proper():
    assert loop_is_proper(*PROPER[:8])

    def found_proper(spec, plain, quiet):
        return _ident(1.0, params=PROPER)
    kept = loose_retry(_ident(3.0), chain_spec('position'), IdentifySettings(), found_proper)
    assert kept.proper and kept.er_percent == 1.0 and not kept.warnings
    assert kept.proper_alternative is None


def test_the_lines_an_improper_loop_never_reaches_are_still_said():
    v = 9.0 + 0.3 * np.sin(np.linspace(0.0, 20.0, 400))     # a small loop in the middle
    words, names = get_family('tk').unexcited(np.array(H), v)
    assert words and names


#: ``python bench/improper_loops.py --test-record 0 1 2 3 4 5``: rms / sigma 0.973-1.014 over
#: noise seeds 0-5, each unperturbed and under round-off probes 1 and 2 (18 runs, every one
#: kept improper; 0.973-1.144 before the loose set dropped the paper's c_l < c_r); the
#: proper search alone ends near 5.5 x on this chain (the bench's #9).
RATIO_BOUND = 1.15


def _identified(rec, sigma: float) -> tuple[Identification, float]:
    """``identify`` with its defaults (one process) and its RMS error over the true noise."""
    ident = identify(rec, settings=IdentifySettings(workers=1))
    rms = ident.er_percent / 100 * float(np.sqrt(np.mean(rec.measurement ** 2)))
    return ident, rms / sigma


@pytest.mark.slow
def test_identify_reaches_the_floor_on_an_improper_loop():
    ident, ratio = _identified(*improper_recording(0))
    assert not ident.proper
    assert ident.warnings[0].startswith('the loop that fits is not a proper one')
    assert ratio < RATIO_BOUND
    # its jumps look clockwise to the data alone; a fit at the floor is not told otherwise
    assert not any('clockwise' in w for w in ident.warnings)


#: ``python bench/improper_loops.py --far-record 0 1 2 3``: rms / sigma 0.976-1.007 over noise
#: seeds 0-3, each unperturbed and under round-off probes 1 and 2 (12 runs, every one kept
#: improper, 21-55 s); the proper search alone ends near 40 x the floor on this chain, where
#: the loose search did not run at all before the quick look (``LOOSE_WITHIN``).
FAR_BOUND = 1.15


@pytest.mark.slow
def test_identify_looks_at_loose_loops_where_the_proper_search_ends_far_off():
    ident, ratio = _identified(*far_recording(0))
    assert not ident.proper
    assert ratio < FAR_BOUND
    alternative = ident.proper_alternative
    assert alternative.proper
    assert alternative.er_percent > LOOSE_WITHIN * alternative.noise_floor_percent


@pytest.mark.slow
def test_the_cli_reports_an_improper_loop_and_writes_the_best_proper_one(tmp_path, capsys):
    csv = tmp_path / 'run.csv'
    rec, sigma = improper_csv(1, csv)
    params, result = tmp_path / 'comp.yaml', tmp_path / 'result.json'
    code = main(['identify', str(csv), '--workers', '1', '--json', str(result),
                 '--params-out', str(params)])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert 'with the best proper loop found' in out.err
    assert 'Traceback' not in out.err
    doc = json.loads(result.read_text())
    assert doc['proper_loop'] is False
    rms = doc['er_percent'] / 100 * float(np.sqrt(np.mean(rec.measurement ** 2)))
    assert rms / sigma < RATIO_BOUND
    assert 'not a proper one' in out.out
    # the file holds the proper search's loop (the JSON's proper_alternative), which the
    # compensator accepts, and which fits worse than the loop kept
    alternative = doc['proper_alternative']
    assert alternative['er_percent'] > doc['er_percent']
    written = yaml.safe_load(params.read_text())['/**']['ros__parameters']
    h = [written[name] for name in ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b')]
    assert loop_is_proper(*h)
    check_hysteresis(h)     # raises for a loop the compensator cannot invert


def test_a_fit_at_the_floor_is_not_told_it_can_only_approximate_the_loop():
    """The jumps of an improper loop look clockwise to the orientation measure.

    An independent review (stop 65) got "the loop runs clockwise ... can only approximate
    this one" next to an improper loop that fitted at 0.98 x the noise; a ringing flow
    sensor at the floor got "cannot follow these transitions" the same way.
    """
    rec, _ = improper_recording(0)
    assert any('clockwise' in w for w in orientation_warnings(rec))
    assert orientation_warnings(rec, followed=True) == []
    assert orientation_warnings(rec, -1.0, followed=True)[0].startswith('output sign -1')
    assert fit_follows(1.05, 1.0) and not fit_follows(2.0, 1.0)
    assert not fit_follows(1.0, 1e-12)          # a floor of about 0 next to the fit says nothing
