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

"""What a diagnosis is asked to do and what it found (value objects).

:class:`DiagnoseSettings`, :class:`Finding` (one accepted mechanism with its
fitted block, words and held-out gain) and :class:`Diagnosis` (everything,
with its JSON document, its ``/diagnostics`` status and its text report).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from numbers import Real
from typing import Any, Callable

import numpy as np

from hyst_id.checks import check_fields
from hyst_id.diagnosis.blocked_cv import confirmed
from hyst_id.diagnosis.locate import Localization
from hyst_id.diagnosis.measured_loop import measured_loop, MeasuredLoop
from hyst_id.diagnosis.select import Criteria, FitResult
from hyst_id.errors import ConfigError
from hyst_id.io.jsonable import jsonable

__all__ = ['DiagnoseSettings', 'Diagnosis', 'Finding']


@dataclass(frozen=True)
class DiagnoseSettings:
    """How to diagnose.

    Attributes
    ----------
    train_fraction : float
        Share of the record's duration used for fitting (the rest is held out).
    seeds, generations, pop_size, workers :
        GAASS settings of the baseline's two identifications (fewer seeds than
        the paper; each result refined by least squares, then identify's
        global phase when they end above the floor; see
        :func:`hyst_id.diagnosis.baseline.baseline_starts`).
    mechanisms : tuple of str or None
        Mechanism ids to test (default: the whole library).
    max_mechanisms : int
        Most mechanisms added in sequence.
    criteria : Criteria
        Acceptance thresholds.
    fit_budget : int
        Residual evaluations for each local least-squares fit.
    hops : int
        Most jumps of identify's basin hopping in the baseline's and the
        whole record's identifications (identify's default, 100). A chain
        that lacks physics cannot reach the floor, so the jumps are all spent:
        on concealed bag ``case_h`` 100 jumps cost 36 of the diagnosis's 76 s
        for nothing, on the blind family's clean #27 they are what makes its
        baseline predict the held-out part (20 do not reach it;
        ``bench/diagnosis_hops.py``). The tests' short settings take 20.
    more_starts : bool
        The identifications with a global phase (the baseline's, the
        re-identifications of :mod:`hyst_id.diagnosis.refit`, the whole
        record's) build more chains from the data when the usual ones stop
        above the floor (identify's ``more_starts``; the quick searches and
        the four structured starts of the composed model stay as they are).
        Off by default: on 75 recordings of the blind family it took the
        physics claims off the two clean recordings that had them (#59,
        #63), moved three verdicts on recordings with effects (#9 saturation
        -> friction, #23 static_nonlinearity + dead_time -> creep, #13
        unknown -> gain_drift) and made the median diagnosis 1.7 x slower
        (docs/diagnosis.md). Off, a diagnosis still runs such a search where
        blocks were accepted against a baseline near its floor
        (:mod:`hyst_id.diagnosis.challenge`); on, there is no such challenge.
    start_state : bool
        When the baseline stays above its floor, try the record from the
        command's first reversal on, and diagnose that instead when a probe
        there nears the floor (:mod:`hyst_id.diagnosis.start_cut`: an actuator
        that starts inside its play). On by default.
    joint_generations : int
        Generations of the joint search of a round's leading candidates with the
        chain over the whole box (:mod:`hyst_id.diagnosis.joint`), run where a
        candidate's local fit lowers the training BIC yet stays above the floor;
        0 (the default): none. 300 found friction on three blind recordings
        the local fits had missed (#162, #164, #175) at seconds per search, two
        per round: on by default it slowed the test suite's diagnoses by about
        two fifths, beyond its 30 minutes (docs/diagnosis.md).
    loose_loops : bool
        When the proper baseline stays above its floor, search the loops the
        paper's constraints admit and the proper set does not (corners out of
        order), and run the diagnosis over them when such a loop alone fits the
        training part (:mod:`hyst_id.diagnosis.loose_baseline`). On by default;
        off where the set feeds H⁻¹ (the paper's experiment).
    should_stop : callable, optional
        Passed to the baseline's identifications (``identify(should_stop=...)``:
        looked at before each jump of hopping and each generation of an
        in-process global run; raises
        :class:`~hyst_id.identification.workers.WorkersStopped`). Not
        compared or printed.
    """

    train_fraction: float = 0.7
    seeds: tuple[int, ...] = (0, 1)
    generations: int = 200
    pop_size: int = 10
    workers: int = 1
    mechanisms: tuple[str, ...] | None = None
    max_mechanisms: int = 2
    criteria: Criteria = field(default_factory=Criteria)
    fit_budget: int = 600
    hops: int = 100
    more_starts: bool = False
    start_state: bool = True
    joint_generations: int = 0
    loose_loops: bool = True
    should_stop: Callable[[], bool] | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        check_fields(self, seeds='seeds',
                     at_least={'generations': 1, 'pop_size': 2, 'workers': 0,
                               'max_mechanisms': 0, 'fit_budget': 1, 'hops': 0,
                               'joint_generations': 0})
        if (isinstance(self.train_fraction, bool) or not isinstance(self.train_fraction, Real)
                or not 0.0 < self.train_fraction < 1.0):
            raise ConfigError('DiagnoseSettings.train_fraction: the train fraction must be in '
                              f'(0, 1), got {self.train_fraction!r}')


@dataclass
class Finding:
    """One mechanism the data support, with its fitted block and what it bought."""

    mechanism: str
    title: str
    placement: str
    explanation: str
    where: dict
    params: dict
    er_train_before_percent: float
    er_train_after_percent: float
    er_holdout_before_percent: float
    er_holdout_after_percent: float
    delta_bic: float
    holdout_z: float
    alternatives: list = field(default_factory=list)
    #: How the block is made up for in operation: ``{'kind': ..., 'how': words,
    #: 'correction': {augment.* values}}`` (:data:`hyst_id.diagnosis.mechanisms.base.
    #: COMPENSATION_KINDS`; the correction is empty without an in-line one).
    compensation: dict = field(default_factory=dict)
    #: the block against the model before it, each time block of the record predicted by
    #: a refit on the others (:func:`hyst_id.diagnosis.blocked_cv.confirm`), at acceptance
    blocked_cv: dict = field(default_factory=dict)
    #: searched parameters that ended on an edge of their search (words each)
    at_edges: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-ready form."""
        return {'mechanism': self.mechanism, 'title': self.title, 'placement': self.placement,
                'explanation': self.explanation, 'where': jsonable(self.where),
                'params': {k: q.to_dict() for k, q in self.params.items()},
                'er_train_before_percent': self.er_train_before_percent,
                'er_train_after_percent': self.er_train_after_percent,
                'er_holdout_before_percent': self.er_holdout_before_percent,
                'er_holdout_after_percent': self.er_holdout_after_percent,
                'delta_bic': self.delta_bic, 'holdout_z': self.holdout_z,
                'alternatives': jsonable(list(self.alternatives)),
                'compensation': dict(self.compensation),
                'blocked_cv': jsonable(self.blocked_cv), 'at_edges': list(self.at_edges)}


@dataclass
class Diagnosis:
    """Everything a diagnosis found (see :meth:`to_dict` for the JSON layout)."""

    channel: str
    source: str
    mode: str
    verdict: str
    t_s: np.ndarray
    command: np.ndarray
    measurement: np.ndarray
    n_train: int
    baseline: FitResult
    final: FitResult
    findings: list[Finding]
    localization: Localization
    final_localization: Localization
    noise_std: float
    noise_floor_percent: float
    noise_floor_train_percent: float
    rounds: list = field(default_factory=list)
    baseline_params: dict = field(default_factory=dict)
    measurement_unit: str = ''
    command_unit: str = ''
    notes: list = field(default_factory=list)
    extra: dict = field(default_factory=dict)
    #: What a model could still gain (:class:`~hyst_id.diagnosis.empirical.EmpiricalBlock`).
    empirical: Any = None
    #: What the file calls the signals (a CSV header's names); empty when unknown.
    measurement_name: str = ''
    command_name: str = ''

    @property
    def quantity(self) -> str:
        """The measured quantity for words and axes: the file's name for it, else the channel."""
        return self.measurement_name or self.channel

    @property
    def measured_loop(self) -> MeasuredLoop:
        """The loop the whole record traces, from the data alone (:mod:`.measured_loop`)."""
        return measured_loop(self.t_s, self.command, self.measurement)

    @property
    def train_fraction(self) -> float:
        """Share of the duration used for training."""
        t = self.t_s
        return float((t[self.n_train - 1] - t[0]) / (t[-1] - t[0]))

    def to_dict(self) -> dict:
        """The ``--json`` document."""
        t = self.t_s
        out = {
            'channel': self.channel, 'source': self.source, 'mode': self.mode,
            'verdict': self.verdict,
            'split': {'train_fraction': self.train_fraction, 'n_train': self.n_train,
                      'n_holdout': int(t.size - self.n_train),
                      't_split_s': float(t[self.n_train])},
            'baseline': {'er_train_percent': self.baseline.er_train_percent,
                         'er_holdout_percent': self.baseline.er_holdout_percent,
                         'params': self.baseline_params},
            'noise_floor_percent': self.noise_floor_percent,
            'noise_floor_train_percent': self.noise_floor_train_percent,
            'noise_std': self.noise_std, 'measurement_unit': self.measurement_unit,
            'measurement_name': self.measurement_name, 'command_name': self.command_name,
            'findings': [f.to_dict() for f in self.findings],
            'final': {'mechanisms': list(self.final.ids),
                      'er_train_percent': self.final.er_train_percent,
                      'er_holdout_percent': self.final.er_holdout_percent},
            'located': {'summary': self.localization.summary(self.measurement_unit),
                        **self.localization.to_dict()},
            'final_residual': {'summary': self.final_localization.summary(
                self.measurement_unit), 'white': self.final_localization.white,
                'independent': self.final_localization.independent},
            'measured_loop': self.measured_loop.to_dict(),
            'tested': self.rounds, 'notes': list(self.notes),
            'empirical': None if self.empirical is None else self.empirical.to_dict(),
        }
        out.update(self.extra)
        return jsonable(out)

    def status(self) -> tuple[str, str, dict[str, str]]:
        """Level (``ok``/``warn``), one-line message and string key-values, for diagnostics.

        A ROS node can put these straight into a ``diagnostic_msgs/DiagnosticStatus``
        (the core does not import ROS).
        """
        values = {'verdict': self.verdict, 'channel': self.channel,
                  'baseline_er_holdout_percent': f'{self.baseline.er_holdout_percent:.4g}',
                  'final_er_holdout_percent': f'{self.final.er_holdout_percent:.4g}',
                  'noise_floor_percent': f'{self.noise_floor_percent:.4g}',
                  'measured_loop': self.measured_loop.direction,
                  'mechanisms': ','.join(f.mechanism for f in self.findings)}
        shaky = [f.mechanism for f in self.findings if not confirmed(f.blocked_cv)]
        if shaky:       # fitted on the split, not held up by blocked cross-validation
            values['not_confirmed'] = ','.join(shaky)
        for f in self.findings:
            for name, q in f.params.items():
                values[f'{f.mechanism}.{name}'] = f'{q.value:.4g} {q.unit}'.strip()
            if f.compensation:
                values[f'{f.mechanism}.compensation'] = f.compensation['kind']
        if self.verdict == 'unknown' and self.extra.get('no_response'):
            return 'warn', 'the measurement does not follow the command', values
        if self.verdict == 'unknown' and not self.rounds:
            return 'warn', 'the model misses something; no block of the library was tried', values
        if self.verdict == 'unknown':
            return 'warn', ('something is missing that no mechanism of the library explains'
                            + (f': {self.empirical.summary()}' if self.empirical else '')), values
        if not self.findings:
            return 'ok', 'no missing physics found', values
        f = next(f for f in self.findings if f.mechanism == self.verdict)
        return 'warn', f'{f.mechanism}: {f.explanation.split(". ")[0]}', values

    def report(self) -> str:
        """Plain-text report (see :mod:`hyst_id.diagnosis.report`)."""
        from hyst_id.diagnosis.report import format_diagnosis
        return format_diagnosis(self)
