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

"""Live identification without ROS: samples, pairing, background jobs, the result.

What the identifier node (:mod:`hyst_id.nodes.identifier`) does that does
not need ``rclpy`` lives here, so it is tested and reused without a ROS
installation:

* :class:`SampleBuffer` collects the command and measurement streams of a
  run (stamps in ns) and turns them into a :class:`~hyst_id.io.recording.Recording`
  with :func:`pair_streams`, which pairs each measurement with the last
  command at or before it exactly as the bag reader
  (:func:`hyst_id.io.readers.read_mcap`) does, with the same sorting and
  de-duplication of each stream (:func:`hyst_id.io.readers._tidy`, one
  implementation for both) and the same notes; it also notes gaps in the
  measurement stream (samples lost in transit);
* :class:`IdentificationJob` and :class:`DiagnosisJob` run
  :func:`hyst_id.identify.identify` / :func:`hyst_id.diagnose.diagnose` in a
  worker thread, can be cancelled (:meth:`BackgroundJob.cancel`: between two
  seeds, or two diagnosis steps) and never raise into the caller;
* :func:`compensator_set`, :func:`result_document` and
  :func:`diagnosis_statuses` build what the node publishes.
"""

from __future__ import annotations

import datetime
import threading
import time
from typing import Any

import numpy as np

from hyst_id.chains import chain_spec, ChainSpec
from hyst_id.compensate import InverseModel
from hyst_id.errors import HystIdError, IdentificationError, InvalidParametersError
from hyst_id.identify import Identification, identify, IdentifySettings, SeedRun
from hyst_id.io.params_file import COMPENSATOR_NAMES
from hyst_id.io.readers import _tidy as tidy_stream
from hyst_id.io.recording import Recording

__all__ = ['BackgroundJob', 'DiagnosisJob', 'GAP_NOTE_FACTOR', 'IdentificationJob',
           'JobCancelled', 'SampleBuffer', 'compensator_set', 'diagnosis_statuses',
           'pair_streams', 'recovered_document', 'result_document', 'warm_up_kernels']

#: A measurement interval longer than this many median intervals is noted as a gap.
GAP_NOTE_FACTOR = 5.0


# ------------------------------------------------------------------ samples
def pair_streams(cmd_t_ns: np.ndarray, cmd_v: np.ndarray, meas_t_ns: np.ndarray,
                 meas_v: np.ndarray, channel: str, source: str = '',
                 units: tuple[str, str] = ('', ''),
                 names: tuple[str, str] = ('command', 'measurement')) -> Recording:
    """Pair each measurement with the last command at or before it (as the bag reader does).

    Each stream is sorted by stamp and repeated stamps keep their last
    sample (with a note each, like :func:`hyst_id.io.readers.read_mcap`);
    measurements before the first command are dropped (noted); gaps longer
    than :data:`GAP_NOTE_FACTOR` median intervals in the measurement stream
    are noted (validation refuses gaps beyond 1000 median intervals);
    ``t_s`` counts from the first kept measurement.

    Parameters
    ----------
    cmd_t_ns, cmd_v, meas_t_ns, meas_v : array_like
        Stamps (integer ns) and values of the two streams, in arrival order.
    channel : str
        Measured channel.
    source : str
        Where the samples came from (for reports).
    units : tuple of str
        Command and measurement units.
    names : tuple of str
        How the two streams are called in notes (e.g. their topics).

    Returns
    -------
    Recording
        Not validated; ``notes`` say what was sorted, dropped or missing.

    Raises
    ------
    IdentificationError
        A stream is empty or no measurement follows a command.
    """
    if len(cmd_t_ns) == 0 or len(meas_t_ns) == 0:
        raise IdentificationError(f'no samples yet: {len(cmd_t_ns)} commands, '
                                  f'{len(meas_t_ns)} measurements')
    notes: list[str] = []
    cmd_t, cmd_v = tidy_stream(np.asarray(cmd_t_ns, dtype=np.int64),
                               np.asarray(cmd_v, dtype=float), names[0], notes)
    meas_t, meas_v = tidy_stream(np.asarray(meas_t_ns, dtype=np.int64),
                                 np.asarray(meas_v, dtype=float), names[1], notes)
    idx = np.searchsorted(cmd_t, meas_t, side='right') - 1
    keep = idx >= 0
    if not keep.any():
        raise IdentificationError('no measurement at or after the first command (clocks of '
                                  'the publishers differ?)')
    if not keep.all():
        notes.append(f'dropped {int((~keep).sum())} {names[1]} samples before the first '
                     f'command')
    meas_t, meas_v, idx = meas_t[keep], meas_v[keep], idx[keep]
    t_s = (meas_t - meas_t[0]).astype(np.float64) * 1e-9
    gap = _gap_note(t_s, names[1])
    if gap:
        notes.append(gap)
    return Recording(t_s=t_s, command=cmd_v[idx], measurement=meas_v, channel=channel,
                     command_unit=units[0], measurement_unit=units[1], source=source,
                     notes=tuple(notes))


