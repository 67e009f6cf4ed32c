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

"""Simulator against recording: which of the rig simulator's effects the recording shows.

``diagnose_sim(recording, rig_params)`` drives the rig simulator
(:mod:`hyst_id.rig`) with the recording's own command and time stamps and
compares its noise-free output with the measurement; nothing is fitted
first, the simulator as configured is the baseline. The residual is located
as in :func:`hyst_id.diagnosis.diagnose`; then every mechanism of the library
that the simulator can switch on for that channel is switched on and its
parameters fitted on the training part by re-simulation (a coarse grid,
then a bounded scalar search or Nelder-Mead). The same criteria decide
(:mod:`hyst_id.diagnosis.select`), a second effect is tried if structure is
left, and the simulator parameters with the found effects switched on are
returned, ready for :func:`hyst_id.rig.save_rig_params`.

==========================  ====================================================
mechanism                   simulator setting fitted
==========================  ====================================================
``dead_time``               ``effects.dead_time.delay_s``
``sensor_lag``              ``effects.sensor_lag.<channel>_tau_s`` (others kept)
``supply_decay``            ``supply.regulation: false``, ``supply.vessel_volume_m3``
``offset_drift``            ``effects.offset_drift.<channel rate>``
``saturation``              ``effects.end_stops.min_position / max_position``
``stiction``                ``effects.stick_slip.static_band / dynamic_band``
``static_nonlinearity``     ``effects.valve_characteristic`` (kind and its parameter)
``rate_dependence``         ``effects.rate_hysteresis.width_per_rate_s / filter_tau_s``
==========================  ====================================================

The valve characteristic and the supply act on pressure and flow only, so
they are not tested on a position recording.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import minimize, minimize_scalar
from threadpoolctl import threadpool_limits

from hyst_id.diagnosis.driver import located_where
from hyst_id.diagnosis.locate import Localization, locate, noise_std
from hyst_id.diagnosis.mechanisms import MECHANISMS, Quantity
from hyst_id.diagnosis.result import DiagnoseSettings, Diagnosis, Finding
from hyst_id.diagnosis.select import compare, Comparison, Data, FitResult, round_record
from hyst_id.diagnosis.split_notes import range_note, require_split
from hyst_id.diagnosis.stick_events import bands_from_demand
from hyst_id.diagnosis.ties import alternatives_record, choose, close_calls
from hyst_id.errors import ConfigError, HystIdError
from hyst_id.identification.chains import er_percent
from hyst_id.io.recording import Recording, roundoff_probe, validate_recording
from hyst_id.signals.noise import floor_percent
from hyst_id.signals.reversals import reversal_times
from hyst_id.signals.split import inside_rows, split_index

__all__ = ['SIM_EFFECTS', 'diagnose_sim', 'simulate_clean']

_CLEAN = {'position': 'position_clean', 'pressure': 'pressure_clean_pa', 'flow': 'flow_clean_g_s'}
_DRIFT = {'position': 'position_per_s', 'pressure': 'pressure_pa_per_s',
          'flow': 'flow_g_s_per_s'}


@dataclass(frozen=True)
class _Param:
    name: str
    unit: str
    lo: float
    hi: float
    log: bool = False


def simulate_clean(params, t_s: np.ndarray, command: np.ndarray, channel: str) -> np.ndarray:
    """Noise-free reading of ``channel`` (drift and lag included) for a command."""
    from hyst_id.rig import simulate_rig
    run = simulate_rig(params, t_s, command, seed=0)
    return np.asarray(run.truth[_CLEAN[channel]], dtype=float)


def _space(mech_id: str, params, channel: str, truth: dict, t: np.ndarray, period: float
           ) -> tuple[dict, list[_Param]] | None:
    """Fixed settings and searched parameters of one mechanism (None: not applicable)."""
    pos = truth['position_true']
    lo, hi = float(np.min(pos)), float(np.max(pos))
    w = max(hi - lo, 1e-9)
    if mech_id == 'dead_time':
        return ({'effects.dead_time.enabled': True},
                [_Param('effects.dead_time.delay_s', 's', 0.0, min(0.25 * period, 2.0))])
    if mech_id == 'sensor_lag':
        e = params.effects.sensor_lag
        fixed = {'effects.sensor_lag.enabled': True}
        if not e.enabled:
            fixed.update({f'effects.sensor_lag.{c}_tau_s': 0.0 for c in _CLEAN})
        return fixed, [_Param(f'effects.sensor_lag.{channel}_tau_s', 's', 0.0,
                              min(0.5 * period, 5.0))]
    if mech_id == 'supply_decay':
        if channel == 'position' or not params.supply.regulation:
            return None
        v0 = params.supply.vessel_volume_m3
        return ({'supply.regulation': False},
                [_Param('supply.vessel_volume_m3', 'm^3', v0 * 1e-3, v0 * 10.0, log=True)])
    if mech_id == 'offset_drift':
        e = params.effects.offset_drift
        fixed = {'effects.offset_drift.enabled': True}
        if not e.enabled:
            fixed.update({f'effects.offset_drift.{k}': 0.0 for k in _DRIFT.values()})
        return fixed, [_Param(f'effects.offset_drift.{_DRIFT[channel]}', '', -np.inf, np.inf)]
    if mech_id == 'saturation':
        return ({'effects.end_stops.enabled': True},
                [_Param('effects.end_stops.min_position', 'position units', lo - 0.05 * w,
                        lo + 0.45 * w),
                 _Param('effects.end_stops.max_position', 'position units', hi - 0.45 * w,
                        hi + 0.05 * w)])
    if mech_id == 'stiction':
        return ({'effects.stick_slip.enabled': True},
                [_Param('effects.stick_slip.static_band', 'position units', 1e-4 * w, 0.2 * w,
                        log=True),
                 # searched as a share of the static band, reported (and written) absolute
                 _Param('effects.stick_slip.dynamic_band', 'position units', 0.0, 0.9)])
    if mech_id == 'static_nonlinearity':
        if channel == 'position':
            return None
        return ({'effects.valve_characteristic.enabled': True},
                [_Param('effects.valve_characteristic.rangeability', '1', 1.05, 200.0, log=True)])
    if mech_id == 'rate_dependence':
        return ({'effects.rate_hysteresis.enabled': True},
                [_Param('effects.rate_hysteresis.width_per_rate_s', 's', 0.0, 0.5 * period),
                 _Param('effects.rate_hysteresis.filter_tau_s', 's', 0.02, period, log=True)])
    return None


#: Mechanisms the simulator can switch on.
SIM_EFFECTS = tuple(MECHANISMS)


class _SimObjective:
    def __init__(self, base, fixed, space, t, v, y, n_train, channel):
        self.base, self.fixed, self.space = base, fixed, space
        self.t, self.v, self.y, self.n, self.channel = t, v, y, n_train, channel
        self.cache: dict = {}

    def values(self, theta) -> dict:
        out = dict(self.fixed)
        for p, x in zip(self.space, theta):
            out[p.name] = float(x)
        if 'effects.stick_slip.dynamic_band' in out:
            out['effects.stick_slip.dynamic_band'] *= out['effects.stick_slip.static_band']
        return out

    def predict(self, theta) -> np.ndarray | None:
        key = tuple(np.round(np.asarray(theta, dtype=float), 12))
        if key not in self.cache:
            try:
                params = self.base.with_values(self.values(theta))
                self.cache[key] = simulate_clean(params, self.t, self.v, self.channel)
            except HystIdError:
                self.cache[key] = None
        return self.cache[key]

    def sse(self, theta) -> float:
        pred = self.predict(theta)
        if pred is None or not np.all(np.isfinite(pred)):
            return np.inf
        r = self.y[:self.n] - pred[:self.n]
        return float(r @ r)


def _to_unit(p: _Param, x: float) -> float:
    if p.log:
        return (np.log(x) - np.log(p.lo)) / (np.log(p.hi) - np.log(p.lo))
    return (x - p.lo) / (p.hi - p.lo)


def _from_unit(p: _Param, u: float) -> float:
    u = float(np.clip(u, 0.0, 1.0))
    if p.log:
        return float(np.exp(np.log(p.lo) + u * (np.log(p.hi) - np.log(p.lo))))
    return p.lo + u * (p.hi - p.lo)


def _fit_effect(obj: _SimObjective, mech_id: str, demand: np.ndarray | None = None
                ) -> np.ndarray:
    space = obj.space
    if mech_id == 'stiction' and obj.channel == 'position' and demand is not None:
        theta = _stiction_from_events(obj, demand)
        if theta is not None:
            return theta
    if mech_id == 'offset_drift':
        pred = obj.predict([0.0])
        tau = obj.t[:obj.n] - obj.t[0]
        r = obj.y[:obj.n] - pred[:obj.n]
        return np.array([float(r @ tau / (tau @ tau))])
    if len(space) == 1:
        p = space[0]
        grid = np.linspace(0.0, 1.0, 9)
        costs = [obj.sse([_from_unit(p, u)]) for u in grid]
        k = int(np.argmin(costs))
        a, b = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        res = minimize_scalar(lambda u: obj.sse([_from_unit(p, u)]), bounds=(a, b),
                              method='bounded', options={'xatol': 1e-3, 'maxiter': 20})
        u = res.x if res.fun < costs[k] else grid[k]
        return np.array([_from_unit(p, u)])
    n_grid = 12 if mech_id == 'stiction' else 5
    axes = [np.linspace(0.0, 1.0, n_grid)] * len(space)
    best_u, best_f = None, np.inf
    for u in np.array(np.meshgrid(*axes)).reshape(len(space), -1).T:
        f = obj.sse([_from_unit(p, x) for p, x in zip(space, u)])
        if f < best_f:
            best_u, best_f = u, f
    if best_u is None:
        return np.array([_from_unit(p, 0.0) for p in space])
    res = minimize(lambda u: obj.sse([_from_unit(p, x) for p, x in zip(space, u)]), best_u,
                   method='Nelder-Mead', options={'maxfev': 40, 'xatol': 1e-3,
                                                  'initial_simplex': None})
    u = res.x if res.fun < best_f else best_u
    return np.array([_from_unit(p, x) for p, x in zip(space, u)])


def _stiction_from_events(obj: _SimObjective, demand: np.ndarray) -> np.ndarray | None:
    """Bands from the measured slips (a grid cannot line the staircase up, see stick_events)."""
    n = obj.n
    sigma = noise_std(obj.y[:n])
    bands = bands_from_demand(demand[:n], obj.y[:n], sigma)
    if bands is None:
        return None
    static, dynamic = bands
    lo, hi = obj.space[0].lo, obj.space[0].hi
    if not lo <= static <= hi:
        return None
    return np.array([static, dynamic / static])


def _implausible(mech_id: str, channel: str, theta: np.ndarray, sigma: float) -> str:
    """As :meth:`Mechanism.implausible`, for the simulator's settings (position slips)."""
    if mech_id == 'stiction' and channel == 'position':
        slip = float(theta[0]) * (1.0 - float(theta[1]))
        if slip < 2.0 * sigma:
            return (f'slip of {slip:.3g} is below twice the noise std ({sigma:.3g}): '
                    'no visible slips')
    return ''


