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

"""What the paper's experiment is asked to do and what it returns (value objects).

The settings (:class:`ExperimentConfig`), the per-channel calibration, and the
results per channel, scenario (supply regulation off / on) and run, with their
JSON form (:func:`result_to_dict`). Computation is in
:mod:`hyst_id.experiment.run`, tables and figures in
:mod:`hyst_id.experiment.report`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from hyst_id.errors import ConfigError
from hyst_id.identification import Identification, IdentifySettings
from hyst_id.identification.chains import CHAIN_NAMES
from hyst_id.identification.gauge import canonical_gauge
from hyst_id.rig import RigParams, RigRun

__all__ = ['CHANNELS', 'CLEAN_SERIES', 'MODES', 'eps_c_percent', 'ExperimentConfig',
           'Calibration', 'ChannelResult',
           'ScenarioResult', 'ExperimentResult', 'result_to_dict', 'supply_drop_percent']


CHANNELS = ('position', 'pressure', 'flow')
#: ``gaass``: GAASS only (the paper's procedure); ``refined``: GAASS + refinement.
MODES = ('refined', 'gaass')
#: Truth series of each channel's noise-free reading.
CLEAN_SERIES = {'position': 'position_clean', 'pressure': 'pressure_clean_pa',
                'flow': 'flow_clean_g_s'}


def eps_c_percent(w_c: np.ndarray, w_ud: np.ndarray, offset: float = 0.0) -> float:
    """Average percentage control error, Eq. 26, of signals measured from ``offset``.

    ``offset`` is the reading at zero position (a calibration's ``b``): the
    error is then relative to the position-equivalent signal (``k`` cancels).
    """
    w_c, w_ud = np.asarray(w_c, dtype=float), np.asarray(w_ud, dtype=float)
    return float(np.sqrt(np.sum((w_c - w_ud) ** 2) / np.sum((w_ud - offset) ** 2)) * 100.0)


@dataclass(frozen=True)
class ExperimentConfig:
    """Runs of the experiment (the paper gives only the compensation run's timing).

    Attributes
    ----------
    ident_duration_s, ident_dt_s :
        Identification run (Eq. 24): ten periods of its 10 s sine at 20 Hz.
    comp_duration_s, comp_dt_s :
        Compensation runs (Eq. 25): the paper's 60 s at 0.5 s.
    ident_noise_seed, comp_noise_seed :
        Sensor-noise seeds of the rig (GAASS seeds are in the settings).
    command_limits_ma :
        Range of the compensated command (a 4-20 mA positioner).
    compensate_with :
        ``'best'``: the best seed's parameters (lowest J); ``'mean'``: the
        parameters averaged over seeds (the paper's Table 1; falls back to the
        best run if the average violates a constraint). Averaging is unsafe
        when seeds end in different basins of the near-degenerate landscape
        (docs/RESULTS.md), hence the default.
    """

    ident_duration_s: float = 100.0
    ident_dt_s: float = 0.05
    comp_duration_s: float = 60.0
    comp_dt_s: float = 0.5
    ident_noise_seed: int = 0
    comp_noise_seed: int = 1
    command_limits_ma: tuple[float, float] = (4.0, 20.0)
    compensate_with: str = 'best'

    def __post_init__(self) -> None:
        if self.compensate_with not in ('mean', 'best'):
            raise ConfigError(f"compensate_with must be 'mean' or 'best', "
                              f'got {self.compensate_with!r}')
        for name in ('ident_duration_s', 'ident_dt_s', 'comp_duration_s', 'comp_dt_s'):
            if not getattr(self, name) > 0:
                raise ConfigError(f'{name} must be positive')


@dataclass(frozen=True)
class Calibration:
    """``reading = k F(position) + b``: position units (mA-eq) into a channel's units.

    ``F`` is the fitted lag (``dynamics``; empty for position, where
    ``k = 1, b = 0`` by definition). Position-equivalent of a reading:
    ``(reading - b) / k``.
    """

    channel: str
    k: float
    b: float
    dynamics: dict = field(default_factory=dict)
    rms_residual: float = 0.0
    #: ``(centre, scale, (c_2, c_3, ...))``: a static curve ``sum_i c_i z^i`` added,
    #: ``z = (position - centre) / scale``; empty: a straight line
    curve: tuple = ()

    def to_position(self, reading: np.ndarray) -> np.ndarray:
        """Readings in position-equivalent units (of the straight part ``k``, ``b``)."""
        return (np.asarray(reading, dtype=float) - self.b) / self.k

    def from_position(self, position: np.ndarray) -> np.ndarray:
        """Static channel value for positions (the desired trajectory of a channel)."""
        p = np.asarray(position, dtype=float)
        out = self.k * p + self.b
        if self.curve:
            centre, scale, coefs = self.curve
            z = (p - centre) / scale
            out = out + sum(c * z ** (i + 2) for i, c in enumerate(coefs))
        return out


@dataclass
class ChannelResult:
    """Identification and compensation from one sensor in one mode."""

    channel: str
    mode: str
    ident: Identification
    used: str                      # 'mean' or 'best': the set given to the compensator
    x_used: np.ndarray             # canonical, channel units
    x_position: np.ndarray         # the same set in position units (canonical gauge)
    x_position_seeds: np.ndarray   # every seed in position units, one row each
    er: dict                       # %e_r: {raw,cal}_{best,seeds_mean,mean_params,noise_floor}
    desired: np.ndarray            # desired channel value (channel units)
    command_ma: np.ndarray         # compensated command
    run: RigRun                    # the compensated run
    eps_c_raw_percent: float
    eps_c_percent: float           # position-equivalent
    position_rms_error: float      # measured position vs u_d, mA-eq
    top_line_reached: bool         # the identified top line met inside the identification
    #                                range by more than 1 % of its span
    eps_c_other_supply_percent: float = float('nan')  # same command, other supply setting
    #: Issue 17's columns (b) augmented and (c) tracking
    #: (:class:`hyst_id.experiment.columns.AdaptiveColumns`), when run.
    adaptive: Any = None


@dataclass
class ScenarioResult:
    """Everything for one supply setting."""

    regulation: bool
    ident_run: RigRun
    calibrations: dict
    reference: RigRun
    uncompensated: RigRun
    eps_unc_raw_percent: dict
    eps_unc_percent: dict
    position_rms_error_unc: float
    channels: dict = field(default_factory=dict)   # (mode, channel) -> ChannelResult

    @property
    def name(self) -> str:
        """``'regulation on'`` or ``'regulation off'``."""
        return 'regulation on' if self.regulation else 'regulation off'


@dataclass
class ExperimentResult:
    """The whole experiment; :meth:`to_dict` is JSON-ready."""

    params_source: str
    rig: RigParams
    config: ExperimentConfig
    settings: IdentifySettings
    modes: tuple[str, ...]
    scenarios: dict                # 'off' / 'on' -> ScenarioResult
    timings_s: dict

    @property
    def true_x(self) -> np.ndarray:
        """The rig's true H and B (the paper's H), position units."""
        return np.r_[self.rig.actuator.hysteresis, self.rig.actuator.backlash]

    def to_dict(self) -> dict:
        """JSON-ready summary: settings, per-scenario metrics, parameters, series."""
        return result_to_dict(self)


def result_to_dict(result: ExperimentResult) -> dict:
    """JSON-ready summary (:meth:`ExperimentResult.to_dict`): metrics, parameters, series."""
    names = CHAIN_NAMES['position']
    out = {'params_source': result.params_source, 'config': asdict(result.config),
           'settings': {k: (list(v) if isinstance(v, tuple) else v)
                        for k, v in asdict(result.settings).items()},
           'modes': list(result.modes), 'timings_s': dict(result.timings_s),
           'true': dict(zip(names, result.true_x.tolist())),
           'true_canonical': dict(zip(names, canonical_gauge(result.true_x).tolist())),
           'scenarios': {}}
    for key, sc in result.scenarios.items():
        d = {'regulation': sc.regulation,
             'calibrations': {ch: asdict(c) for ch, c in sc.calibrations.items()},
             'eps_c_uncompensated_raw_percent': sc.eps_unc_raw_percent,
             'eps_c_uncompensated_percent': sc.eps_unc_percent,
             'supply_drop_percent': supply_drop_percent(sc),
             'supply_drop_ident_percent': supply_drop_percent(sc, sc.ident_run),
             'position_rms_error_uncompensated': sc.position_rms_error_unc,
             'compensation_t_s': sc.reference.t_s.tolist(),
             'u_d_ma': sc.uncompensated.command_ma.tolist(),
             'w_ud': {ch: sc.reference.truth[CLEAN_SERIES[ch]].tolist() for ch in CHANNELS},
             'w_uncompensated': {ch: sc.uncompensated.measurement(ch).tolist()
                                 for ch in CHANNELS},
             'results': {}}
        for (mode, ch), r in sc.channels.items():
            d['results'].setdefault(mode, {})[ch] = {
                'identification': r.ident.to_dict(), 'compensated_with': r.used,
                'params_position_units': dict(zip(names, r.x_position[:11].tolist())),
                'params_position_units_seed_std': dict(zip(
                    names, r.x_position_seeds[:, :11].std(axis=0).tolist())),
                'er': r.er, 'eps_c_raw_percent': r.eps_c_raw_percent,
                'eps_c_percent': r.eps_c_percent, 'top_line_reached': r.top_line_reached,
                'position_rms_error': r.position_rms_error,
                'eps_c_other_supply_percent': r.eps_c_other_supply_percent,
                'desired': r.desired.tolist(), 'command_ma': r.command_ma.tolist(),
                'w_c': r.run.measurement(ch).tolist(),
                'adaptive': None if r.adaptive is None else r.adaptive.to_dict()}
        out['scenarios'][key] = d
    return out


def supply_drop_percent(sc: ScenarioResult, run: RigRun | None = None) -> float:
    """Drop of the supply pressure over a run (default the uncompensated one), percent."""
    p = (run or sc.uncompensated).truth['supply_pressure_pa']
    return float((p[0] - p[-1]) / p[0] * 100.0)
