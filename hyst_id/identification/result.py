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

"""What an identification is asked to do and what it returns (plain value objects).

:class:`IdentifySettings` (GAASS and refinement settings, the paper's by
default), :class:`SeedRun` (one seed's result) and :class:`Identification`
(everything :func:`hyst_id.identification.identify` produced). No computation
here beyond building the JSON form and the chain spec of the result.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, replace

import numpy as np

from hyst_id.checks import check_fields
from hyst_id.identification.chains import chain_spec, ChainSpec
from hyst_id.models.tk import loop_is_proper

__all__ = ['IdentifySettings', 'SeedRun', 'Identification']


@dataclass(frozen=True)
class IdentifySettings:
    """How to identify; defaults are the paper's GAASS settings plus refinement.

    Attributes
    ----------
    pop_size, maxiter, c, xi :
        GAASS population size, generations, contraction rate (Eq. 15) and
        mutation subspace coefficient (Eq. 22).
    seeds : tuple of int
        One GAASS run per seed; results are averaged like the paper's Table 1.
    workers : int
        Parallel processes (0: one per core, at most one per seed).
    refine : bool
        Polish each GAASS result with bounded least squares (GAASS-only when False).
    refine_max_nfev : int
        Cost evaluations allowed to each refinement.
    refine_top : int
        How many of the best distinct chromosomes of a GAASS run are refined.
    restarts : int
        Extra GAASS runs (new derived seeds) while %e_r is above
        ``restart_factor`` times the estimated noise floor (refinement on only).
    restart_factor : float
        Restarts stop once %e_r is within this factor of the noise floor.
    restart_patience : int
        Restarts also stop after this many in a row that lower the cost by
        less than 1 % while %e_r is above 1.5 x the noise floor (the floor is
        out of the model's reach: real data with unmodelled physics would
        otherwise always pay for every restart).
    er_bound_percent : float or None
        Stop a GAASS run early once %e_r falls below this bound.
    data_starts : bool
        With refinement on, polish the chains built from the data once and
        give every seed the best of them as the result to beat
        (:func:`hyst_id.identification.incumbent.data_incumbent`). Off, or with
        ``refine=False`` (the paper's procedure), seeds start from GAASS alone.
    conventions : {'auto', 'given'}
        ``auto``: with data starts on, choose the chain's initial state and
        sensor hold convention from the data
        (:func:`hyst_id.identification.incumbent.rank_conventions`; a seed's
        odd restarts try the runner-up); ``given``: keep the spec's.
    global_evals : int
        With refinement on, when the seeds end above ``global_factor`` times
        the estimated noise floor, runs of scipy's differential evolution
        over the whole box, each refined, join the runs (seeds ``-1``,
        ``-2``, ...) when they do better: one per initial state and sensor
        hold convention with this many evaluations, then, while the fit is
        within ``long_runs_within`` x the floor, runs with three times
        as many under the best fit's conventions, in rounds of two until the
        fit reaches
        ``global_factor`` or ``global_runs`` are spent
        (:mod:`hyst_id.identification.global_phase`). 0: off.
    global_factor : float
        The floor multiple above which the global phase runs.
    global_runs : int
        Most runs of the global phase (0: off); 14: the sweep of
        conventions and up to ten longer runs.
    long_runs_within : float
        The global phase's longer runs and basin hopping only while the best
        fit is within this multiple of the floor: further off, the misfit is
        taken for physics the chain lacks (a choice between H families
        compares them with 1.5 and 6 runs:
        :func:`hyst_id.identification.model_choice.choose_family`).
    hops : int
        With refinement on, when the best seed ends between ``global_factor``
        and ``long_runs_within`` x the floor: the most jumps of basin hopping from it before
        the global phase, and again from the global phase's best when that
        improved but is still above (:mod:`hyst_id.identification.hop`;
        fewer on a record over 5,000 samples). 0: off.
    search_samples : int
        With refinement on, on a record longer than this the GAASS runs, the
        polishes of each run's best chromosomes and of the data-built starts
        see about this many samples: every k-th sample plus every command
        reversal (the loop's memory),
        :func:`hyst_id.identification.incumbent.search_subset`; the best of each
        group is then polished on all samples, and every cost compared
        between seeds and every figure reported uses all samples. 0: always
        all.
    more_starts : bool
        With data starts on, when the incumbent of the four splits of the
        loop width (:data:`hyst_id.identification.starts.SPLITS`) stays above
        the noise floor: the five of
        :data:`~hyst_id.identification.starts.MORE_SPLITS` too, and under
        ``conventions='auto'`` the data-built starts ranked again under the
        other sensor hold (:func:`hyst_id.identification.incumbent.data_incumbent`,
        :func:`~hyst_id.identification.incumbent.rank_conventions`). Off by
        default: in a diagnosis's baseline it took the claims off the two
        clean blind recordings that had them (#59, #63) but moved three
        verdicts of recordings with effects (two from right to wrong) and
        made a diagnosis 1.7 x slower (median, 75 recordings;
        docs/diagnosis.md). Nothing to do with ``refine`` off.
    start_state : bool
        When the fit stays above 1.5 x the noise floor, try the record from
        the command's first reversal on and keep that fit when it is clearly
        closer to its floor (:mod:`hyst_id.identification.start_state`: an
        actuator that starts inside its play). Off in the paper's experiment
        (the paper fits the whole run) and in a diagnosis's baseline (judged
        on the whole record; its blind-family figures were measured without).
    loose_loops : bool
        With refinement on, when every proper search ends above ``global_factor``
        x the floor (beyond :data:`~hyst_id.identification.loose_phase.LOOSE_WITHIN`
        x only when a quick loose fit comes within it):
        search the paper's constraint set too, loops whose output jumps at some
        reversals (:mod:`hyst_id.identification.loose_phase`), and keep such a loop
        only when it fits clearly better. Off in the paper's experiment, a
        diagnosis's baseline and the live identifier (their sets feed H⁻¹, which
        needs a proper loop).
    """

    pop_size: int = 10
    maxiter: int = 500
    c: float = 0.007
    xi: float = 0.02
    seeds: tuple[int, ...] = tuple(range(10))
    workers: int = 0
    refine: bool = True
    refine_max_nfev: int = 2000
    refine_top: int = 3
    restarts: int = 4
    restart_factor: float = 1.05
    restart_patience: int = 2
    er_bound_percent: float | None = None
    data_starts: bool = True
    conventions: str = 'auto'
    global_evals: int = 200000
    global_factor: float = 1.1
    global_runs: int = 14
    long_runs_within: float = 4.0
    hops: int = 100
    search_samples: int = 20000
    more_starts: bool = False
    start_state: bool = True
    loose_loops: bool = True

    def __post_init__(self) -> None:
        check_fields(self, seeds='seeds', choices={'conventions': ('auto', 'given')},
                     at_least={'workers': 0, 'refine_max_nfev': 1, 'refine_top': 1,
                               'restarts': 0, 'restart_patience': 0, 'global_evals': 0,
                               'global_runs': 0, 'hops': 0, 'search_samples': 0},
                     positive=('restart_factor', 'er_bound_percent', 'global_factor',
                               'long_runs_within'))


@dataclass
class SeedRun:
    """Result of one seed: GAASS, then (optionally) refinement, raw and canonical.

    ``sign`` is the canonical calibration gain (+1, or -1 for a sensor that
    falls as the actuator output rises): measurement = ``sign * chain(x)``.
    ``initial`` and ``hold`` are the conventions of the chain ``x`` belongs to
    (a seed's restarts may try the runner-up conventions, see
    :func:`hyst_id.identification.driver.run_seed`).
    """

    seed: int
    x_raw: np.ndarray
    x: np.ndarray
    sign: float
    fun: float
    er_percent: float
    er_gaass_percent: float
    nfev: int
    nit: int
    best_history: np.ndarray
    message: str
    initial: str = 'rising'
    hold: str = 'before'


@dataclass
class Identification:
    """Everything an identification produced.

    Attributes
    ----------
    channel : str
        Channel of the chain.
    names : tuple of str
        Parameter names.
    params : dict
        Best run's parameters in the canonical gauge (output in measurement units).
    params_mean : dict
        Canonical parameters averaged over seeds (the paper's Table 1 convention).
    output_sign : float
        +1, or -1 when the measurement falls as the actuator output rises;
        the canonical chain predicts ``output_sign * measurement``.
    er_percent : float
        %e_r of the best run.
    er_mean_params_percent : float
        %e_r of the averaged parameters.
    noise_floor_percent : float
        %e_r that the estimated measurement noise alone gives.
    runs : list of SeedRun
        Per-seed results.
    bounds : numpy.ndarray
        Search domains used.
    initial, hold : str
        The chain's initial state and sensor hold convention
        (:attr:`hyst_id.identification.chains.ChainSpec.initial`, ``.hold``).
    other_nfev : int
        Evaluations of global-phase runs and basin hopping that did not improve
        (not in ``runs``); :attr:`nfev` counts them with the runs'.
    proper_alternative : Identification or None
        When the loop kept is not :attr:`proper`: the best proper loop the proper
        search found before (what a compensator can invert); else None.
    """

    channel: str
    names: tuple[str, ...]
    params: dict
    params_mean: dict
    output_sign: float
    er_percent: float
    er_mean_params_percent: float
    noise_floor_percent: float
    runs: list[SeedRun]
    bounds: np.ndarray
    domain_source: str
    settings: IdentifySettings
    warnings: list[str] = field(default_factory=list)
    #: Parameters the recording pins down poorly, each with its uncertainty relative
    #: to its scale (see ``quality.poorly_determined``; ``inf``: not determined at all).
    poorly_determined: dict[str, float] = field(default_factory=dict)
    source: str = ''
    family: str = 'tk'
    initial: str = 'rising'
    hold: str = 'before'
    other_nfev: int = 0
    proper_alternative: Identification | None = field(default=None, repr=False)

    @property
    def proper(self) -> bool:
        """Whether the loop is proper: False for one only the paper's wider set admits.

        Such a loop's corners are out of a proper loop's order
        (:mod:`hyst_id.identification.loose_phase`); other families are always proper.
        """
        if self.family != 'tk':
            return True
        return bool(loop_is_proper(*(float(self.params[n]) for n in self.names[:8])))

    @property
    def nfev(self) -> int:
        """Every evaluation made: the runs' and the global phase's that did not improve."""
        return int(sum(r.nfev for r in self.runs)) + int(self.other_nfev)

    @property
    def x(self) -> np.ndarray:
        """Best canonical parameter vector."""
        return np.array([self.params[n] for n in self.names])

    def spec(self) -> ChainSpec:
        """Chain spec that simulates the canonical parameters (calibration sign, 0)."""
        return replace(chain_spec(self.channel, calibration=(self.output_sign, 0.0),
                                  family=self.family, initial=self.initial),
                       hold=self.hold, proper=self.proper).with_bounds(
            self.bounds, source=self.domain_source)

    def to_dict(self) -> dict:
        """JSON-ready summary (arrays as lists)."""
        runs = []
        for r in self.runs:
            runs.append({'seed': r.seed, 'params': dict(zip(self.names, r.x.tolist())),
                         'er_percent': r.er_percent, 'er_gaass_percent': r.er_gaass_percent,
                         'nfev': r.nfev, 'nit': r.nit, 'message': r.message})
        return {
            'channel': self.channel, 'family': self.family, 'source': self.source,
            'initial_state': self.initial, 'sensor_hold': self.hold,
            'proper_loop': self.proper,
            'params': self.params, 'params_mean': self.params_mean,
            'output_sign': self.output_sign,
            'calibration': {'k': self.output_sign, 'b': 0.0,
                            'note': 'canonical gauge: H output in measurement units '
                            '(negated when output_sign is -1), backlash unit slope '
                            'centred on 0'},
            'er_percent': self.er_percent, 'nfev': self.nfev,
            'er_mean_params_percent': self.er_mean_params_percent,
            'er_seeds_percent': [r.er_percent for r in self.runs],
            'noise_floor_percent': self.noise_floor_percent,
            'domains': {n: list(map(float, b)) for n, b in zip(self.names, self.bounds)},
            'domain_source': self.domain_source,
            'settings': {k: (list(v) if isinstance(v, tuple) else v)
                         for k, v in asdict(self.settings).items()},
            'warnings': list(self.warnings),
            'poorly_determined': {k: (v if np.isfinite(v) else None)
                                  for k, v in self.poorly_determined.items()},
            'runs': runs,
            'proper_alternative': None if self.proper_alternative is None else {
                'params': self.proper_alternative.params,
                'output_sign': self.proper_alternative.output_sign,
                'er_percent': self.proper_alternative.er_percent},
        }
