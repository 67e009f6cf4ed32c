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

"""The global phase's schedule: every convention first, then longer runs; never by core count."""

from __future__ import annotations

from dataclasses import replace
import importlib
from pathlib import Path
import sys

from excitations import off_chain_recording
import numpy as np
import pytest

from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import chain_spec
from hyst_id.identification.result import SeedRun
from hyst_id.io.recording import Recording

gp = importlib.import_module('hyst_id.identification.global_phase')

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))
import generalisation as FAMILY  # noqa: E402, I100


def _run(spec, fun, run_id=0):
    return SeedRun(seed=run_id, x_raw=np.zeros(spec.n_params), x=np.zeros(spec.n_params),
                   sign=1.0, fun=fun, er_percent=fun, er_gaass_percent=float('nan'), nfev=1,
                   nit=1, best_history=np.zeros(0), message='', initial=spec.initial,
                   hold=spec.hold)


def _others(spec):
    return [replace(spec, initial=i, hold=h) for i, h in
            (('falling', 'before'), ('rising', 'after'), ('falling', 'after'),
             ('rising', 'before'))]


@pytest.fixture
def calls(monkeypatch):
    """Record each global-phase run; each scores ``scores[j]`` (%e_r) in turn."""
    made = []

    def fake(spec, rec, settings, seed, run_id=-1, evals=None, subset=None, should_stop=None):
        made.append((spec.initial, spec.hold, run_id, evals or settings.global_evals))
        return _run(spec, made_scores[len(made) - 1], run_id)
    made_scores = []
    monkeypatch.setattr(gp, 'global_phase', fake)
    return made, made_scores


def test_every_convention_before_longer_runs_under_the_best(calls):
    made, scores = calls
    spec = chain_spec('pressure')
    scores += [9.0, 8.0, 1.5, 7.0, 1.4, 1.3]          # never below 1.1 x a floor of 1
    best = _run(replace(spec, initial='rising', hold='before'), 10.0)
    settings = IdentifySettings(global_evals=1000, global_runs=6)
    seen = []
    improved = gp.global_phases(spec, _others(spec), None, settings, best, 1.0,
                                on_run=lambda run: seen.append(run.seed))
    assert seen == [-1, -2, -3, -4, -5, -6]
    # the best run's conventions, then each other once, then 3 x longer under the best so far
    assert [m[:2] for m in made] == [('rising', 'before'), ('falling', 'before'),
                                     ('rising', 'after'), ('falling', 'after'),
                                     ('rising', 'after'), ('rising', 'after')]
    assert [m[2] for m in made] == [-1, -2, -3, -4, -5, -6]
    assert [m[3] for m in made] == [1000] * 4 + [3000] * 2
    assert [r.fun for r in improved] == [9.0, 8.0, 1.5, 1.4, 1.3]


def test_no_longer_runs_far_from_the_floor(calls):
    """Beyond LONG_RUNS_WITHIN x the floor the misfit is taken for missing physics, not a trap."""
    made, scores = calls
    spec = chain_spec('flow')
    scores += [9.0, 8.0, 1.01 * gp.LONG_RUNS_WITHIN, 7.0]
    gp.global_phases(spec, _others(spec), None, IdentifySettings(), _run(spec, 10.0), 1.0)
    assert len(made) == 4                               # the conventions only


def test_by_default_ten_longer_runs_within_four_times_the_floor(calls):
    """A trap at 3.5 x gets the sweep and then ten longer runs (#44 of the family: 3.65 x)."""
    made, scores = calls
    spec = chain_spec('flow')
    scores += [9.0, 8.0, 3.5, 7.0] + [3.4 - 0.1 * k for k in range(10)]
    settings = IdentifySettings()
    improved = gp.global_phases(spec, _others(spec), None, settings, _run(spec, 10.0), 1.0)
    assert len(made) == settings.global_runs == 14
    assert [m[3] for m in made] == [settings.global_evals] * 4 + [3 * settings.global_evals] * 10
    assert improved[-1].fun == pytest.approx(2.5)


def test_stops_after_the_round_that_reaches_the_floor(calls):
    made, scores = calls
    spec = chain_spec('flow')
    scores += [5.0, 1.05, 0.5, 0.4]
    best = _run(spec, 10.0)
    improved = gp.global_phases(spec, _others(spec), None, IdentifySettings(), best, 1.0)
    assert len(made) == 2                               # a round is two runs
    assert [r.fun for r in improved] == [5.0, 1.05]


@pytest.mark.parametrize('settings', [IdentifySettings(global_runs=0),
                                      IdentifySettings(global_evals=0),
                                      IdentifySettings(refine=False)])