def _gap_note(t_s: np.ndarray, name: str) -> str:
    """Describe intervals longer than GAP_NOTE_FACTOR median intervals ('' if none)."""
    if t_s.size < 3:
        return ''
    dt = np.diff(t_s)
    median = float(np.median(dt))
    if median <= 0.0:
        return ''
    long = np.flatnonzero(dt > GAP_NOTE_FACTOR * median)
    if long.size == 0:
        return ''
    k = int(long[np.argmax(dt[long])])
    missing = int(np.sum(np.rint(dt[long] / median) - 1))
    return (f'{name}: {long.size} gap(s) longer than {GAP_NOTE_FACTOR:g} median intervals '
            f'({median:.3g} s), about {missing} samples missing; longest {dt[k]:.3g} s after '
            f't={t_s[k]:.6g} s')


class SampleBuffer:
    """Command and measurement samples of the current run (stamps in ns).

    Samples may arrive in any order (they are sorted when the recording is
    built). At most ``max_samples`` of each stream are kept (the oldest are
    dropped, in blocks of a tenth).
    """

    def __init__(self, max_samples: int = 2000000) -> None:
        self.max_samples = int(max_samples)
        self.clear()

    def clear(self) -> None:
        """Forget every sample."""
        self.cmd_t: list[int] = []
        self.cmd_v: list[float] = []
        self.meas_t: list[int] = []
        self.meas_v: list[float] = []
        self.last_rx: float | None = None

    def add_command(self, t_ns: int, value: float) -> None:
        """Append a command sample."""
        self.cmd_t.append(int(t_ns))
        self.cmd_v.append(float(value))
        self._trim(self.cmd_t, self.cmd_v)

    def add_measurement(self, t_ns: int, value: float) -> None:
        """Append a measurement sample."""
        self.meas_t.append(int(t_ns))
        self.meas_v.append(float(value))
        self._trim(self.meas_t, self.meas_v)
        self.last_rx = time.monotonic()

    def _trim(self, t: list, v: list) -> None:
        if len(t) > self.max_samples + self.max_samples // 10:
            del t[:len(t) - self.max_samples]
            del v[:len(v) - self.max_samples]

    @property
    def n_measurements(self) -> int:
        """Measurements collected."""
        return len(self.meas_t)

    def recording(self, channel: str, source: str = '', units: tuple[str, str] = ('', ''),
                  names: tuple[str, str] = ('command', 'measurement')) -> Recording:
        """The run so far as a Recording (see :func:`pair_streams`)."""
        return pair_streams(np.array(self.cmd_t, dtype=np.int64), np.array(self.cmd_v),
                            np.array(self.meas_t, dtype=np.int64), np.array(self.meas_v),
                            channel, source, units, names)