def _result(ids, theta, pred, y, n_train) -> FitResult:
    r = y - pred
    tr, ho = r[:n_train], r[n_train:]
    return FitResult(ids=tuple(ids), p=np.asarray(theta, dtype=float), coef=np.zeros(0),
                     labels=[], prediction=pred, residual=r, sse_train=float(tr @ tr),
                     sse_holdout=float(ho @ ho), n_free=len(theta),
                     er_train_percent=float(er_percent(float(tr @ tr), y[:n_train])),
                     er_holdout_percent=float(er_percent(float(ho @ ho), y[n_train:])),
                     span=(0.0, 1.0), travel_raw=np.zeros(0))


def diagnose_sim(recording: Recording, rig_params, *,
                 settings: DiagnoseSettings | None = None,
                 progress: Callable[[str], None] | None = None):
    """Compare the rig simulator with a recording and switch on the effects it lacks.

    Parameters
    ----------
    recording : Recording
        The measured run (its command drives the simulator).
    rig_params : RigParams
        Simulator parameters to start from (e.g. ``load_rig_params(path)``).
    settings : DiagnoseSettings, optional
        Split, mechanisms, criteria (GAASS settings are not used).
    progress : callable, optional
        Called with a short message at each step.

    Returns
    -------
    tuple of (Diagnosis, RigParams)
        The diagnosis (``mode == 'sim'``) and the simulator parameters with
        every accepted effect switched on at its fitted values.
    """
    settings = settings or DiagnoseSettings()
    say = progress or (lambda msg: None)
    with threadpool_limits(limits=1):
        return _diagnose_sim(recording, rig_params, settings, say)


