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

"""hyst_id.live without ROS: pairing of live streams, worker jobs, result documents."""

from __future__ import annotations

import math
from types import SimpleNamespace

from excitations import off_chain_recording
import numpy as np
import pytest

from hyst_id.compensation.params_file import compensator_names
from hyst_id.errors import RecordingError
from hyst_id.identification import IdentifySettings
from hyst_id.identification.chains import chain_spec
from hyst_id.live import (
    BackgroundJob,
    compensator_set,
    diagnosis_statuses,
    DiagnosisJob,
    IdentificationJob,
    pair_streams,
    recovered_document,
    SampleBuffer,
)
from hyst_id.signals.excitation import eq24

PAPER = {'m_l': 1.01, 'm_r': 1.05, 'm_t': 0.10, 'm_b': 0.15, 'c_l': -0.25, 'c_r': 0.50,
         'c_t': 14.0, 'c_b': 7.0, 'm_bl': 1.0, 'c_bl': -0.25, 'c_br': 0.25}
T0 = 1_800_000_000 * 10**9
DT = 50_000_000


def _streams(n: int = 400):
    t = np.arange(n) * DT * 1e-9
    v = eq24(t)
    y = chain_spec('position').simulate(np.array(list(PAPER.values())), t, v)
    y = y + np.random.default_rng(0).normal(0, 0.005, n)
    return T0 + np.arange(n) * DT, v, T0 + np.arange(n) * DT + 1000, y


def test_out_of_order_arrivals_are_sorted_and_noted():
    ct, cv, mt, mv = _streams()
    ref = pair_streams(ct, cv, mt, mv, 'position')
    order = np.random.default_rng(1).permutation(ct.size)
    buf = SampleBuffer()
    for k in order:                       # both streams arrive shuffled
        buf.add_command(ct[k], cv[k])
        buf.add_measurement(mt[k], mv[k])
    rec = buf.recording('position', names=('/cmd', '/pos'))
    np.testing.assert_array_equal(rec.t_s, ref.t_s)
    np.testing.assert_array_equal(rec.command, ref.command)
    np.testing.assert_array_equal(rec.measurement, ref.measurement)
    assert any('/cmd' in n and 'out of order' in n for n in rec.notes), rec.notes
    assert any('/pos' in n and 'out of order' in n for n in rec.notes), rec.notes
    assert all(n.startswith('time origin') for n in ref.notes), ref.notes   # nothing repaired


def test_gaps_and_duplicates_are_reported():
    ct, cv, mt, mv = _streams()
    keep = np.r_[0:100, 130:400]                     # 30 measurements lost in transit
    mt2 = np.r_[mt[keep], mt[5]]                     # and one repeated stamp
    mv2 = np.r_[mv[keep], mv[5]]
    rec = pair_streams(ct, cv, mt2, mv2, 'position', names=('command', 'position'))
    assert rec.n_samples == 370
    gap = [n for n in rec.notes if 'gap' in n]
    assert len(gap) == 1 and 'about 30 samples missing' in gap[0] and 'position' in gap[0]
    assert any('duplicate' in n and 'another value' not in n for n in rec.notes), rec.notes
    clash = pair_streams(ct, cv, np.r_[mt, mt[7]], np.r_[mv, mv[7] + 1.0], 'position')
    assert any('dropped 1 messages with a duplicate stamp (kept the last at each stamp; 1 of '
               'them carried another value' in n for n in clash.notes), clash.notes
    with pytest.raises(RecordingError, match='no samples'):
        pair_streams(ct[:0], cv[:0], mt, mv, 'position')


def test_compensator_set_is_the_best_run_with_a_guard():
    ident = SimpleNamespace(params=dict(PAPER), er_percent=0.5, output_sign=-1.0, family='tk')
    comp, er, note = compensator_set(ident)
    assert comp == {**PAPER, 'output_sign': -1.0, 'family': 'tk'} and er == 0.5 and note == ''
    ident.params['m_t'] = 2.0                        # cannot come out of identify
    comp, er, note = compensator_set(ident)
    assert comp is None and np.isnan(er) and 'not a valid compensator model' in note


def test_compensator_set_carries_the_smooth_family():
    names = compensator_names('smooth')
    values = dict(zip(names, [0.5, 0.3, 0.0, 0.2, 0.0, 0.1, 0.05, 1.0, 2.0, 0.0, 0.0,
                              1.0, -0.1, 0.1]))
    ident = SimpleNamespace(params=values, er_percent=0.4, output_sign=1.0, family='smooth')
    comp, er, note = compensator_set(ident)
    assert comp == {**values, 'output_sign': 1.0, 'family': 'smooth'} and note == ''
    ident.params['w_0'] = -1.0                       # a negative weight: not invertible
    comp, er, note = compensator_set(ident)
    assert comp is None and 'not a valid compensator model' in note


