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

"""How close a desired value from the identification run can get to Eq. 26's reference.

Issue 17's targets for the unregulated paper rig (pressure <= 1.5 %, flow <= 3 %
%ε_c) compare the compensated reading with the reading of the *regulated*,
hysteresis-free rig following the desired position. A compensator can only
aim at a desired reading made from the desired position by a calibration
fitted on the (unregulated) identification run, so %ε_c of that desired value
itself, through the calibration's own sensor lag, is a floor for any
compensator that follows it (the "desired value vs reference" column of
``hyst-id experiment``).

For pressure and flow this prints that floor for calibrations of growing
richness, all fitted on the identification run by variable projection (the
package's :func:`~hyst_id.experiment.run.fit_position_calibration`, and a
fit of its own here only for the lead, which the package does not model):

* ``linear``: ``k F(position) + b`` (the paper's procedure; ``F`` the
  channel's sensor lag: first order for pressure, second order for flow);
* ``+ gain law``: times a linear gain ``1 + r t`` from the run's start,
  referred to the start (what column (b) uses for the ``gain_drift`` the
  diagnosis finds on this run);
* ``+ polynomial``: a cubic of the position instead of ``k position``;
* ``+ lead``: a first-order high-pass of the position added (the pipe
  emptying when the valve opens: flow overshoots).

Columns: the fitted lag, rms residual of the fit on the identification run,
and the floor. Usage: ``python bench/desired_value_floor.py``
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from hyst_id.experiment.result import CLEAN_SERIES, ExperimentConfig
from hyst_id.experiment.run import calibration_lag, eps_c_percent, \
    fit_position_calibration, ideal_actuator_params
from hyst_id.models.sensors import simulate_first_order, simulate_second_order
from hyst_id.rig import simulate_rig
from hyst_id.rig.params_file import load_rig_params
from hyst_id.signals.excitation import eq24, eq25

LAGS = {'pressure': ((0.3,), (1.0,), (3.0,)), 'flow': ((0.3, 0.5), (0.7, 1.5), (0.5, 5.0))}
BOUNDS = {'pressure': ([0.0], [20.0]), 'flow': ([0.0, 0.01], [0.99, 10.0])}


def lag(channel: str, theta, x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The channel's sensor lag applied to ``x``."""
    if channel == 'pressure':
        return simulate_first_order(x, t, theta[0])
    return simulate_second_order(x, t, theta[0], theta[1])


def fit_with_lead(channel: str, t: np.ndarray, pos: np.ndarray, y: np.ndarray, degree: int):
    """Fit ``y = (1 + r t) (sum_i a_i F(z^i) + a_l F(hp(p)) + b0) + b1``, ``hp`` a high-pass.

    Returns the lag, rate and lead time constant, the linear coefficients, the
    position's centre and scale, and the rms residual.
    """
    centre, scale = float(pos.mean()), float(pos.std())
    powers = [((pos - centre) / scale) ** i for i in range(1, degree + 1)]
    n_lag = 1 if channel == 'pressure' else 2
    rate = 1.0 / float(t[-1] - t[0])

    def columns(theta):
        fs = [lag(channel, theta[:n_lag], p, t) for p in powers]
        fs.append(lag(channel, theta[:n_lag],
                      pos - simulate_first_order(pos, t, theta[n_lag + 1]), t))
        g = 1.0 + theta[n_lag] * (t - t[0])       # linear, as (b) uses for gain_drift
        return np.column_stack([g[:, None] * np.column_stack(fs), g, np.ones_like(t)])

    def residual(theta):
        a = columns(theta)
        return y - a @ np.linalg.lstsq(a, y, rcond=None)[0]

    lo = list(BOUNDS[channel][0]) + [-0.99 * rate, 0.05]
    hi = list(BOUNDS[channel][1]) + [rate, 200.0]
    best = None
    for start in LAGS[channel]:
        for tz in (2.0, 20.0):
            sol = least_squares(residual, list(start) + [0.0, tz], bounds=(lo, hi))
            if best is None or sol.cost < best.cost:
                best = sol
    coef = np.linalg.lstsq(columns(best.x), y, rcond=None)[0]
    return best.x, coef, (centre, scale), float(np.sqrt(np.mean(residual(best.x) ** 2)))


def main() -> None:
    rig = load_rig_params('params/paper_rig.yaml').with_values({'supply.regulation': False})
    config = ExperimentConfig()
    t_id = np.arange(0.0, config.ident_duration_s, config.ident_dt_s)
    run = simulate_rig(rig, t_id, eq24(t_id), seed=config.ident_noise_seed)
    t_c = np.arange(int(round(config.comp_duration_s / config.comp_dt_s)) + 1) * config.comp_dt_s
    u_d = eq25(t_c)
    reference = simulate_rig(ideal_actuator_params(rig), t_c, u_d, seed=None)
    print('| channel | calibration | lag | fit rms | desired value vs reference (%) |')
    print('|---|---|---|---|---|')
    for ch in ('pressure', 'flow'):
        y, pos = run.measurement(ch), run.position
        paper = fit_position_calibration(ch, t_id, pos, y)
        w_ref = reference.truth[CLEAN_SERIES[ch]]
        n_lag = 1 if ch == 'pressure' else 2
        for name, law, degree in (('linear', 'none', 1), ('+ gain law', 'linear', 1),
                                  ('+ gain law + polynomial', 'linear', 3)):
            cal = paper if law == 'none' else fit_position_calibration(ch, t_id, pos, y, law,
                                                                       degree)
            floor = eps_c_percent(calibration_lag(cal, cal.from_position(u_d), t_c), w_ref,
                                  paper.b)
            shown = ', '.join(f'{v:.3g}' for k, v in cal.dynamics.items()
                              if k in ('tau_s', 'zeta', 'omega_n'))
            print(f'| {ch} | {name} | {shown} | {cal.rms_residual:.4g} | {floor:.2f} |')
        for name, degree in (('+ gain law + lead', 1), ('+ gain law + polynomial + lead', 3)):
            theta, coef, (centre, scale), rms = fit_with_lead(ch, t_id, pos, y, degree)
            ud = (u_d - centre) / scale
            # the desired value at the run's start (g = 1), static: the lead is the
            # unregulated pipe's, the regulated reference has none to follow
            desired = sum(coef[i] * ud ** (i + 1) for i in range(degree)) + coef[-2] + coef[-1]
            floor = eps_c_percent(lag(ch, theta[:n_lag], desired, t_c), w_ref, paper.b)
            shown = ', '.join(f'{v:.3g}' for v in theta[:n_lag])
            print(f'| {ch} | {name} | {shown} | {rms:.4g} | {floor:.2f} |')


if __name__ == '__main__':
    main()
