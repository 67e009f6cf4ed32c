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

"""Where a model's residual departs from measurement noise (classical residual analysis).

Given the measurement, the model's prediction (fitted on the training part,
predicted on the rest) and the measurement-noise level,
:func:`locate` answers

* *is anything left?* whiteness of the residual (autocorrelation with 99 %
  bounds ``2.58/sqrt(N)``, Ljung-Box portmanteau test) and independence from
  the input (cross-correlation with the command and with its rate, with
  Ljung's bounds ``3.29 sqrt(P/N)`` (99.9 %: the largest of many lags),
  ``P = sum_k r_ee(k) r_uu(k)``, at least the white residual's 1);
* *when?* RMS per time window, the linear trend of the residual (Newey-West
  t statistic) and whether the trend scales with the output level;
* *under which input?* residual per command level, direction of motion,
  time since the last reversal and command rate;
* *at which frequencies?* share of residual power below the command's
  fundamental (drift), at its harmonics (loop-shaped error) and elsewhere.

Everything is computed on the whole record (training residual plus
held-out prediction error) and summarised both as numbers
(:class:`Localization`) and in words (:meth:`Localization.summary`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import signal as sps
from scipy import stats

from hyst_id.signals.noise import robust_noise_std as noise_std
from hyst_id.signals.reversals import reversal_times

__all__ = ['LEVEL_TREND_T', 'Localization', 'locate', 'newey_west_t', 'noise_std', 'span_label']

Z99 = 2.5758   # two-sided 99 % normal quantile
Z_FAMILY = 3.29  # two-sided 99.9 %: bound for the largest of many correlation lags
#: |t| of the time x level term above which the residual's trend scales with the output
#: level (a gain that changes with time, not an offset)
LEVEL_TREND_T = 4.0


@dataclass
class Localization:
    """Result of :func:`locate` (numbers in the measurement's units unless named)."""

    n: int
    dt_s: float
    period_s: float
    noise_std: float
    rms: float
    white: bool
    independent: bool
    ljung_box: dict
    acf: dict
    ccf_command: dict
    ccf_rate: dict
    trend: dict
    windows: list
    regimes: dict
    spectrum: dict
    features: dict
    regions: list = field(default_factory=list)
    mask: np.ndarray | None = None

    @property
    def structured(self) -> bool:
        """Whether the residual shows structure (not white or not independent)."""
        return not (self.white and self.independent)

    def summary(self, unit: str = '') -> list[str]:
        """The located mismatch in plain words, most telling first."""
        u = f' {unit}' if unit else ''
        out = []
        ratio = self.rms / self.noise_std if self.noise_std > 0 else np.inf
        out.append(f'residual RMS {self.rms:.4g}{u} = {ratio:.2f} x the measurement noise '
                   f'({self.noise_std:.3g}{u})')
        lb = self.ljung_box
        if self.white:
            out.append(f'residual is white (Ljung-Box Q={lb["q"]:.1f} over {lb["lags"]} lags, '
                       f'p={lb["p"]:.2g})')
        else:
            out.append(f'residual is NOT white: Ljung-Box Q={lb["q"]:.0f} over {lb["lags"]} '
                       f'lags (p={lb["p"]:.1e}); autocorrelation outside the 99 % bound up to '
                       f'{self.acf["correlated_for_s"]:.2g} s')
        for name, c in (('command', self.ccf_command), ('command rate', self.ccf_rate)):
            if c['significant']:
                out.append(f'correlated with the {name}: r={c["peak_r"]:+.2f} at lag '
                           f'{c["peak_lag_s"]:+.2f} s (99.9 % bound {c["bound"]:.2f})')
        tr = self.trend
        if tr['significant']:
            out.append(f'trend over time: {tr["slope_per_s"]:+.3g}{u}/s (t={tr["t"]:.1f}); '
                       f'held-out mean {tr["holdout_mean"]:+.3g}{u} vs training '
                       f'{tr["train_mean"]:+.3g}{u}')
        if abs(tr['level_t']) > LEVEL_TREND_T:
            out.append(f'the trend scales with the output level (t={tr["level_t"]:.1f}): a '
                       'gain that changes with time')
        bad = [w for w in self.windows if w['flagged']]
        if bad:
            spans = ', '.join(f'{span_label(w["t_start_s"], w["t_end_s"], 0)} s'
                              for w in bad[:4])
            out.append(f'largest in time windows {spans}'
                       + (f' (+{len(bad) - 4} more)' if len(bad) > 4 else ''))
        for key, words, every in (('level', 'at command level', 'command level'),
                                  ('direction', 'while', 'direction of motion'),
                                  ('since_reversal', 'after a reversal:', 'time since a reversal'),
                                  ('rate', 'at command rate', 'command rate')):
            bins = self.regimes.get(key, [])
            bad = sorted((b for b in bins if b['flagged']), key=lambda b: -b['rms_ratio'])
            if not bad:
                continue
            ratios = [b['rms_ratio'] for b in bins]
            if len(bad) == len(bins) > 1 and max(ratios) < 1.3 * min(ratios):
                out.append(f'about the same at every {every} (RMS {min(ratios):.1f}-'
                           f'{max(ratios):.1f} x noise)')
                continue
            for b in bad[:2]:
                out.append(f'{words} {b["label"]}: RMS {b["rms_ratio"]:.1f} x noise, mean '
                           f'{b["mean"]:+.3g}{u} (t={b["mean_t"]:.1f})')
        stuck = self.features.get('stuck_fraction', 0.0)
        if stuck > 0.15:
            out.append(f'the measurement holds still in {100 * stuck:.0f} % of the stretches '
                       'where the model moves (a stick-slip signature)')
        sp = self.spectrum
        if sp['total'] > 0:
            out.append(f'residual power: {100 * sp["low_fraction"]:.0f} % below the command '
                       f'fundamental ({sp["f0_hz"]:.3g} Hz), {100 * sp["harmonic_fraction"]:.0f}'
                       f' % at its harmonics, {100 * sp["other_fraction"]:.0f} % elsewhere')
        return out

    def to_dict(self) -> dict:
        """JSON-ready summary (no per-sample arrays)."""
        def clean(d):
            return {k: v for k, v in d.items() if not isinstance(v, np.ndarray)}
        return {
            'white': self.white, 'independent': self.independent,
            'rms': self.rms, 'noise_std': self.noise_std, 'period_s': self.period_s,
            'ljung_box': self.ljung_box, 'acf': clean(self.acf),
            'ccf_command': clean(self.ccf_command), 'ccf_rate': clean(self.ccf_rate),
            'trend': self.trend, 'windows': [w for w in self.windows if w['flagged']],
            'regimes': {k: [b for b in v if b['flagged']] for k, v in self.regimes.items()},
            'spectrum': clean(self.spectrum), 'features': self.features,
            'regions_s': [[float(a), float(b)] for a, b, _ in self.regions],
        }


def newey_west_t(x: np.ndarray, y: np.ndarray, bandwidth: int) -> tuple[np.ndarray, np.ndarray]:
    """OLS of ``y`` on the columns of ``x`` with Newey-West (HAC) t statistics."""
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    e = y - x @ coef
    xe = x * e[:, None]
    s = xe.T @ xe
    for lag in range(1, bandwidth + 1):
        w = 1.0 - lag / (bandwidth + 1.0)
        g = xe[lag:].T @ xe[:-lag]
        s += w * (g + g.T)
    xtx_inv = np.linalg.pinv(x.T @ x)
    cov = xtx_inv @ s @ xtx_inv
    se = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    return coef, coef / se


def _acf(e: np.ndarray, max_lag: int) -> np.ndarray:
    e = e - e.mean()
    n = e.size
    f = np.fft.rfft(e, 2 * n)
    r = np.fft.irfft(f * np.conj(f))[:max_lag + 1]
    return r / r[0] if r[0] > 0 else np.zeros(max_lag + 1)


def _ccf(e: np.ndarray, u: np.ndarray, max_lag: int) -> tuple[np.ndarray, np.ndarray]:
    """``r(tau) = corr(e(t), u(t - tau))`` for ``tau = -max_lag..max_lag``."""
    e = e - e.mean()
    u = u - u.mean()
    n = e.size
    denom = np.sqrt(np.sum(e * e) * np.sum(u * u))
    if denom <= 0:
        return np.arange(-max_lag, max_lag + 1), np.zeros(2 * max_lag + 1)
    fe = np.fft.rfft(e, 2 * n)
    fu = np.fft.rfft(u, 2 * n)
    c = np.fft.irfft(fe * np.conj(fu))
    lags = np.arange(-max_lag, max_lag + 1)
    return lags, c[lags % (2 * n)] / denom


def _cross(e, u, n_lag, dt, acf_e):
    lags, r = _ccf(e, u, n_lag)
    acf_u = _acf(u, n_lag)
    p = 1.0 + 2.0 * float(np.sum(acf_e[1:n_lag + 1] * acf_u[1:n_lag + 1]))
    # at least the white residual's P = 1: estimated from the sample ACFs the sum over many
    # lags of a smooth command can come out near 0, and a bound of 0.01 then called r = 0.01
    # correlated on a clean record (a new user's review: 2,000 samples, bound 0.07)
    bound = Z_FAMILY * np.sqrt(max(p, 1.0) / e.size)
    k = int(np.argmax(np.abs(r)))
    return {'lags_s': lags * dt, 'r': r, 'bound': float(bound), 'peak_r': float(r[k]),
            'peak_lag_s': float(lags[k] * dt), 'significant': bool(abs(r[k]) > bound)}


def span_label(lo: float, hi: float, decimals: int | None = None) -> str:
    """``lo-hi`` with the digits that tell them apart; ``lo to hi`` when either is negative.

    ``decimals``: fixed decimals to start from (more are added until the two
    differ: a last window of 19.6-20 s had read '20-20 s'); else 4 significant
    digits, more as needed (a level range '-0.9998--0.5968' now reads
    '-0.9998 to -0.5968').
    """
    lo, hi = float(lo), float(hi)
    for extra in range(0, 6):
        if decimals is None:
            a, b = f'{lo:.{4 + extra}g}', f'{hi:.{4 + extra}g}'
        else:
            a, b = f'{lo:.{decimals + extra}f}', f'{hi:.{decimals + extra}f}'
        if a != b or lo == hi:
            break
    return f'{a} to {b}' if lo < 0 or hi < 0 else f'{a}-{b}'


def _bin(label, sel, e, sigma, bw, lo=None, hi=None):
    n = int(np.sum(sel))
    if n < 5:
        return None
    x = e[sel]
    mean = float(np.mean(x))
    rms = float(np.sqrt(np.mean(x * x)))
    n_eff = max(1.0, n / max(1.0, bw))
    sd = float(np.std(x)) or 1e-300
    return {'label': label, 'lo': lo, 'hi': hi, 'n': n, 'mean': mean, 'rms': rms,
            'rms_ratio': rms / sigma if sigma > 0 else np.inf,
            'mean_t': mean / (sd / np.sqrt(n_eff)), 'flagged': False}


def locate(t_s: np.ndarray, command: np.ndarray, measurement: np.ndarray,
           prediction: np.ndarray, noise_std: float, n_train: int | None = None,
           period_s: float | None = None) -> Localization:
    """Analyse the residual ``measurement - prediction``.

    Parameters
    ----------
    t_s, command, measurement, prediction : numpy.ndarray
        The record and the model's output over it.
    noise_std : float
        Measurement-noise standard deviation (:func:`hyst_id.signals.noise.estimate_noise_std`).
    n_train : int, optional
        Samples of the training part (the held-out part follows).
    period_s : float, optional
        Typical loop period; estimated from the command's reversals.

    Returns
    -------
    Localization
    """
    t = np.asarray(t_s, dtype=float)
    v = np.asarray(command, dtype=float)
    e = np.asarray(measurement, dtype=float) - np.asarray(prediction, dtype=float)
    n = e.size
    n_train = n if n_train is None else int(n_train)
    dt = float(np.median(np.diff(t)))
    rev = reversal_times(t, v)
    if period_s is None:
        period_s = float(2 * np.median(np.diff(rev))) if rev.size > 2 else 0.25 * (t[-1] - t[0])
    sigma = float(noise_std) if noise_std > 0 else float(np.std(e)) or 1e-300
    rms = float(np.sqrt(np.mean(e * e)))
    bw = max(1, int(round(max(n ** (1 / 3), 1.0 / dt))))

    # whiteness
    n_lag = int(min(max(20, round(0.5 * period_s / dt)), n // 4))
    acf = _acf(e, n_lag)
    h = min(20, n // 10)
    q = float(n * (n + 2) * np.sum(acf[1:h + 1] ** 2 / (n - np.arange(1, h + 1))))
    p_lb = float(stats.chi2.sf(q, h))
    bound = Z99 / np.sqrt(n)
    outside = np.abs(acf[1:]) > bound
    run = int(np.argmin(outside)) if not outside.all() else outside.size
    acf_d = {'lags_s': np.arange(n_lag + 1) * dt, 'r': acf, 'bound': float(bound),
             'correlated_for_s': run * dt, 'lag1': float(acf[1]) if n_lag else 0.0}
    white = p_lb >= 0.01

    # cross-correlation with the command and its rate
    rate = np.gradient(v, t)
    ccf_u = _cross(e, v, n_lag, dt, acf)
    ccf_w = _cross(e, rate, n_lag, dt, acf)
    independent = not (ccf_u['significant'] or ccf_w['significant'])

    # trend in time, and whether it scales with the level
    tau = (t - 0.5 * (t[0] + t[-1])) / max(t[-1] - t[0], 1e-12)
    yp = np.asarray(prediction, dtype=float)
    z = (yp - yp.mean()) / (yp.std() or 1.0)
    coef, tv = newey_west_t(np.column_stack([np.ones(n), tau]), e, bw)
    coef2, tv2 = newey_west_t(np.column_stack([np.ones(n), tau, z, tau * z]), e, bw)
    duration = max(t[-1] - t[0], 1e-12)
    tr_mean = float(np.mean(e[:n_train]))
    ho_mean = float(np.mean(e[n_train:])) if n_train < n else tr_mean
    trend = {'slope_per_s': float(coef[1] / duration), 't': float(tv[1]),
             'level_t': float(tv2[3]), 'level_slope_per_s': float(coef2[3] / duration),
             'train_mean': tr_mean, 'holdout_mean': ho_mean,
             'significant': bool(abs(tv[1]) > 4 and abs(coef[1]) > 0.5 * sigma)}

    # time windows
    w_len = max(period_s, 20 * dt, (t[-1] - t[0]) / 24)
    edges = np.arange(t[0], t[-1] + w_len, w_len)
    windows = []
    for a, b in zip(edges[:-1], edges[1:]):
        sel = (t >= a) & (t < b)
        if sel.sum() < 5:
            continue
        r = float(np.sqrt(np.mean(e[sel] ** 2)))
        windows.append({'t_start_s': float(a), 't_end_s': float(min(b, t[-1])),
                        'rms': r, 'rms_ratio': r / sigma, 'mean': float(np.mean(e[sel])),
                        'flagged': False})
    med = float(np.median([w['rms'] for w in windows])) if windows else rms
    for w in windows:
        w['flagged'] = bool(w['rms'] > 1.5 * sigma and w['rms'] > 1.3 * med)

    # input regimes
    span = float(np.ptp(v)) or 1.0
    moving = np.abs(rate) > 0.01 * (np.percentile(np.abs(rate), 95) or 1.0)
    regimes: dict[str, list] = {'level': [], 'direction': [], 'since_reversal': [], 'rate': []}
    qs = np.percentile(v, [0, 20, 40, 60, 80, 100])
    for i in range(5):
        sel = (v >= qs[i]) & ((v < qs[i + 1]) if i < 4 else (v <= qs[i + 1]))
        b = _bin(span_label(qs[i], qs[i + 1]), sel, e, sigma, bw, float(qs[i]),
                 float(qs[i + 1]))
        if b:
            regimes['level'].append(b)
    for label, sel in (('rising', moving & (rate > 0)), ('falling', moving & (rate < 0)),
                       ('holding', ~moving)):
        b = _bin(label, sel, e, sigma, bw)
        if b:
            regimes['direction'].append(b)
    since = np.full(n, np.inf)
    if rev.size:
        k = np.searchsorted(rev, t, side='right') - 1
        ok = k >= 0
        since[ok] = t[ok] - rev[k[ok]]
    edges_r = period_s * np.array([0.0, 0.03, 0.08, 0.15, 0.3, np.inf])
    for a, b in zip(edges_r[:-1], edges_r[1:]):
        label = f'{a:.2g}-{b:.2g} s' if np.isfinite(b) else f'> {a:.2g} s'
        bb = _bin(label, (since >= a) & (since < b), e, sigma, bw, float(a), float(b))
        if bb:
            regimes['since_reversal'].append(bb)
    ar = np.abs(rate)
    if moving.sum() > 20:
        qr = np.percentile(ar[moving], [0, 25, 50, 75, 100])
        for i in range(4):
            sel = moving & (ar >= qr[i]) & ((ar < qr[i + 1]) if i < 3 else (ar <= qr[i + 1]))
            b = _bin(f'{qr[i]:.3g}-{qr[i + 1]:.3g} /s', sel, e, sigma, bw, float(qr[i]),
                     float(qr[i + 1]))
            if b:
                regimes['rate'].append(b)
    mask = np.zeros(n, dtype=bool)
    for key, bins in regimes.items():
        for b in bins:
            big = b['rms'] > 1.3 * rms and b['rms'] > 1.5 * sigma
            biased = abs(b['mean_t']) > 4 and abs(b['mean']) > 0.5 * sigma
            b['flagged'] = bool(big or biased)

    # frequencies
    spectrum = _spectrum(t, v, e, dt, period_s)

    # features for the mechanisms' evidence
    lv = regimes['level']
    mid = [b['rms'] for b in lv[1:-1]] or [rms]
    ext = [b['rms'] for b in (lv[:1] + lv[-1:])] or [rms]
    sr = regimes['since_reversal']
    rt = regimes['rate']
    dirs = {b['label']: b for b in regimes['direction']}
    split_t = 0.0
    if 'rising' in dirs and 'falling' in dirs:
        a, b = dirs['rising'], dirs['falling']
        se = np.sqrt((a['rms'] ** 2) / max(1.0, a['n'] / bw) + (b['rms'] ** 2) / max(
            1.0, b['n'] / bw))
        split_t = (a['mean'] - b['mean']) / se if se > 0 else 0.0
    y = np.asarray(measurement, dtype=float)
    k = 5
    dy, dp = y[k::k] - y[:-k:k], yp[k::k] - yp[:-k:k]
    moves = np.abs(dp) > 6 * sigma
    stuck = float(np.mean(np.abs(dy[moves]) < 3 * sigma)) if moves.sum() > 20 else 0.0
    lo_y, hi_y = np.percentile(y, [0.5, 99.5])
    near = (np.abs(y - lo_y) < 2 * sigma) | (np.abs(y - hi_y) < 2 * sigma)
    features = {
        'rms_ratio': rms / sigma,
        'extreme_ratio': float(np.mean(ext) / (np.mean(mid) or 1e-300)),
        'early_late_ratio': float(sr[0]['rms'] / (np.mean([b['rms'] for b in sr[2:]]) or 1e-300))
        if len(sr) > 2 else 1.0,
        'slow_fast_ratio': float(rt[0]['rms'] / (rt[-1]['rms'] or 1e-300)) if len(rt) > 1
        else 1.0,
        'direction_split_t': float(split_t),
        'level_mean_t': float(max([abs(b['mean_t']) for b in lv] or [0.0])),
        'clip_fraction': float(np.mean(near)),
        'stuck_fraction': stuck,
        'trend_t': trend['t'], 'level_trend_t': trend['level_t'],
        'holdout_shift_sigma': (ho_mean - tr_mean) / sigma,
        'ccf_rate_peak': ccf_w['peak_r'], 'ccf_rate_lag_s': ccf_w['peak_lag_s'],
        'ccf_command_peak': ccf_u['peak_r'],
        'low_fraction': spectrum['low_fraction'],
        'harmonic_fraction': spectrum['harmonic_fraction'],
        'span': span,
    }
    regions = [(w['t_start_s'], w['t_end_s'], 'window') for w in windows if w['flagged']]
    return Localization(n=n, dt_s=dt, period_s=period_s, noise_std=sigma, rms=rms,
                        white=bool(white), independent=bool(independent),
                        ljung_box={'q': q, 'lags': h, 'p': p_lb}, acf=acf_d, ccf_command=ccf_u,
                        ccf_rate=ccf_w, trend=trend, windows=windows, regimes=regimes,
                        spectrum=spectrum, features=features, regions=regions, mask=mask)


def _spectrum(t, v, e, dt, period_s):
    grid = np.arange(t[0], t[-1], dt)
    if grid.size < 16:
        return {'f_hz': np.zeros(0), 'psd': np.zeros(0), 'f0_hz': 0.0, 'total': 0.0,
                'low_fraction': 0.0, 'harmonic_fraction': 0.0, 'other_fraction': 0.0}
    eu = np.interp(grid, t, e)
    vu = np.interp(grid, t, v)
    nper = int(min(grid.size, 2 ** int(np.ceil(np.log2(max(16, 3 * period_s / dt))))))
    f, pe = sps.welch(eu, fs=1.0 / dt, nperseg=nper, detrend=False)
    fv, pv = sps.periodogram(vu - vu.mean(), fs=1.0 / dt)
    f0 = float(fv[1 + np.argmax(pv[1:])]) if pv.size > 1 else 1.0 / period_s
    df = f[1] - f[0] if f.size > 1 else f0
    total = float(np.sum(pe))
    low = f < max(0.5 * f0, 1.5 * df)
    harm = np.zeros_like(low)
    for k in range(1, 12):
        harm |= np.abs(f - k * f0) <= max(0.25 * f0, 1.01 * df)
    harm &= ~low
    lf = float(np.sum(pe[low]) / total) if total > 0 else 0.0
    hf = float(np.sum(pe[harm]) / total) if total > 0 else 0.0
    return {'f_hz': f, 'psd': pe, 'f0_hz': f0, 'total': total, 'low_fraction': lf,
            'harmonic_fraction': hf, 'other_fraction': max(0.0, 1.0 - lf - hf)}