def test_identification_job_cancels_between_seeds():
    ct, cv, mt, mv = _streams()
    rec = pair_streams(ct, cv, mt, mv, 'position')
    settings = IdentifySettings(seeds=tuple(range(50)), maxiter=30, refine=False, workers=1)
    job = IdentificationJob(rec, chain_spec('position'), settings)
    deadline = 60.0
    while not job.runs and deadline > 0:
        job.wait(0.05)
        deadline -= 0.05
    job.cancel()
    assert job.wait(60.0)
    assert job.cancelled and job.result is None and job.error is None
    assert 1 <= len(job.runs) < 50


def test_identification_job_reports_generations_and_cancels_within_a_seed():
    ct, cv, mt, mv = _streams()
    rec = pair_streams(ct, cv, mt, mv, 'position')
    settings = IdentifySettings(seeds=(0,), maxiter=100000, refine=False, workers=1)
    job = IdentificationJob(rec, chain_spec('position'), settings)
    deadline = 60.0
    while job.progress().get('generation', 0) < 5 and deadline > 0:
        job.wait(0.05)
        deadline -= 0.05
    prog = job.progress()
    assert prog['seed'] == 0 and prog['restart'] == 0 and prog['generation'] >= 5
    assert prog['seed_er_percent'] > 0
    job.cancel()
    assert job.wait(30.0)            # 100000 generations would take minutes
    assert job.cancelled and not job.runs


def test_identification_job_counts_global_runs_apart_from_seeds():
    """A drift the chain cannot make keeps the fit above the floor: both global runs run."""
    rec = off_chain_recording('position', seed=0)
    settings = IdentifySettings(seeds=(0,), maxiter=20, restarts=0, workers=1,
                                global_evals=3000, global_runs=2)
    job = IdentificationJob(rec, None, settings)
    assert job.wait(120.0) and job.error is None
    prog = job.progress()
    assert prog['seeds_done'] == 1 and prog['seeds'] == 1 and prog['global_runs_done'] == 2
    assert prog['best_er_percent'] == pytest.approx(job.result.er_percent)


def test_identification_job_reports_hopping_and_cancels_between_jumps(monkeypatch):
    """After the seeds the job reports the jump it is on, and a cancel stops between two."""
    import threading

    from hyst_id.identification import driver
    started = threading.Event()

    def slow_hop(*args, on_jump=None, **kwargs):
        for k in range(1000):                        # 1000 jumps of 0.05 s: 50 s if uncancelled
            on_jump(k, 1000, 1.25)
            started.set()
            threading.Event().wait(0.05)
        return None, 0
    monkeypatch.setattr(driver, 'hop_with_cost', slow_hop)
    ct, cv, mt, mv = _streams()
    rec = pair_streams(ct, cv, mt, mv, 'position')
    settings = IdentifySettings(seeds=(0,), maxiter=10, refine=False, workers=1)
    job = IdentificationJob(rec, chain_spec('position'), settings)
    assert started.wait(60.0)
    prog = job.progress()
    assert prog['seeds_done'] == 1 and prog['hops'] == 1000 and prog['hop'] >= 1, prog
    assert prog['hop_er_percent'] == 1.25
    job.cancel()
    assert job.wait(5.0)
    assert job.cancelled and job.result is None and job.error is None


def test_identification_job_forgets_hopping_once_it_ended(monkeypatch):
    from hyst_id.identification import driver

    def quick_hop(*args, on_jump=None, **kwargs):
        on_jump(0, 2, 1.3)
        on_jump(1, 2, 1.2)
        on_jump(2, 2, 1.2)                           # the end
        return None, 0
    monkeypatch.setattr(driver, 'hop_with_cost', quick_hop)
    ct, cv, mt, mv = _streams()
    settings = IdentifySettings(seeds=(0,), maxiter=10, refine=False, workers=1)
    job = IdentificationJob(pair_streams(ct, cv, mt, mv, 'position'), chain_spec('position'),
                            settings)
    assert job.wait(60.0) and job.error is None
    assert 'hop' not in job.progress() and job.hopping == {}


def test_background_job_errors_are_one_line():
    class Boom(BackgroundJob):
        def work(self):
            raise ValueError('bad\nthing')

    job = Boom().start()
    assert job.wait(5.0)
    assert job.error.startswith('ValueError: bad') and job.result is None