def _diagnose_sim(recording, base, settings, say):
    from hyst_id.rig import simulate_rig
    rec = roundoff_probe(validate_recording(recording))
    t, v, y, ch = rec.t_s, rec.command, rec.measurement, rec.channel
    n_train = split_index(t, settings.train_fraction)
    require_split(n_train, t.size)
    ids = settings.mechanisms or SIM_EFFECTS
    unknown = [i for i in ids if i not in MECHANISMS]
    if unknown:
        raise ConfigError(f'unknown mechanism(s) {unknown}; known: {list(MECHANISMS)}')
    rev = reversal_times(t[:n_train], v[:n_train])
    period = float(2 * np.median(np.diff(rev))) if rev.size > 2 else 0.25 * (t[-1] - t[0])
    sigma = noise_std(y)
    data = Data(t_s=t, v=v, y=y, n_train=n_train, noise_std=sigma,
                judged=inside_rows(v, n_train))
    say('simulating the command of the recording with the given simulator parameters')
    pred0 = simulate_clean(base, t, v, ch)
    baseline = _result((), [], pred0, y, n_train)
    loc0 = locate(t, v, y, pred0, sigma, n_train, period)
    current, loc, params, findings, rounds, applied = baseline, loc0, base, [], [], {}
    floor_h = floor_percent(y[n_train:], sigma)
    for round_no in range(settings.max_mechanisms):
        if not loc.structured and current.er_holdout_percent <= 1.5 * floor_h:
            break
        if round_no > 0 and current.er_holdout_percent <= 1.2 * floor_h:
            break
        truth = simulate_rig(params, t, v, seed=0).truth
        comps, spaces = [], {}
        for mid in ids:
            if mid in applied:
                continue
            space = _space(mid, params, ch, truth, t, period)
            if space is None:
                continue
            say(f'round {round_no + 1}: switching on {mid} in the simulator')
            obj = _SimObjective(params, space[0], space[1], t, v, y, n_train, ch)
            theta = _fit_effect(obj, mid, truth['backlash_out'])
            pred = obj.predict(theta)
            if pred is None:
                continue
            fit = _result(current.ids + (mid,), theta, pred, y, n_train)
            fit.n_free = current.n_free + len(theta)
            comp = compare(current, fit, data, mid, settings.criteria)
            comp.evidence, comp.where = MECHANISMS[mid].evidence(loc)
            reason = _implausible(mid, ch, theta, sigma)
            if reason and comp.accepted:
                comp.accepted, comp.status = False, f'rejected: {reason}'
            comps.append(comp)
            spaces[mid] = (obj, theta)
        winner, tied = choose(comps, data, settings.criteria)
        rounds.append(round_record(round_no + 1, comps, winner, data))
        if winner is None:
            break
        obj, theta = spaces[winner.mechanism]
        values = obj.values(theta)
        applied[winner.mechanism] = values
        params = params.with_values(values)
        findings.append(_finding(winner, current, loc, values, obj.space))
        findings[-1].alternatives = alternatives_record(
            tied, close_calls(comps, winner, tied, data, settings.criteria), data)
        current = winner.fit
        loc = locate(t, v, y, current.prediction, sigma, n_train, period)
    diag = Diagnosis(channel=ch, source=rec.source, mode='sim',
                     verdict=findings[0].mechanism if findings else 'none', t_s=t, command=v,
                     measurement=y, n_train=n_train, baseline=baseline, final=current,
                     findings=findings, localization=loc0,
                     final_localization=loc if current is not baseline else loc0,
                     noise_std=sigma, noise_floor_percent=floor_h,
                     noise_floor_train_percent=floor_percent(y[:n_train], sigma),
                     rounds=rounds, measurement_unit=rec.measurement_unit,
                     command_unit=rec.command_unit,
                     notes=list(rec.notes) + range_note(v, n_train, data.judged_rows.size),
                     extra={'simulator_changes': {k: val for d in applied.values()
                                                  for k, val in d.items()}})
    return diag, params


def _finding(comp: Comparison, before: FitResult, loc: Localization, values: dict,
             space: list) -> Finding:
    mech = MECHANISMS[comp.mechanism]
    units = {p.name: p.unit for p in space}
    params = {k: Quantity(float(v), units.get(k, ''), 'simulator setting')
              for k, v in values.items() if not isinstance(v, bool)}
    words = ', '.join(f'{k} = {q.value:.4g}{(" " + q.unit) if q.unit else ""}'
                      for k, q in params.items() if k in units)
    explanation = (f'The simulator leaves out {mech.title}: {mech.physics}. Switched on '
                   f'with {words}; re-simulated, the held-out %e_r falls from '
                   f'{before.er_holdout_percent:.3g} to {comp.fit.er_holdout_percent:.3g}.')
    return Finding(mechanism=mech.id, title=mech.title, placement=mech.placement,
                   explanation=explanation, where=located_where(loc, comp.where), params=params,
                   er_train_before_percent=before.er_train_percent,
                   er_train_after_percent=comp.fit.er_train_percent,
                   er_holdout_before_percent=before.er_holdout_percent,
                   er_holdout_after_percent=comp.fit.er_holdout_percent,
                   delta_bic=comp.delta_bic, holdout_z=comp.holdout_z)
