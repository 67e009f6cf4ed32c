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
3. identification from each sensor (:func:`hyst_id.identification.identify`, the
   paper's domains), GAASS only and/or GAASS + refinement;
4. compensation with Eq. 25 (``comp_duration_s`` at ``comp_dt_s``): the
   desired value of a channel is ``k u_d + b`` (its calibration applied to
   ``u_d``, a desired position in mA-eq), inverted by the H⁻¹ (and B⁻¹)
   identified from that channel; plus one uncompensated run (``u_d`` sent
   straight to the actuator) and one *reference* run: the same rig with an
   ideal (hysteresis- and backlash-free) actuator and regulated supply, whose
   noise-free readings are ``w_{u_d}`` of Eq. 26.

With ``adaptive=True`` each channel also gets issue 17's columns (b) the
model augmented with what a diagnosis of the identification run found and
(c) adaptive tracking (:mod:`hyst_id.experiment.columns`).

No simulator truth enters identification, calibration or compensation; the
truth is only used for the reference output and the true-vs-identified table.
Tables and figures are in :mod:`hyst_id.experiment.report`.
"""

from __future__ import annotations

from dataclasses import replace
import os
import time
from typing import Any, Callable, Sequence

import numpy as np
from scipy.optimize import least_squares

from hyst_id.compensation import CommandLimits, Compensator, InverseModel
from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.experiment.result import (
    Calibration,
    ChannelResult,
    CHANNELS,
    CLEAN_SERIES,
    eps_c_percent,
    ExperimentConfig,
    ExperimentResult,
    MODES,
    ScenarioResult,
)
from hyst_id.identification import Identification, identify, IdentifySettings
from hyst_id.identification.domains import preset_spec
from hyst_id.identification.gauge import affine_map_output
from hyst_id.models.sensors import simulate_first_order, simulate_second_order
from hyst_id.models.tk import loop_corners
from hyst_id.rig import as_rig_params, RigParams, simulate_rig
from hyst_id.signals.excitation import eq24, eq25

__all__ = ['run_experiment', 'calibration_by_bic', 'calibration_lag', 'fit_position_calibration',
           'to_position_units', 'to_backlash_gauge', 'eps_c_percent', 'ideal_actuator_params']


def _lag(channel: str, theta: np.ndarray, position: np.ndarray, t_s: np.ndarray) -> np.ndarray:
    if channel == 'pressure':
        return simulate_first_order(position, t_s, theta[0])
    return simulate_second_order(position, t_s, theta[0], theta[1])


def fit_position_calibration(channel: str, t_s: np.ndarray, position: np.ndarray,
                             reading: np.ndarray, gain_law: str = 'none',
                             curve_degree: int = 1) -> Calibration:
    """Fit ``reading = k F(position) + b`` on a run where both were recorded.

    ``F`` is ``1/(tau s + 1)`` for pressure and ``w^2/(s^2 + 2 zeta w s + w^2)``
    for flow (the sensor models of Eq. 8-9, here describing the whole
    position-to-reading path); ``k, b`` are linear least squares for every
    ``F`` (variable projection), ``F``'s parameters bounded least squares
    from a few starts. Only measured data are used.

    With ``gain_law`` ``'exponential'`` or ``'linear'`` (a diagnosed
    ``supply_decay`` or ``gain_drift``) the fit is ``reading = g(t) (k F + b0)
    + b1`` with ``g = exp(-rate t)`` or ``1 + rate t`` from the run's start,
    and the calibration returned holds at the start: ``k, b = b0 + b1``, the
    rate in ``dynamics['gain_rate_per_s']``. With ``'offset'`` (a diagnosed
    ``offset_drift``) it is ``reading = k F + b + rate t``, linear in the rate.
    ``curve_degree`` > 1 adds ``sum_i c_i F(z^i)``, ``i = 2 .. degree``, ``z``
    the position centred and scaled on the run (a static curve of the
    position-to-reading path: an orifice's, a valve characteristic's), kept
    in ``Calibration.curve``.

    Parameters
    ----------
    channel : str
        ``position``, ``pressure`` or ``flow``.
    t_s, position, reading : numpy.ndarray
        Sample times, position readings (mA-eq) and the channel's readings.
    gain_law : {'none', 'exponential', 'linear', 'offset'}
        A gain (or an offset) changing over the run.
    curve_degree : int
        Degree of the static curve (1: a straight line, the paper's).

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

    n_dyn = 1 if channel == 'pressure' else 2
    elapsed = t - t[0]
    centre, scale = float(np.mean(pos)), float(np.std(pos)) or 1.0
    powers = [pos] + [((pos - centre) / scale) ** i for i in range(2, int(curve_degree) + 1)]

    def solve(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        f = np.column_stack([_lag(channel, theta[:n_dyn], p, t) for p in powers])
        if gain_law == 'none':
            a = np.column_stack([f, ones])
        elif gain_law == 'offset':
            a = np.column_stack([f, ones, elapsed])
        else:
            r = theta[n_dyn]
            g = np.exp(-r * elapsed) if gain_law == 'exponential' else 1.0 + r * elapsed
            a = np.column_stack([g[:, None] * f, g, ones])
        kb = np.linalg.lstsq(a, y, rcond=None)[0]
        return kb, y - a @ kb

    if channel == 'pressure':
        starts, bounds = [[0.3], [1.0], [3.0]], ([0.0], [20.0])
    else:
        starts = [[0.3, 0.5], [0.7, 1.5], [0.5, 5.0]]
        bounds = ([0.0, 0.01], [0.99, 10.0])
    if gain_law not in ('none', 'exponential', 'linear', 'offset'):
        raise ConfigError(f'unknown gain law {gain_law!r}')
    if int(curve_degree) < 1:
        raise ConfigError(f'curve_degree must be >= 1, got {curve_degree!r}')
    if gain_law in ('exponential', 'linear'):
        # rates of -1 .. +1 per run length (linear: the gain stays above 0)
        span = max(float(elapsed[-1]), 1e-9)
        lo = -1.0 / span if gain_law == 'exponential' else -0.99 / span
        starts = [x0 + [0.0] for x0 in starts]
        bounds = (bounds[0] + [lo], bounds[1] + [1.0 / span])
    best = None
    for x0 in starts:
        sol = least_squares(lambda th: solve(th)[1], x0, bounds=bounds, method='trf')
        if best is None or sol.cost < best.cost:
            best = sol
    coef, res = solve(best.x)
    names = ('tau_s',) if channel == 'pressure' else ('zeta', 'omega_n')
    dynamics = {n: float(v) for n, v in zip(names, best.x)}
    m = len(powers)
    curve = (centre, scale, tuple(float(c) for c in coef[1:m])) if m > 1 else ()
    if gain_law == 'offset':
        k, b = float(coef[0]), float(coef[m])
        dynamics.update(gain_law=gain_law, offset_rate_per_s=float(coef[m + 1]))
    else:
        k, b = float(coef[0]), float(np.sum(coef[m:]))
    if gain_law in ('exponential', 'linear'):
        dynamics.update(gain_law=gain_law, gain_rate_per_s=float(best.x[n_dyn]))
    return Calibration(channel, k, b, dynamics, float(np.sqrt(np.mean(res ** 2))), curve)


def calibration_by_bic(channel: str, t_s: np.ndarray, position: np.ndarray,
                       reading: np.ndarray, gain_law: str = 'none',
                       max_degree: int = 3) -> Calibration:
    """:func:`fit_position_calibration` with the static curve's degree chosen by BIC.

    Degrees 1 .. ``max_degree``; ``n ln(mean squared residual) + p ln n``
    with ``p`` the curve's coefficients: a curve is kept only where the run
    shows it (on the paper's rig the pressure's orifice curve, not the flow's).
    """
    n = len(reading)
    fits = [fit_position_calibration(channel, t_s, position, reading, gain_law, d)
            for d in range(1, max_degree + 1)]
    bic = [n * np.log(max(c.rms_residual, 1e-300) ** 2) + d * np.log(n)
           for d, c in enumerate(fits, start=1)]
    return fits[int(np.argmin(bic))]


def to_position_units(x: np.ndarray, output_sign: float, cal: Calibration) -> np.ndarray:
    """Re-express canonical chain parameters with H's output in position units.

    The canonical chain predicts ``reading = output_sign * s``; with
    ``reading = k position + b`` the position is ``(output_sign/k) s - b/k``,
    an affine map of the chain output (:func:`hyst_id.identification.gauge.affine_map_output`).
    """
    alpha = output_sign / cal.k
    if not alpha > 0:
        raise InvalidParametersError(f'{cal.channel}: calibration gain sign ({cal.k:+.3g}) '
                                     'disagrees with the identified output sign')
    return affine_map_output(x, alpha, -cal.b / cal.k)


def to_backlash_gauge(x: np.ndarray, m_bl: float, centre: float) -> np.ndarray:
    """Canonical parameters re-expressed with backlash slope ``m_bl`` centred on ``centre``.

    The inverse of :func:`hyst_id.identification.gauge.canonical_gauge` for a chosen gauge: the
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
    w_ud = sc.reference.truth[CLEAN_SERIES[ch]]
    w_c = run.measurement(ch)
    other = simulate_rig(rig.with_values({'supply.regulation': not sc.regulation}),
                         sc.reference.t_s, command, seed=config.comp_noise_seed)
    x_pos = to_position_units(x, ident.output_sign, cal)
    seeds = np.array([to_position_units(r.x, r.sign, cal) for r in ident.runs
                      if r.sign == ident.output_sign])
    v_max = float(np.max(sc.ident_run.command_ma))
    # a top line met at the very last bit of the range changes no sample: 1 % of the span
    v_reach = v_max - 0.01 * float(np.ptp(sc.ident_run.command_ma))
    return ChannelResult(
        channel=ch, mode=mode, ident=ident, used=used, x_used=x, x_position=x_pos,
        x_position_seeds=seeds, er=_er_variants(ident, y, cal), desired=desired,
        command_ma=command, run=run, eps_c_raw_percent=eps_c_percent(w_c, w_ud),
        eps_c_percent=eps_c_percent(w_c, w_ud, cal.b),
        position_rms_error=_rms(run.position - u_d),
        eps_c_other_supply_percent=eps_c_percent(other.measurement(ch), w_ud, cal.b),
        top_line_reached=bool(v_reach >= loop_corners(x_pos[:8])['C'][0]))


def _adaptive(sc: ScenarioResult, rig: RigParams, config: ExperimentConfig,
              channels: Sequence[str], diagnose_settings: Any,
              progress: Callable[[int, int, str], None] | None, total: int, key: str,
              timings: dict) -> None:
    """Columns (b) and (c) for every channel result of a scenario."""
    from hyst_id.diagnosis import DiagnoseSettings
    from hyst_id.experiment.columns import adaptive_columns, diagnose_channel

    # the diagnosis's set feeds H^-1: proper loops only, as the identification's
    settings = replace(diagnose_settings or DiagnoseSettings(max_mechanisms=3),
                       loose_loops=False)
    lo, hi = config.command_limits_ma
    run = sc.ident_run
    for ch in channels:
        t0 = time.perf_counter()
        diag = diagnose_channel(run.recording(ch), settings)
        # a diagnosed drift in time: the position calibration with it, referred to the
        # run's start (the supply level the regulated reference holds)
        law = 'none'
        for f in diag.findings:
            corr = f.compensation.get('correction', {})
            if law == 'none' and 'augment.gain_law' in corr:
                law = corr['augment.gain_law']
            elif law == 'none' and 'augment.offset_rate_per_s' in corr:
                law = 'offset'
        cal = sc.calibrations[ch] if law == 'none' or ch == 'position' else \
            calibration_by_bic(ch, run.t_s, run.position, run.measurement(ch), law)
        desired = cal.from_position(sc.uncompensated.command_ma)
        for (mode, c), r in sc.channels.items():
            if c == ch:
                r.adaptive = adaptive_columns(
                    diag, r, rig, sc.reference.t_s, sc.reference.truth[CLEAN_SERIES[ch]],
                    sc.calibrations[ch].b, CommandLimits(lo, hi), config.comp_noise_seed,
                    desired_augmented=desired)
                r.adaptive.calibration = cal
                r.adaptive.floor_percent = (_desired_floor(sc, ch, sc.calibrations[ch]),
                                            _desired_floor(sc, ch, cal))
        timings[f'{key} adaptive {ch}'] = time.perf_counter() - t0
        if progress:
            progress(1, total, f'{key} {ch}: diagnosis {diag.verdict}, augmented and tracking')


def calibration_lag(cal: Calibration, x: np.ndarray, t_s: np.ndarray) -> np.ndarray:
    """``x`` (channel units) through the calibration's fitted lag (none for position)."""
    names = {'pressure': ('tau_s',), 'flow': ('zeta', 'omega_n')}.get(cal.channel)
    if names is None:
        return np.asarray(x, dtype=float)
    return _lag(cal.channel, np.array([cal.dynamics[n] for n in names]), x, t_s)


def _desired_floor(sc: ScenarioResult, ch: str, cal: Calibration) -> float:
    """%ε_c of a perfect compensator: the desired value through the calibration's lag."""
    w = calibration_lag(cal, cal.from_position(sc.uncompensated.command_ma), sc.reference.t_s)
    return eps_c_percent(w, sc.reference.truth[CLEAN_SERIES[ch]], sc.calibrations[ch].b)


def _settings_for(settings: IdentifySettings, mode: str) -> IdentifySettings:
    return replace(settings, refine=(mode == 'refined'))


def run_experiment(params_path=None, *, settings: IdentifySettings | None = None,
                   seeds: int | Sequence[int] | None = None,
                   regulation: Sequence[bool] = (False,), modes: Sequence[str] = MODES,
                   channels: Sequence[str] = CHANNELS, config: ExperimentConfig | None = None,
                   progress: Callable[[int, int, str], None] | None = None,
                   adaptive: bool = False, diagnose_settings: Any = None
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
        ``progress(advance, total, message)`` after every GAASS seed (and every
        channel's diagnosis with ``adaptive``).
    adaptive : bool
        Also run columns (b) augmented and (c) tracking (issue 17).
    diagnose_settings : DiagnoseSettings, optional
        For (b)'s diagnosis (default: ``DiagnoseSettings(max_mechanisms=3)``).

    Returns
    -------
    ExperimentResult
    """
    # the paper's procedure fits the whole run (no start-state retry)
    settings = replace(settings or IdentifySettings(), start_state=False, loose_loops=False)
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
    total = len(regulation) * (len(modes) * len(settings.seeds) + int(adaptive)) * len(channels)
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
        w = {ch: (unc.measurement(ch), reference.truth[CLEAN_SERIES[ch]]) for ch in channels}
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
        if adaptive:
            _adaptive(sc, rig, config, channels, diagnose_settings, progress, total, key,
                      timings)
        scenarios[key] = sc
    timings['total'] = time.perf_counter() - t_start
    return ExperimentResult(params_source=source, rig=base, config=config, settings=settings,
                            modes=tuple(modes), scenarios=scenarios, timings_s=timings)
