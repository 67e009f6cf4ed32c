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

"""The baseline fit: the paper's chain of a channel on the training part.

GAASS with a few seeds (refined by least squares, :func:`hyst_id.identification.identify`)
finds a basin; a handful of starts built from the data themselves
(:func:`structured_starts`: the loop width measured where the output
crosses its median, split between H and the backlash) are polished too,
because on some records every GAASS seed ends in the same wrong basin (a
backlash dead band standing in for the hysteron's flat inner lines). The
best of them all is the baseline; the data-built starts also seed the
mechanism fits, so that a chain distorted by a missing mechanism does not
trap them.
"""

from __future__ import annotations

import hashlib
import os
import threading

import numpy as np

from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import ChainSpec
from hyst_id.identification.starts import data_starts, SPLITS
from hyst_id.io.recording import Recording, ROUNDOFF_PROBE_ENV

__all__ = ['baseline_starts', 'forget_quick', 'identify_base', 'quick_memo', 'quick_starts',
           'remember', 'structured_starts', 'whole_record_er']

#: Most quick searches kept (:func:`quick_starts`); the oldest go first.
QUICK_KEPT = 8
_QUICK: dict[str, tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]] = {}
_QUICK_LOCK = threading.Lock()


def structured_starts(spec: ChainSpec, t_s: np.ndarray, v: np.ndarray, y: np.ndarray,
                      sensor: np.ndarray, splits: tuple = SPLITS) -> list[np.ndarray]:
    """Chain starts built from the data (:func:`hyst_id.identification.starts.data_starts`).

    One loop per split (unit mean side slopes), the given sensor parameters.
    """
    return data_starts(spec, t_s, v, y, sensors=[np.asarray(sensor, dtype=float)],
                       splits=splits, per_split=1)


def identify_base(settings) -> dict:
    """The identify settings of a diagnosis baseline, from its ``DiagnoseSettings``."""
    return {'pop_size': settings.pop_size, 'maxiter': settings.generations,
            'seeds': tuple(settings.seeds), 'workers': settings.workers, 'refine': True,
            'refine_top': 2, 'restarts': 1, 'refine_max_nfev': 1500, 'hops': settings.hops,
            'start_state': False, 'loose_loops': False}


def baseline_starts(rec_train: Recording, spec: ChainSpec, settings, *, thorough: bool = True,
                    global_phase: bool | None = None, others: list | None = None
                    ) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """The best identified chains and the data-built starts.

    Returns the best chain of each identification (canonical to the spec's
    initial state, raw parameters) and the data-built starts; the caller
    polishes them all in its composed model, in every hold convention it
    tries, and keeps the best.

    ``thorough`` (the baseline of a diagnosis): two identifications with
    identify's global phase, one in the spec's conventions
    (``conventions='given'``) and one choosing them from the data
    (``'auto'``; its runs that start on the other boundary are dropped: the
    composed model starts on the spec's). A baseline short of the floor is
    what a mechanism block then fills: with the old baseline (two GAASS seeds,
    given conventions, no global phase) 14 of the 39 clean recordings of the
    blind family claimed physics, with this one and the null control 3
    (bench/blind_family.py, docs/diagnosis.md). Otherwise (a family swap's
    refit) the quick search: GAASS seeds refined, given conventions.
    ``global_phase`` (default: as ``thorough``) adds identify's global phase
    (one run) to the quick search (the re-identification of a chain with its
    accepted blocks undone, :mod:`hyst_id.diagnosis.refit`).
    ``others``: the best chain (raw parameters) of the thorough search's runs that
    start on the other boundary is appended to it, for
    :func:`hyst_id.diagnosis.challenge.chain_fit` to weigh.
    """
    base = identify_base(settings)
    runs = []
    for conventions in (('given', 'auto') if thorough else ('given',)):
        use_global = thorough if global_phase is None else global_phase
        global_evals = IdentifySettings.global_evals if use_global else 0   # identify's default
        # one global run in the given conventions, two (best and runner-up) in 'auto'
        ident = identify(rec_train, spec=spec, settings=IdentifySettings(
            **base, conventions=conventions, global_evals=global_evals,
            global_runs=1 if conventions == 'given' else 2,
            more_starts=settings.more_starts and use_global),
            should_stop=settings.should_stop)
        own = [r for r in ident.runs if r.initial == spec.initial]
        if own:
            runs.append(min(own, key=lambda r: r.fun))
        other = [r for r in ident.runs if r.initial != spec.initial]
        if other and others is not None:
            others.append(np.array(min(other, key=lambda r: r.fun).x_raw, dtype=float))
    x_fits = [np.array(r.x_raw, dtype=float) for r in sorted(runs, key=lambda r: r.fun)]
    return x_fits, structured_starts(spec, rec_train.t_s, rec_train.command,
                                     rec_train.measurement, x_fits[0][spec.sensor_slice])