# --------------------------------------------------------------------- jobs
class JobCancelled(HystIdError):
    """Raised inside a worker to stop a cancelled job."""


class BackgroundJob:
    """Run :meth:`work` in a daemon thread; keep its result or a one-line error.

    ``done`` turns true when the thread has ended, with ``result`` set, or
    ``error`` (a message, never an exception), or ``cancelled``.
    :meth:`cancel` asks the work to stop at its next check point
    (:meth:`check_cancelled`); the caller should drop the job at once and
    treat whatever it returns later as void.
    """

    name = 'job'

    def __init__(self) -> None:
        self.result: Any = None
        self.error: str | None = None
        self.cancelled = False
        self.started = time.monotonic()
        self._cancel = threading.Event()
        self._thread = threading.Thread(target=self._run, name=self.name, daemon=True)

    def start(self) -> BackgroundJob:
        """Start the worker thread; return self."""
        self.started = time.monotonic()
        self._thread.start()
        return self

    def work(self) -> Any:
        """The job (runs in the worker thread)."""
        raise NotImplementedError

    def _run(self) -> None:
        try:
            self.check_cancelled()
            result = self.work()
            self.check_cancelled()
            self.result = result
        except JobCancelled:
            self.cancelled = True
        except HystIdError as exc:
            self.error = str(exc)
        except Exception as exc:  # noqa: BLE001 - reported by the caller, never a traceback
            self.error = f'{type(exc).__name__}: {exc}'

    def cancel(self) -> None:
        """Ask the job to stop at its next check point."""
        self._cancel.set()

    @property
    def cancel_requested(self) -> bool:
        """True once :meth:`cancel` was called."""
        return self._cancel.is_set()

    def check_cancelled(self) -> None:
        """Raise :class:`JobCancelled` when a cancel was requested (worker side)."""
        if self._cancel.is_set():
            raise JobCancelled(f'{self.name} cancelled')

    @property
    def done(self) -> bool:
        """True once the thread has ended (started jobs only)."""
        return self._thread.ident is not None and not self._thread.is_alive()

    @property
    def elapsed_s(self) -> float:
        """Seconds since the start."""
        return time.monotonic() - self.started

    def wait(self, timeout: float | None = None) -> bool:
        """Block until done (tests); return whether it is."""
        self._thread.join(timeout)
        return self.done


class IdentificationJob(BackgroundJob):
    """:func:`hyst_id.identify.identify` of one recording in a worker thread.

    The same function as ``hyst-id identify``, so the same settings and
    seeds give the same result. ``workers == 1`` runs the seeds one after
    the other in the thread (a cancel stops it within a generation);
    otherwise ``identify`` runs them in worker processes and the thread only
    waits (a cancel takes effect when they are done). :meth:`progress` is
    safe to call from another thread at any time; with ``workers == 1`` it
    also gives the running seed's GAASS generation.
    """

    name = 'identify'

    def __init__(self, rec: Recording, spec: ChainSpec, settings: IdentifySettings) -> None:
        super().__init__()
        self.rec, self.spec, self.settings = rec, spec, settings
        self.seeds = tuple(settings.seeds)
        self.runs: list[SeedRun] = []
        self.generation: dict[str, Any] = {}
        self.start()

    def work(self) -> Identification:
        return identify(self.rec, spec=self.spec, settings=self.settings,
                        progress=self._progress, on_generation=self._generation)

    def _progress(self, done: int, total: int, run: SeedRun) -> None:
        self.runs = self.runs + [run]
        self.check_cancelled()

    def _generation(self, seed: int, restart: int, generation: int, er: float) -> None:
        self.generation = {'seed': seed, 'restart': restart, 'generation': generation,
                           'seed_er_percent': er}
        self.check_cancelled()

    def progress(self) -> dict[str, Any]:
        """Seeds done, best %e_r so far, elapsed time; the running seed's generation.

        The generation is known when the seeds run in the job's own thread
        (``workers == 1``); a cancel then stops within one generation.
        """
        runs = self.runs
        out: dict[str, Any] = {'seeds_done': len(runs), 'seeds': len(self.seeds),
                               'elapsed_s': self.elapsed_s}
        if runs:
            out['best_er_percent'] = min(r.er_percent for r in runs)
        if self.generation and len(runs) < len(self.seeds):
            out.update(self.generation)
        return out


