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

"""The data-built incumbent: four splits, five more while above a floor it is given.

On blind recording #63 of ``bench/blind_family.py`` (independent reference
simulator, clean pressure, random steps) the four splits of
:data:`~hyst_id.identification.starts.SPLITS` polish into other basins than
the true chain's (2.8-2.9 x the floor unperturbed): the five of
:data:`~hyst_id.identification.starts.MORE_SPLITS` are asked for there. Which
basin a polish ends in turns on round-off there (``bench/start_splits.py``,
docs/model.md), so this test checks the rule, not a figure;
``test/diagnosis/test_clean_blind.py`` checks what it buys on #59.
"""

from __future__ import annotations

import multiprocessing
from pathlib import Path
import sys

import numpy as np
import pytest

from hyst_id.identification import incumbent
from hyst_id.identification.chains import chain_spec
from hyst_id.identification.result import IdentifySettings
from hyst_id.identification.starts import MORE_SPLITS, SPLITS
from hyst_id.io.recording import Recording, roundoff_probe, validate_recording
from hyst_id.signals.split import split_index

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))
import blind_family  # noqa: E402, I100

__all__: list[str] = []


def _training_part(index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The first 70 % in a diagnosis's normalised command scale (7-11), probed.

    Under ``HYST_ID_ROUNDOFF_PROBE`` perturbed at round-off level as identify
    and diagnose perturb what they are given (:func:`roundoff_probe`).
    """
    case = blind_family.draw(index)
    t, u, y = case['t'], case['command'], case['measurement']
    n = split_index(t, 0.7)
    lo, hi = float(u[:n].min()), float(u[:n].max())
    half = 0.5 * (hi - lo)
    v = (u[:n] - (0.5 * (lo + hi) - 4.5 * half)) / (half / 2.0)
    rec = roundoff_probe(validate_recording(Recording(t[:n], v, y[:n], case['channel'])))
    return rec.t_s, rec.command, rec.measurement


def test_more_splits_only_with_a_floor_and_above_it(monkeypatch):
    """No floor or a floor the four reach: the four alone; otherwise the five too."""
    asked = []
    real = incumbent.data_starts

    def spy(*args, splits, **kwargs):
        asked.append(splits)
        return real(*args, splits=splits, **kwargs)

    monkeypatch.setattr(incumbent, 'data_starts', spy)
    t, v, y = _training_part(63)
    spec = chain_spec('pressure')
    for floor, want in ((None, [SPLITS]), (1e3, [SPLITS]), (1e-6, [SPLITS, MORE_SPLITS])):
        asked.clear()
        got = incumbent.data_incumbent(spec, t, v, y, IdentifySettings(), floor)
        assert asked == want and got is not None


def test_the_other_hold_ranks_the_starts_again_only_with_a_floor(monkeypatch):
    """rank_conventions: data-built starts under the other hold only above a given floor."""
    holds = []
    real = incumbent._data_incumbent

    def spy(spec, *args):
        holds.append((spec.initial, spec.hold))
        return real(spec, *args)

    monkeypatch.setattr(incumbent, '_data_incumbent', spy)
    t, v, y = _training_part(63)
    spec = chain_spec('pressure')
    rec = Recording(t, v, y, 'pressure')
    first = incumbent.data_incumbent(spec, t, v, y, IdentifySettings())
    for floor, other_hold_runs in ((None, 0), (1e-6, 2)):
        holds.clear()
        ranked = incumbent.rank_conventions(spec, rec, first, IdentifySettings(), floor)
        assert sum(h != spec.hold for _, h in holds) == other_hold_runs
        assert len(ranked) == 4       # two initial states x two holds


def side_by_side() -> None:
    """The data-built starts and the conventions polished in two workers: the same answer.

    Run by :func:`test_polished_side_by_side_gives_the_same_bits` in a fresh
    process, which has one thread, so that the two workers are forked (a test
    process may have threads left by earlier tests, and the polishes then run
    in it). Raises AssertionError when the pool was not used or a bit differs.
    """
    from pool_watch import watch_pools
    pools = watch_pools(incumbent)
    t, v, y = _training_part(63)
    spec = chain_spec('pressure')
    rec = Recording(t, v, y, 'pressure')
    outs = []
    for workers in (1, 2):
        pools.clear()
        settings = IdentifySettings(workers=workers)
        first = incumbent.data_incumbent(spec, t, v, y, settings, 1e-6)
        ranked = incumbent.rank_conventions(spec, rec, first, settings, 1e-6)
        outs.append((first, ranked))
        assert len(pools) == 2
        if workers == 1:
            assert pools == [None, None], 'one worker: polished in this process'
        else:
            assert all(p is not None for p in pools), 'two workers: polished in the pool'
    (first_a, ranked_a), (first_b, ranked_b) = outs
    np.testing.assert_array_equal(first_a[0], first_b[0])
    assert first_a[1:] == first_b[1:]
    assert [r[0] for r in ranked_a] == [r[0] for r in ranked_b]
    for (_, (xa, fa, na)), (_, (xb, fb, nb)) in zip(ranked_a, ranked_b):
        np.testing.assert_array_equal(xa, xb)
        assert (fa, na) == (fb, nb)


@pytest.mark.skipif('fork' not in multiprocessing.get_all_start_methods(),
                    reason='no fork on this platform: the polishes run in one process')
def test_polished_side_by_side_gives_the_same_bits():
    """Every polish is computed as in one process and taken in the same order.

    So the incumbent, the ranking and the evaluation counts are equal to the
    last bit with one worker and two (the floor of 1e-6 makes the five extra
    splits and the other hold's starts run too); :func:`side_by_side` in a
    fresh process.
    """
    from pool_watch import in_fresh_process
    done = in_fresh_process(__file__, 'side_by_side()')
    assert done.returncode == 0, done.stderr[-3000:]


def test_the_polishes_get_as_many_processes_as_the_seeds(monkeypatch):
    """The rule of identify: ``workers`` (0: one per core), at most one per seed, at least one."""
    import os

    from hyst_id.identification.workers import n_processes
    monkeypatch.setattr(os, 'cpu_count', lambda: 8)
    assert [n_processes(w, n) for w, n in ((0, 2), (0, 12), (3, 2), (1, 5), (4, 0))] == \
        [2, 8, 2, 1, 1]
    asked = []
    monkeypatch.setattr(incumbent, 'forked_pool', lambda n: asked.append(n))
    for seeds, workers in (((0,), 0), ((0, 1), 0), ((0, 1, 2), 2)):
        incumbent.polish_pool(IdentifySettings(seeds=seeds, workers=workers))
    assert asked == [1, 2, 2]