def test_off(calls, settings):
    made, scores = calls
    spec = chain_spec('flow')
    assert gp.global_phases(spec, [], None, settings, _run(spec, 10.0), 1.0) == []
    assert made == []


def test_at_the_floor_nothing_runs(calls):
    made, _ = calls
    spec = chain_spec('flow')
    assert gp.global_phases(spec, _others(spec), None, IdentifySettings(),
                            _run(spec, 1.09), 1.0) == []
    assert made == []


def test_the_same_runs_with_one_or_two_workers():
    """The schedule and streams do not depend on the core count (real DE, small budget)."""
    case = FAMILY.draw_case(2, n_samples=300)
    rec = Recording(case.t_s, case.command, case.measurement, case.channel, 'u', 'y', 'family')
    from hyst_id.identification.domains import domains_from_data
    spec = domains_from_data(rec)
    settings = IdentifySettings(global_evals=3000, global_runs=3)
    best = _run(spec, np.inf)
    best.er_percent = np.inf
    one = gp.global_phases(spec, _others(spec), rec, settings, best, 1e-9, n_workers=1)
    two = gp.global_phases(spec, _others(spec), rec, settings, best, 1e-9, n_workers=2)
    assert one
    assert [(r.seed, r.initial, r.hold) for r in one] == [(r.seed, r.initial, r.hold)
                                                          for r in two]
    for a, b in zip(one, two):
        np.testing.assert_array_equal(a.x_raw, b.x_raw)


def test_identify_sweeps_every_convention_of_a_sensor_channel():
    """Flow: two initial states x two sensor holds, each once, the best-ranked first.

    Which run finds a trapped fit's basin is luck of its stream and the last
    bits (family #104 reached 1.06 x under one probe and stayed at 11.3 x under
    another), so what is asserted is that every convention is searched.
    """
    rec = off_chain_recording('flow', seed=1)
    seen = []
    ident = identify(rec, settings=IdentifySettings(
        seeds=(0,), maxiter=20, restarts=0, workers=1, global_evals=3000, global_runs=6),
        progress=lambda done, total, run: seen.append(run))
    glob = [r for r in seen if r.seed < 0]
    assert ident.er_percent > gp.LONG_RUNS_WITHIN * ident.noise_floor_percent  # no longer
    assert [r.seed for r in glob] == [-1, -2, -3, -4]
    assert {(r.initial, r.hold) for r in glob} == {(i, h) for i in ('rising', 'falling')
                                                   for h in ('before', 'after')}
    assert (glob[0].initial, glob[0].hold) == (seen[0].initial, seen[0].hold)
    assert ident.er_percent <= seen[0].er_percent


def test_a_long_record_is_searched_on_its_subset_and_scored_on_every_sample():
    case = FAMILY.draw_case(3, n_samples=30000)
    rec = Recording(case.t_s, case.command, case.measurement, case.channel, 'u', 'y', 'long')
    from hyst_id.identification.domains import domains_from_data
    from hyst_id.identification.driver import search_subset
    spec = domains_from_data(rec)
    sub = search_subset(rec.command, 5000)
    assert sub is not None and sub.size < rec.n_samples // 3
    settings = IdentifySettings(global_evals=2000, refine_max_nfev=50)
    run = gp.global_phase(spec, rec, settings, 0, -1, subset=sub)
    full = spec.cost_function(rec.t_s, rec.command, rec.measurement)(run.x_raw[None, :])[0]
    assert run.fun == pytest.approx(full, rel=1e-9)


def test_identify_reports_each_global_run_after_its_seeds():
    """A fit the chain cannot make (a slow drift added): one seed, then both conventions."""
    rec = off_chain_recording('position', seed=0)
    calls, reported = [], []

    def progress(done, total, run):
        calls.append((done, total, run.seed))
        reported.append(run)
    # (loose_loops off: the quick look at loose loops beyond 20 x the floor is not reported
    # as progress; test_loose_loops.py counts its evaluations)
    ident = identify(rec, settings=IdentifySettings(
        seeds=(0,), maxiter=20, restarts=0, workers=1, global_evals=3000, global_runs=4,
        loose_loops=False), progress=progress)
    assert ident.er_percent > gp.LONG_RUNS_WITHIN * ident.noise_floor_percent  # no longer
    # position: two initial states, no sensor hold; the bar's total counts the most runs
    assert calls == [(1, 1, 0), (2, 5, -1), (3, 5, -2)]
    # every evaluation counts, also a global run's that did not improve (not in runs)
    assert ident.nfev == sum(r.nfev for r in reported) >= sum(r.nfev for r in ident.runs)
