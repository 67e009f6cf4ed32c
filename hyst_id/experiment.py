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

"""The paper's section 4 experiment on the simulated rig (issue 4).

``run_experiment(params_path)`` does, per supply setting (regulation off as in
the paper, and/or on):

1. one identification run: Eq. 24 for ``ident_duration_s`` at ``ident_dt_s``,
   all three sensors recorded at once;
2. a *position calibration* of the pressure and flow readings from that run
   alone (:func:`fit_position_calibration`): ``reading = k F(position) + b``
   with ``F`` a first-order (pressure) or second-order (flow) lag fitted with
   it; the position sensor reads position units (mA-eq) directly;
3. identification from each sensor (:func:`hyst_id.identify.identify`, the
   paper's domains), GAASS only and/or GAASS + refinement;
4. compensation with Eq. 25 (``comp_duration_s`` at ``comp_dt_s``): the
   desired value of a channel is ``k u_d + b`` (its calibration applied to
   ``u_d``, a desired position in mA-eq), inverted by the H⁻¹ (and B⁻¹)
   identified from that channel; plus one uncompensated run (``u_d`` sent
   straight to the actuator) and one *reference* run: the same rig with an
   ideal (hysteresis- and backlash-free) actuator and regulated supply, whose
   noise-free readings are ``w_{u_d}`` of Eq. 26.

No simulator truth enters identification, calibration or compensation; the
truth is only used for the reference output and the true-vs-identified table.
Tables and figures are in :mod:`hyst_id.experiment_report`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import os
import time
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import least_squares

from hyst_id.compensate import CommandLimits, Compensator, InverseModel
from hyst_id.domains import preset_spec
from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.excitation import eq24, eq25
from hyst_id.gauge import affine_map_output
from hyst_id.identify import Identification, identify, IdentifySettings
from hyst_id.models.hysteresis import loop_corners
from hyst_id.models.sensors import simulate_first_order, simulate_second_order
from hyst_id.rig import as_rig_params, RigParams, RigRun, simulate_rig

__all__ = ['CHANNELS', 'MODES', 'ExperimentConfig', 'Calibration', 'ChannelResult',
           'ScenarioResult', 'ExperimentResult', 'run_experiment', 'fit_position_calibration',
           'to_position_units', 'to_backlash_gauge', 'eps_c_percent', 'ideal_actuator_params']

CHANNELS = ('position', 'pressure', 'flow')
#: ``gaass``: GAASS only (the paper's procedure); ``refined``: GAASS + refinement.
MODES = ('refined', 'gaass')
_CLEAN = {'position': 'position_clean', 'pressure': 'pressure_clean_pa',
          'flow': 'flow_clean_g_s'}


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

    def to_position(self, reading: np.ndarray) -> np.ndarray:
        """Readings in position-equivalent units."""
        return (np.asarray(reading, dtype=float) - self.b) / self.k

    def from_position(self, position: np.ndarray) -> np.ndarray:
        """Static channel value for positions (the desired trajectory of a channel)."""
        return self.k * np.asarray(position, dtype=float) + self.b


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
    top_line_reached: bool
    eps_c_other_supply_percent: float = float('nan')  # same command, other supply setting


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
        from hyst_id.experiment_report import result_to_dict

        return result_to_dict(self)


def eps_c_percent(w_c: np.ndarray, w_ud: np.ndarray, offset: float = 0.0) -> float:
    """Average percentage control error, Eq. 26, of signals measured from ``offset``.

    ``offset`` is the reading at zero position (a calibration's ``b``): the
    error is then relative to the position-equivalent signal (``k`` cancels).
    """
    w_c, w_ud = np.asarray(w_c, dtype=float), np.asarray(w_ud, dtype=float)
    return float(np.sqrt(np.sum((w_c - w_ud) ** 2) / np.sum((w_ud - offset) ** 2)) * 100.0)


def _lag(channel: str, theta: np.ndarray, position: np.ndarray, t_s: np.ndarray) -> np.ndarray:
    if channel == 'pressure':
        return simulate_first_order(position, t_s, theta[0])
    return simulate_second_order(position, t_s, theta[0], theta[1])


def fit_position_calibration(channel: str, t_s: np.ndarray, position: np.ndarray,
                             reading: np.ndarray) -> Calibration:
    """Fit ``reading = k F(position) + b`` on a run where both were recorded.

    ``F`` is ``1/(tau s + 1)`` for pressure and ``w^2/(s^2 + 2 zeta w s + w^2)``
    for flow (the sensor models of Eq. 8-9, here describing the whole
    position-to-reading path); ``k, b`` are linear least squares for every
    ``F`` (variable projection), ``F``'s parameters bounded least squares
    from a few starts. Only measured data are used.

    Parameters
    ----------
    channel : str
        ``position``, ``pressure`` or ``flow``.
    t_s, position, reading : numpy.ndarray
        Sample times, position readings (mA-eq) and the channel's readings.

    Returns
    -------
    Calibration
    """
    if channel == 'position':
        return Calibration('position', 1.0, 0.0)
    if channel not in CHANNELS:
        raise ConfigError(f'unknown channel {channel!r}')
    t = np.asarray(t_s, dtype=float)
    pos = np.asarray(position, dtype=float)
    y = np.asarray(reading, dtype=float)
    ones = np.ones_like(y)

    def solve(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        a = np.column_stack([_lag(channel, theta, pos, t), ones])
        kb = np.linalg.lstsq(a, y, rcond=None)[0]
        return kb, y - a @ kb

    if channel == 'pressure':
        starts, bounds = [[0.3], [1.0], [3.0]], ([0.0], [20.0])
    else:
        starts = [[0.3, 0.5], [0.7, 1.5], [0.5, 5.0]]
        bounds = ([0.0, 0.01], [0.99, 10.0])
    best = None
    for x0 in starts:
        sol = least_squares(lambda th: solve(th)[1], x0, bounds=bounds, method='trf')
        if best is None or sol.cost < best.cost:
            best = sol
    (k, b), res = solve(best.x)
    names = ('tau_s',) if channel == 'pressure' else ('zeta', 'omega_n')
    return Calibration(channel, float(k), float(b),
                       {n: float(v) for n, v in zip(names, best.x)},
                       float(np.sqrt(np.mean(res ** 2))))


def to_position_units(x: np.ndarray, output_sign: float, cal: Calibration) -> np.ndarray:
    """Re-express canonical chain parameters with H's output in position units.

    The canonical chain predicts ``reading = output_sign * s``; with
    ``reading = k position + b`` the position is ``(output_sign/k) s - b/k``,
    an affine map of the chain output (:func:`hyst_id.gauge.affine_map_output`).
    """
    alpha = output_sign / cal.k
    if not alpha > 0:
        raise InvalidParametersError(f'{cal.channel}: calibration gain sign ({cal.k:+.3g}) '
                                     'disagrees with the identified output sign')
    return affine_map_output(x, alpha, -cal.b / cal.k)


def to_backlash_gauge(x: np.ndarray, m_bl: float, centre: float) -> np.ndarray:
    """Canonical parameters re-expressed with backlash slope ``m_bl`` centred on ``centre``.

    The inverse of :func:`hyst_id.gauge.canonical_gauge` for a chosen gauge: the
    chain output is unchanged. With the rig's ``m_bl`` and ``(c_bl + c_br)/2``
    it puts identified sets in the gauge the paper's Table 1 is printed in.
    """
    p = np.array(x, dtype=np.float64)
    shift = m_bl * centre
    p[6] += shift
    p[7] += shift
    p[4] -= shift / p[0]
    p[5] -= shift / p[1]
    p[9] += shift
    p[10] += shift
    p[[0, 1, 2, 3, 6, 7]] /= m_bl
    p[8], p[9], p[10] = m_bl, p[9] / m_bl, p[10] / m_bl
    return p


def ideal_actuator_params(params: RigParams) -> RigParams:
    """The rig with a hysteresis- and backlash-free actuator and regulated supply.

    Position follows the command (mA to mA-eq) to within 1e-8: a loop of
    width 2e-9 mA (constraints need ``c_l < c_r``) whose top and bottom lines
    are far outside any command, and a 2e-9 backlash.
    """
    w = 1e-9
    return params.with_values({
        'actuator.m_l': 1.0, 'actuator.m_r': 1.0, 'actuator.m_t': 0.5, 'actuator.m_b': 0.5,
        'actuator.c_l': -w, 'actuator.c_r': w, 'actuator.c_t': 100.0, 'actuator.c_b': -100.0,
        'actuator.m_bl': 1.0, 'actuator.c_bl': -w, 'actuator.c_br': w,
        'supply.regulation': True})


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def _er_variants(ident: Identification, y: np.ndarray, cal: Calibration) -> dict:
    """%e_r (Eq. 7) raw and position-equivalent: best, seeds' mean, averaged parameters."""
    ss_raw = float(np.sum(y ** 2))
    ss_cal = float(np.sum((y - cal.b) ** 2))
    funs = np.array([r.fun for r in ident.runs])
    j_mean = (ident.er_mean_params_percent / 100.0) ** 2 * ss_raw
    out = {}
    for tag, ss in (('raw', ss_raw), ('cal', ss_cal)):
        out[f'{tag}_best'] = float(np.sqrt(funs.min() / ss) * 100.0)
        out[f'{tag}_seeds_mean'] = float(np.mean(np.sqrt(funs / ss)) * 100.0)
        out[f'{tag}_mean_params'] = float(np.sqrt(j_mean / ss) * 100.0)
        out[f'{tag}_noise_floor'] = float(ident.noise_floor_percent * np.sqrt(ss_raw / ss))
    return out


def _model_for_compensation(ident: Identification, how: str) -> tuple[str, np.ndarray]:
    if how == 'mean':
        x = np.array([ident.params_mean[n] for n in ident.names])
        try:
            InverseModel.from_vector(x, ident.output_sign)
            return 'mean', x
        except InvalidParametersError:
            pass
    return 'best', ident.x


def _channel_result(sc: ScenarioResult, mode: str, ident: Identification, rig: RigParams,
                    config: ExperimentConfig, u_d: np.ndarray) -> ChannelResult:
    ch = ident.channel
    cal = sc.calibrations[ch]
    y = sc.ident_run.measurement(ch)
    used, x = _model_for_compensation(ident, config.compensate_with)
    desired = cal.from_position(u_d)
    lo, hi = config.command_limits_ma
    comp = Compensator(InverseModel.from_vector(x, ident.output_sign),
                       CommandLimits(lo, hi), v0=lo)
    command = comp.run(desired)
    run = simulate_rig(rig, sc.reference.t_s, command, seed=config.comp_noise_seed)
    w_ud = sc.reference.truth[_CLEAN[ch]]
    w_c = run.measurement(ch)
    other = simulate_rig(rig.with_values({'supply.regulation': not sc.regulation}),
                         sc.reference.t_s, command, seed=config.comp_noise_seed)
    x_pos = to_position_units(x, ident.output_sign, cal)
    seeds = np.array([to_position_units(r.x, r.sign, cal) for r in ident.runs
                      if r.sign == ident.output_sign])
    v_max = float(np.max(sc.ident_run.command_ma))
    return ChannelResult(
        channel=ch, mode=mode, ident=ident, used=used, x_used=x, x_position=x_pos,
        x_position_seeds=seeds, er=_er_variants(ident, y, cal), desired=desired,
        command_ma=command, run=run, eps_c_raw_percent=eps_c_percent(w_c, w_ud),
        eps_c_percent=eps_c_percent(w_c, w_ud, cal.b),
        position_rms_error=_rms(run.position - u_d),
        eps_c_other_supply_percent=eps_c_percent(other.measurement(ch), w_ud, cal.b),
        top_line_reached=bool(v_max >= loop_corners(x_pos[:8])['C'][0]))


def _settings_for(settings: IdentifySettings, mode: str) -> IdentifySettings:
    return replace(settings, refine=(mode == 'refined'))


def run_experiment(params_path=None, *, settings: IdentifySettings | None = None,
                   seeds: int | Sequence[int] | None = None,
                   regulation: Sequence[bool] = (False,), modes: Sequence[str] = MODES,
                   channels: Sequence[str] = CHANNELS, config: ExperimentConfig | None = None,
                   progress: Callable[[int, int, str], None] | None = None
                   ) -> ExperimentResult:
    """Reproduce section 4: identification from three sensors, Table 1, compensation.

    Parameters
    ----------
    params_path : str, path, RigParams, mapping or None
        Rig parameters (``params/paper_rig.yaml`` for the paper's rig).
    settings : IdentifySettings, optional
        GAASS settings (default: the paper's); ``refine`` is set per mode.
    seeds : int or sequence of int, optional
        GAASS seeds (an int ``n`` means ``0 .. n-1``); default ``settings.seeds``.
    regulation : sequence of bool
        Supply settings to run (``False``: blow-down, the paper's rig).
    modes : sequence of str
        ``'refined'`` (GAASS + refinement) and/or ``'gaass'`` (GAASS only).
    channels : sequence of str
        Sensors to identify from.
    config : ExperimentConfig, optional
        Run lengths, sampling, noise seeds, command limits.
    progress : callable, optional
        ``progress(advance, total, message)`` after every GAASS seed.

    Returns
    -------
    ExperimentResult
    """
    settings = settings or IdentifySettings()
    if seeds is not None:
        seeds = tuple(range(seeds)) if isinstance(seeds, int) else tuple(int(s) for s in seeds)
        settings = replace(settings, seeds=seeds)
    config = config or ExperimentConfig()
    bad = [m for m in modes if m not in MODES] + [c for c in channels if c not in CHANNELS]
    if bad or not modes or not channels or not regulation:
        raise ConfigError(f'need modes from {MODES} and channels from {CHANNELS}; got {bad}')
    base = as_rig_params(params_path)
    source = (str(params_path) if isinstance(params_path, (str, os.PathLike))
              else 'defaults' if params_path is None else type(params_path).__name__)
    total = len(regulation) * len(modes) * len(channels) * len(settings.seeds)
    timings: dict[str, float] = {}
    t_start = time.perf_counter()
    t_id = np.arange(0.0, config.ident_duration_s, config.ident_dt_s)
    n_comp = int(round(config.comp_duration_s / config.comp_dt_s)) + 1
    t_comp = np.arange(n_comp) * config.comp_dt_s
    u_d = eq25(t_comp)
    scenarios: dict = {}
    cache: dict = {}   # identical recordings (position does not see the supply) run once
    for reg in regulation:
        key = 'on' if reg else 'off'
        rig = base.with_values({'supply.regulation': bool(reg)})
        ident_run = simulate_rig(rig, t_id, eq24(t_id), seed=config.ident_noise_seed)
        cals = {ch: fit_position_calibration(ch, t_id, ident_run.position,
                                             ident_run.measurement(ch)) for ch in channels}
        reference = simulate_rig(ideal_actuator_params(rig), t_comp, u_d, seed=None)
        unc = simulate_rig(rig, t_comp, u_d, seed=config.comp_noise_seed)
        w = {ch: (unc.measurement(ch), reference.truth[_CLEAN[ch]]) for ch in channels}
        sc = ScenarioResult(
            regulation=bool(reg), ident_run=ident_run, calibrations=cals, reference=reference,
            uncompensated=unc,
            eps_unc_raw_percent={ch: eps_c_percent(*w[ch]) for ch in channels},
            eps_unc_percent={ch: eps_c_percent(*w[ch], cals[ch].b) for ch in channels},
            position_rms_error_unc=_rms(unc.position - u_d))
        for mode in modes:
            for ch in channels:
                t0 = time.perf_counter()
                label = f'{key} {mode} {ch}'

                def report(done, n, run, label=label):
                    if progress:
                        progress(1, total, f'{label}: seed {run.seed} %e_r '
                                 f'{run.er_percent:.3g}')

                rec = ident_run.recording(ch)
                digest = (mode, ch, rec.t_s.tobytes(), rec.command.tobytes(),
                          rec.measurement.tobytes())
                if digest not in cache:
                    cache[digest] = identify(rec, spec=preset_spec('paper', ch),
                                             settings=_settings_for(settings, mode),
                                             progress=report)
                elif progress:
                    progress(len(settings.seeds), total, f'{label}: same recording, reused')
                ident = cache[digest]
                sc.channels[(mode, ch)] = _channel_result(sc, mode, ident, rig, config, u_d)
                timings[label] = time.perf_counter() - t0
        scenarios[key] = sc
    timings['total'] = time.perf_counter() - t_start
    return ExperimentResult(params_source=source, rig=base, config=config, settings=settings,
                            modes=tuple(modes), scenarios=scenarios, timings_s=timings)