class DiagnosisJob(BackgroundJob):
    """:func:`hyst_id.diagnose.diagnose` of one recording in a worker thread.

    ``train_fraction``, ``seeds`` (how many, from 0), ``generations`` and
    ``mechanisms`` (ids, comma-separated or a sequence; empty = all) set the
    :class:`~hyst_id.diagnose.DiagnoseSettings`; ``kwargs`` go to
    ``diagnose`` (e.g. ``spec``). A cancel stops it at the next step it
    reports; ``step`` is the last step reported.
    """

    name = 'diagnose'

    def __init__(self, rec: Recording, *, train_fraction: float = 0.7, seeds: int = 2,
                 generations: int = 200, mechanisms: str | tuple[str, ...] = '',
                 **kwargs: Any) -> None:
        super().__init__()
        self.rec, self.kwargs = rec, kwargs
        if isinstance(mechanisms, str):
            mechanisms = tuple(m.strip() for m in mechanisms.split(',') if m.strip())
        self.options = {'train_fraction': float(train_fraction),
                        'seeds': tuple(range(int(seeds))), 'generations': int(generations),
                        'mechanisms': tuple(mechanisms) or None}
        self.step = 'starting'
        self.start()

    def work(self) -> Any:
        # heavy: imported in the worker, only when a diagnosis is asked for
        from hyst_id.diagnose import diagnose, DiagnoseSettings
        return diagnose(self.rec, settings=DiagnoseSettings(**self.options),
                        progress=self._progress, **self.kwargs)

    def _progress(self, message: str) -> None:
        self.step = str(message)
        self.check_cancelled()


# ------------------------------------------------------------------- result
def compensator_set(ident: Identification) -> tuple[dict | None, float, str]:
    """The parameter set to hand to the compensator, its %e_r, and a note.

    The best run's canonical set with its ``output_sign``. Canonical sets
    of feasible results are always valid compensator models (validation is
    gauge invariant, :func:`hyst_id.models.hysteresis.loop_is_proper`); the
    check is kept as a guard: a set the compensator would refuse gives
    ``(None, nan, reason)`` and nothing is handed over.
    """
    best = dict(ident.params, output_sign=float(getattr(ident, 'output_sign', 1.0)))
    try:
        InverseModel.from_mapping(best)
    except InvalidParametersError as exc:
        return None, float('nan'), (
            f'the identified set is not a valid compensator model ({exc}); nothing is handed '
            'to the compensator (please report this: canonical sets should always be valid)')
    return best, float(ident.er_percent), ''


def result_document(ident: Identification, n_samples: int, duration_s: float,
                    notes: tuple[str, ...] | list[str] = ()) -> dict:
    """JSON-ready summary published on the identified-parameters topic.

    ``params`` and ``er_percent`` are the identification's (as ``hyst-id
    identify`` reports them); ``compensator_params`` / ``compensator_er_percent``
    are the set the compensator should use (see :func:`compensator_set`);
    ``notes`` say what was sorted, dropped or missing in the samples.
    """
    comp, comp_er, note = compensator_set(ident)
    return {
        'compensator_params': comp, 'compensator_er_percent': comp_er,
        'compensator_note': note,
        'channel': ident.channel, 'params': ident.params, 'er_percent': ident.er_percent,
        'output_sign': float(getattr(ident, 'output_sign', 1.0)),
        'params_mean': ident.params_mean,
        'er_mean_params_percent': ident.er_mean_params_percent,
        'noise_floor_percent': ident.noise_floor_percent,
        'er_seeds_percent': [r.er_percent for r in ident.runs],
        'seeds': [r.seed for r in ident.runs], 'n_samples': int(n_samples),
        'duration_s': float(duration_s), 'domain_source': ident.domain_source,
        'settings': ident.to_dict()['settings'], 'source': ident.source,
        'notes': list(notes),
        'identified_at': datetime.datetime.now(datetime.timezone.utc).isoformat(),
    }


