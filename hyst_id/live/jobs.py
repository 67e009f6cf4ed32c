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

"""Identification and diagnosis in a worker thread: cancellable, never raising into the caller.

:class:`BackgroundJob` runs :meth:`~BackgroundJob.work` in a daemon thread and
keeps its result or a one-line error; :class:`IdentificationJob` and
:class:`DiagnosisJob` call :func:`hyst_id.identification.identify` /
:func:`hyst_id.diagnosis.diagnose` with progress a node can publish;
:class:`SlidingJob` re-identifies a sliding window and decides a swap
(:func:`hyst_id.live.sliding.reidentify_window`).
"""

from __future__ import annotations

import threading
import time
from typing import Any

from hyst_id.diagnosis.mechanisms.registry import mechanism_ids
from hyst_id.errors import HystIdError
from hyst_id.identification import Identification, identify, IdentifySettings, SeedRun
from hyst_id.identification.chains import ChainSpec
from hyst_id.identification.model_choice import choose_family, ModelChoice
from hyst_id.io.recording import Recording

__all__ = ['BackgroundJob', 'DiagnosisJob', 'IdentificationJob', 'JobCancelled', 'SlidingJob']


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
            if self._cancel.is_set():       # e.g. WorkersStopped: the workers were ended
                self.cancelled = True
            else:
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
    """:func:`hyst_id.identification.identify` of one recording in a worker thread.

    The same function as ``hyst-id identify``, so the same settings and
    seeds give the same result. ``workers == 1`` runs the seeds one after
    the other in the thread (a cancel stops it within a generation);
    otherwise ``identify`` runs them in worker processes, which a cancel
    ends within 0.2 s. :meth:`progress` is
    safe to call from another thread at any time; with ``workers == 1`` it
    also gives the running seed's GAASS generation.

    With ``families`` (ids, e.g. ``('tk', 'smooth')``) H's family is chosen
    on held-out data first (:func:`~hyst_id.identification.model_choice.choose_family`;
    ``spec`` is then unused): the seeds run once per family and once more
    for the final fit, and :attr:`choice` holds the comparison.
    """

    name = 'identify'

    def __init__(self, rec: Recording, spec: ChainSpec | None, settings: IdentifySettings,
                 families: tuple[str, ...] = ()) -> None:
        super().__init__()
        self.rec, self.spec, self.settings = rec, spec, settings
        self.families = tuple(families)
        self.choice: ModelChoice | None = None
        self.seeds = tuple(settings.seeds) * ((len(self.families) + 1) if self.families else 1)
        self.runs: list[SeedRun] = []
        self.generation: dict[str, Any] = {}
        self.hopping: dict[str, Any] = {}
        self.start()

    def work(self) -> Identification:
        def progress(done: int, total: int, run: SeedRun) -> None:
            self.runs = self.runs + [run]
            self.hopping = {}                 # a seed or a global run: hopping is over
            self.check_cancelled()

        def hopping(jump: int, jumps: int, er: float) -> None:
            self.hopping = ({'hop': jump + 1, 'hops': jumps, 'hop_er_percent': er}
                            if jump < jumps else {})       # jump == jumps: hopping ended
            self.check_cancelled()
        progress.hopping = hopping            # identify calls it before each jump
        if self.families:
            self.choice = choose_family(self.rec, self.families, settings=self.settings,
                                        seed_progress=progress,
                                        on_generation=self._generation,
                                        should_stop=self._cancel.is_set)
            return self.choice.identification
        return identify(self.rec, spec=self.spec, settings=self.settings,
                        progress=progress, on_generation=self._generation,
                        should_stop=self._cancel.is_set)

    def _generation(self, seed: int, restart: int, generation: int, er: float) -> None:
        self.generation = {'seed': seed, 'restart': restart, 'generation': generation,
                           'seed_er_percent': er}
        self.check_cancelled()

    def progress(self) -> dict[str, Any]:
        """Seeds and global runs done, best %e_r so far, elapsed time; the seed's generation.

        While basin hopping, the jump it is on (``hop``, ``hops``,
        ``hop_er_percent``).

        The generation is known when the seeds run in the job's own thread
        (``workers == 1``); a cancel then stops within one generation.
        """
        runs = self.runs
        seeds = [r for r in runs if r.seed >= 0]
        out: dict[str, Any] = {'seeds_done': len(seeds), 'seeds': len(self.seeds),
                               'elapsed_s': self.elapsed_s}
        if len(runs) > len(seeds):          # the global phase's runs after the seeds
            out['global_runs_done'] = len(runs) - len(seeds)
        if runs:
            out['best_er_percent'] = min(r.er_percent for r in runs)
        if self.generation and len(seeds) < len(self.seeds):
            out.update(self.generation)
        hopping = self.hopping
        if hopping:                         # hopping now (it is cleared by the next run)
            out.update(hopping)
        return out


class DiagnosisJob(BackgroundJob):
    """:func:`hyst_id.diagnosis.diagnose` of one recording in a worker thread.

    ``train_fraction``, ``seeds`` (how many, from 0), ``generations``, ``hops``,
    ``more_starts`` and ``mechanisms`` (ids, comma-separated or a sequence; empty
    = all) set the :class:`~hyst_id.diagnosis.DiagnoseSettings`; ``kwargs`` go to
    ``diagnose`` (e.g. ``spec``). A cancel stops it at the next step it
    reports; ``step`` is the last step reported.
    """

    name = 'diagnose'

    def __init__(self, rec: Recording, *, train_fraction: float = 0.7, seeds: int = 2,
                 generations: int = 200, mechanisms: str | tuple[str, ...] = '',
                 hops: int = 100, more_starts: bool = False, **kwargs: Any) -> None:
        super().__init__()
        self.rec, self.kwargs = rec, kwargs
        if isinstance(mechanisms, str):
            mechanisms = mechanism_ids(mechanisms)
        self.options = {'train_fraction': float(train_fraction),
                        'seeds': tuple(range(int(seeds))), 'generations': int(generations),
                        'mechanisms': tuple(mechanisms) or None, 'hops': int(hops),
                        'more_starts': bool(more_starts)}
        self.step = 'starting'
        self.start()

    def work(self) -> Any:
        # heavy: imported in the worker, only when a diagnosis is asked for
        from hyst_id.diagnosis import diagnose, DiagnoseSettings
        return diagnose(self.rec, settings=DiagnoseSettings(
            **self.options, should_stop=self._cancel.is_set),   # inside its identifications
            progress=self._progress, **self.kwargs)

    def _progress(self, message: str) -> None:
        self.step = str(message)
        self.check_cancelled()


class SlidingJob(BackgroundJob):
    """:func:`hyst_id.live.sliding.reidentify_window` in a worker thread.

    ``result`` is the :class:`~hyst_id.live.sliding.SwapDecision`; ``kwargs``
    go to ``reidentify_window`` (``rule``, ``gate``, ``fresh_settings``). The
    fresh identification runs its seeds in this thread, so a cancel stops it
    within a generation.
    """

    name = 'sliding'

    def __init__(self, current: Identification, window: Recording, **kwargs: Any) -> None:
        super().__init__()
        self.current, self.window, self.kwargs = current, window, kwargs
        self.start()

    def work(self) -> Any:
        from hyst_id.live.sliding import reidentify_window
        return reidentify_window(self.current, self.window, should_stop=self._cancel.is_set,
                                 **self.kwargs)