def _quick_key(rec_train: Recording, spec: ChainSpec, settings) -> str:
    """What a quick search depends on: the samples, the chain spec, the search settings.

    Not the number of worker processes (the search is the same with any)
    nor the stop check; the round-off probe is in (it perturbs the samples
    again inside :func:`~hyst_id.identification.identify`). Nor
    ``settings.more_starts``: a quick search has no global phase, and
    :func:`baseline_starts` gives identify more starts only with one.
    """
    h = hashlib.sha1()
    for a in (rec_train.t_s, rec_train.command, rec_train.measurement, spec.bounds):
        h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    search = {k: v for k, v in identify_base(settings).items() if k != 'workers'}
    h.update(repr((rec_train.channel, spec.channel, spec.family.id, spec.initial, spec.hold,
                   spec.proper,
                   spec.calibration, spec.domain_source, sorted(search.items()),
                   os.environ.get(ROUNDOFF_PROBE_ENV, '').strip())).encode())
    return h.hexdigest()


def quick_starts(rec_train: Recording, spec: ChainSpec, settings
                 ) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """:func:`baseline_starts` without the thorough search, remembered across rounds.

    A family swap (:func:`hyst_id.diagnosis.trial.try_mechanism`) searches
    the new family's chain on the training part in every round; the search
    depends on nothing the rounds change, so its answer is kept (keyed on
    the samples, the spec and the settings) and the next round reuses it,
    in this process or, handed over by :func:`hyst_id.diagnosis.trial.try_all`,
    in its workers. The answer is the same either way: this only saves the
    repeated search. Copies are returned; the kept arrays are never written.
    """
    key = _quick_key(rec_train, spec, settings)
    with _QUICK_LOCK:
        got = _QUICK.get(key)
    if got is None:
        got = baseline_starts(rec_train, spec, settings, thorough=False)
        remember({key: got})
    x_fits, starts = got
    return [x.copy() for x in x_fits], [x.copy() for x in starts]


def quick_memo() -> dict[str, tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]]:
    """The quick searches this process holds (to hand between a round and its workers)."""
    with _QUICK_LOCK:
        return dict(_QUICK)


def remember(memo: dict) -> None:
    """Keep ``memo``'s quick searches in this process (at most :data:`QUICK_KEPT`)."""
    with _QUICK_LOCK:
        for key, (x_fits, starts) in memo.items():
            _QUICK.pop(key, None)
            _QUICK[key] = (tuple(x_fits), tuple(starts))
        while len(_QUICK) > QUICK_KEPT:
            _QUICK.pop(next(iter(_QUICK)))


def forget_quick() -> None:
    """Drop every kept quick search (a long-running process may want a clean slate)."""
    with _QUICK_LOCK:
        _QUICK.clear()


def whole_record_er(rec: Recording, spec: ChainSpec, settings) -> float:
    """%e_r of the chain identified on every sample of ``rec`` (training and held out).

    Asked only when the held-out part is missed and no block explains it:
    a chain that makes the whole record at its noise floor leaves nothing
    the data can show missing, and the held-out miss is then parameters the
    training part did not pin down (the held-out command going where the
    training's did not, along the loop), not physics. Identify's global
    phase as in the baseline (one run per convention, hopping).
    """
    base = identify_base(settings)
    return float(identify(rec, spec=spec, settings=IdentifySettings(
        **base, global_runs=4, more_starts=settings.more_starts),
        should_stop=settings.should_stop).er_percent)