def recovered_document(values: dict, path: Any) -> dict:
    """The result document of a params file (``read_compensator_params`` values).

    What the identifier republishes after a restart: the set of its last
    result, as both ``params`` and ``compensator_params``.
    """
    params = {n: float(values[n]) for n in COMPENSATOR_NAMES + ('output_sign',)}
    return {'channel': values['channel'], 'params': params, 'compensator_params': params,
            'output_sign': params['output_sign'], 'er_percent': values['er_percent'],
            'compensator_er_percent': values['er_percent'], 'compensator_note': '',
            'notes': [], 'source': f'recovered from {path}'}


def warm_up_kernels(channel: str) -> None:
    """Compile (or load from cache) the numba kernels of ``channel``'s chain."""
    spec = chain_spec(channel)
    t = np.arange(8) * 0.1
    v = np.array([1.0, 2.0, 3.0, 2.0, 1.0, 2.0, 3.0, 2.0])
    x = np.array([[1.01, 1.05, 0.1, 0.15, -0.25, 0.5, 14.0, 7.0, 1.0, -0.2, 0.2, 1.0, 1.0,
                   1.0][:spec.n_params]])
    spec.cost_function(t, v, v)(x)
    spec.signal(x[0], t, v)


def diagnosis_statuses(doc: dict) -> list[tuple[int, str, str, dict[str, Any]]]:
    """One ``(level, name, message, values)`` per finding of a diagnosis document.

    ``doc`` is :meth:`hyst_id.diagnose.Diagnosis.to_dict`. A finding gives
    level 1 (WARN: the model lacks a mechanism) named after its mechanism,
    its explanation as message and, as values, the mechanism, its place in
    the chain, the held-out and training %e_r before and after adding it,
    and its parameters (``name: value unit``). No finding gives one level 0
    status with the verdict, the held-out %e_r and the noise floor.
    """
    out = []
    for f in doc.get('findings') or []:
        values: dict[str, Any] = {'mechanism': f.get('mechanism', '?'),
                                  'title': f.get('title', ''),
                                  'placement': f.get('placement', '')}
        for key in ('er_holdout_before_percent', 'er_holdout_after_percent',
                    'er_train_before_percent', 'er_train_after_percent', 'delta_bic'):
            if f.get(key) is not None:
                values[key] = float(f[key])
        for name, q in (f.get('params') or {}).items():
            if isinstance(q, dict):
                value = q.get('value')
                text = 'nan' if value is None else f'{float(value):.6g}'
                values[f'param.{name}'] = (text + f' {q.get("unit", "")}').strip()
            else:
                values[f'param.{name}'] = str(q)
        message = str(f.get('explanation') or f.get('title') or f.get('mechanism', ''))
        out.append((1, str(f.get('mechanism', '?')), message, values))
    if not out:
        base = doc.get('baseline') or {}
        er = base.get('er_holdout_percent')
        floor = doc.get('noise_floor_percent')
        values = {'verdict': doc.get('verdict', 'none')}
        if er is not None:
            values['er_holdout_percent'] = float(er)
        if floor is not None:
            values['noise_floor_percent'] = float(floor)
        out.append((0, 'none', f'no missing mechanism found (verdict {values["verdict"]}'
                    + (f', held-out %e_r {er:.4g}' if er is not None else '')
                    + (f', noise floor {floor:.4g}' if floor is not None else '') + ')',
                    values))
    return out