def test_diagnosis_statuses_one_per_finding():
    doc = {'verdict': 'offset_drift', 'noise_floor_percent': 0.05,
           'baseline': {'er_holdout_percent': 1.2},
           'findings': [{'mechanism': 'offset_drift', 'title': 'drift', 'placement': 'sensor',
                         'explanation': 'The zero drifts.',
                         'er_holdout_before_percent': 1.2, 'er_holdout_after_percent': 0.06,
                         'params': {'rate_per_s': {'value': 0.01, 'unit': 'units/s'}}},
                        {'mechanism': 'dead_time', 'explanation': 'A delay.', 'params': {}}]}
    out = diagnosis_statuses(doc)
    assert [(lvl, name) for lvl, name, _, _ in out] == [(1, 'offset_drift'), (1, 'dead_time')]
    level, name, message, values = out[0]
    assert message == 'The zero drifts.'
    assert values['er_holdout_before_percent'] == 1.2
    assert values['er_holdout_after_percent'] == 0.06
    assert values['param.rate_per_s'] == '0.01 units/s'
    none = diagnosis_statuses({'verdict': 'none', 'findings': [], 'noise_floor_percent': 0.05,
                               'baseline': {'er_holdout_percent': 0.051}})
    assert none[0][0] == 0 and 'verdict none' in none[0][2] and '0.051' in none[0][2]


def test_recovered_document_carries_the_set():
    values = {'channel': 'position', **PAPER, 'output_sign': 1.0, 'er_percent': 0.2}
    doc = recovered_document(values, '/x/compensator.yaml')
    assert doc['compensator_params'] == {**PAPER, 'output_sign': 1.0, 'family': 'tk'}
    assert doc['source'] == 'recovered from /x/compensator.yaml' and doc['er_percent'] == 0.2


def test_recording_of_an_empty_buffer_says_so():
    with pytest.raises(RecordingError, match='0 commands'):
        SampleBuffer().recording('position')


def test_quality_gate_reasons():
    from hyst_id.live import QualityGate
    ident = SimpleNamespace(er_percent=0.5, noise_floor_percent=0.1,
                            poorly_determined={'m_t': 0.2, 'c_br': math.inf})
    reasons = QualityGate().reasons(ident)
    assert len(reasons) == 2 and '5.0 x the noise floor' in reasons[0]
    assert 'c_br (uncertainty unbounded' in reasons[1] and 'm_t' not in reasons[1]
    assert QualityGate(max_floor_ratio=6.0, max_uncertainty=0.0).reasons(ident) == []
    assert QualityGate(max_floor_ratio=0.0, max_uncertainty=0.1).reasons(ident)[0].count(
        'uncertainty') == 2
    ident.noise_floor_percent = math.nan              # no floor: only the uncertainty counts
    assert len(QualityGate().reasons(ident)) == 1
    assert QualityGate().to_dict([]) == {'passed': True, 'reasons': [], 'max_floor_ratio': 3.0,
                                         'max_uncertainty': 1.0}


def test_identification_job_cancels_within_a_global_run():
    """With ``workers == 1`` a global run runs in the job's thread: a cancel stops it too."""
    rec = off_chain_recording('position', seed=0)
    settings = IdentifySettings(seeds=(0,), maxiter=20, restarts=0, workers=1, hops=0,
                                global_evals=50_000_000, global_runs=1)   # minutes uncancelled
    job = IdentificationJob(rec, None, settings)
    deadline = 60.0
    while job.progress()['seeds_done'] < 1 and deadline > 0:
        job.wait(0.05)
        deadline -= 0.05
    job.wait(1.0)                                    # into the global run
    prog = job.progress()
    assert prog['seeds_done'] == 1 and 'global_runs_done' not in prog and not job.done, prog
    job.cancel()
    assert job.wait(10.0)
    assert job.cancelled and job.result is None and job.error is None


def test_diagnosis_job_cancels_inside_an_identification(monkeypatch):
    """A cancel reaches the baseline's identify (hopping, an in-process global run)."""
    import threading

    from hyst_id.diagnosis import baseline
    from hyst_id.identification.workers import WorkersStopped
    inside = threading.Event()

    def long_identify(rec, *, spec=None, settings=None, should_stop=None, **kwargs):
        inside.set()
        for _ in range(2000):                        # 100 s unless should_stop holds
            if should_stop is not None and should_stop():
                raise WorkersStopped('stopped on request')
            threading.Event().wait(0.05)
        raise AssertionError('the cancel did not reach identify')
    monkeypatch.setattr(baseline, 'identify', long_identify)
    ct, cv, mt, mv = _streams(600)
    job = DiagnosisJob(pair_streams(ct, cv, mt, mv, 'position'), seeds=1, generations=5)
    assert inside.wait(60.0)
    job.cancel()
    assert job.wait(5.0)
    assert job.cancelled and job.result is None and job.error is None
