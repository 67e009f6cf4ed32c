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

"""The empirical block: what a model could still gain, and which features carry it.

When no mechanism of the library explains what the chain leaves, the
diagnosis still says how much is explainable and by what. The residual of
the fitted chain is regressed on a small library of labelled candidate
features of the command and time (levels, powers, rate and direction,
first-order filtered commands at three time constants for linear dynamics,
time and time x command for drift) by sequentially thresholded least
squares on standardised columns (the SINDy recipe: fit, drop the columns
whose coefficient is below a threshold, refit), on the training part only.
The held-out %e_r with the regression added, against the chain alone,
measures what a model could gain; the selected features and their shares of
the explained variance say which behaviour carries it. It is a measurement,
not physics: the report says so.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hyst_id.identification.chains import er_percent

__all__ = ['EmpiricalBlock', 'candidate_features', 'empirical_block', 'stlsq']

#: Relative coefficient (on standardised columns) below which a feature is dropped.
THRESHOLD = 0.05
#: Held-out gain below which the regression is said to explain nothing.
MIN_GAIN = 0.05


@dataclass
class EmpiricalBlock:
    """The regression's verdict on a residual (see the module docstring)."""

    er_holdout_before_percent: float
    er_holdout_after_percent: float
    features: list[tuple[str, float]] = field(default_factory=list)

    @property
    def gain(self) -> float:
        """Relative held-out improvement (0 = none, 1 = all of it)."""
        before = self.er_holdout_before_percent
        return 0.0 if before <= 0 else 1.0 - self.er_holdout_after_percent / before

    def to_dict(self) -> dict:
        """JSON-ready."""
        return {'er_holdout_before_percent': self.er_holdout_before_percent,
                'er_holdout_after_percent': self.er_holdout_after_percent,
                'gain': self.gain,
                'features': [{'feature': f, 'share': s} for f, s in self.features]}

    def summary(self) -> str:
        """One sentence for the report."""
        if not self.features or self.gain < MIN_GAIN:
            return ('an empirical regression on the command and time explains none of it on '
                    'held-out data: no low-order input-driven structure is left')
        top = ', '.join(f'{f} ({100 * s:.0f} %)' for f, s in self.features[:4])
        return (f'an empirical regression on the command and time would lower the held-out '
                f'%e_r from {self.er_holdout_before_percent:.4g} to '
                f'{self.er_holdout_after_percent:.4g} ({100 * self.gain:.0f} % of it); carried '
                f'by: {top}. This measures what a model could gain, it names no physics')


def _filtered(t: np.ndarray, v: np.ndarray, tau_s: float) -> np.ndarray:
    out = np.empty_like(v)
    out[0] = v[0]
    for k in range(1, v.size):
        a = np.exp(-max(t[k] - t[k - 1], 0.0) / tau_s)
        out[k] = a * out[k - 1] + (1.0 - a) * v[k]
    return out


def candidate_features(t_s: np.ndarray, v: np.ndarray,
                       period_s: float) -> tuple[list[str], np.ndarray]:
    """Labelled candidate features of the command ``v`` and time ``t_s`` (columns)."""
    t = np.asarray(t_s, dtype=float)
    v = np.asarray(v, dtype=float)
    c = v - v.mean()
    dv = np.gradient(v, t) if v.size > 1 else np.zeros_like(v)
    direction = np.sign(dv)
    for k in range(1, direction.size):          # hold the last direction over flat parts
        if direction[k] == 0:
            direction[k] = direction[k - 1]
    tt = (t - t[0]) / max(t[-1] - t[0], 1e-12)
    cols = {'command': c, 'command^2': c ** 2, 'command^3': c ** 3,
            'command rate dv/dt': dv, 'direction sign(dv/dt)': direction,
            'direction x command': direction * c, 'time': tt, 'time x command': tt * c}
    for frac in (0.02, 0.1, 0.5):
        tau = max(frac * period_s, 1e-9)
        cols[f'lag: command - first-order filtered (tau {tau:.3g} s)'] = \
            v - _filtered(t, v, tau)
    return list(cols), np.column_stack(list(cols.values()))


def stlsq(x: np.ndarray, r: np.ndarray, threshold: float = THRESHOLD,
          iterations: int = 10) -> np.ndarray:
    """Sequentially thresholded least squares on standardised columns; coefficients."""
    scale = x.std(axis=0)
    keep = scale > 0
    coef = np.zeros(x.shape[1])
    if not keep.any():
        return coef
    xs = (x[:, keep] - x[:, keep].mean(axis=0)) / scale[keep]
    rc = r - r.mean()
    active = np.ones(xs.shape[1], dtype=bool)
    beta = np.zeros(xs.shape[1])
    for _ in range(iterations):
        beta = np.zeros(xs.shape[1])
        if not active.any():
            break
        beta[active] = np.linalg.lstsq(xs[:, active], rc, rcond=None)[0]
        cut = threshold * max(np.max(np.abs(beta)), 1e-300)
        new = np.abs(beta) >= cut
        if np.array_equal(new, active):
            break
        active = new
    coef[keep] = beta / scale[keep]
    return coef


def empirical_block(t_s: np.ndarray, v: np.ndarray, y: np.ndarray, prediction: np.ndarray,
                    n_train: int, period_s: float) -> EmpiricalBlock:
    """Fit the residual ``y - prediction`` on the training part; judge it held out."""
    y = np.asarray(y, dtype=float)
    r = y - np.asarray(prediction, dtype=float)
    labels, x = candidate_features(t_s, v, period_s)
    coef = stlsq(x[:n_train], r[:n_train])
    centre = x[:n_train].mean(axis=0)
    fit = (x - centre) @ coef + r[:n_train].mean()

    def er(res: np.ndarray) -> float:
        return float(er_percent(float(np.sum(res ** 2)), y[n_train:]))

    before, after = er(r[n_train:]), er(r[n_train:] - fit[n_train:])
    parts = {lab: float(np.var((x[n_train:, i] - centre[i]) * coef[i]))
             for i, lab in enumerate(labels) if coef[i] != 0.0}
    total = sum(parts.values()) or 1.0
    features = sorted(((lab, p / total) for lab, p in parts.items()), key=lambda z: -z[1])
    if after >= before or 1.0 - after / before < MIN_GAIN:
        features = []
    return EmpiricalBlock(before, min(after, before), features)
