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

"""Re-identification on a sliding window of live data; when its set replaces the current one.

A plant drifts (supply, temperature, wear); the set identified at the start
of a run goes stale. :func:`reidentify_window` fits the newest stretch of
live data while the compensator keeps running on the current set:

1. the window (the newest ``window_s`` of samples) is split in time: the
   newest ``holdout_s`` are held out, the rest is the training part;
2. two candidates are fitted on the training part: the current set
   polished by bounded least squares (a warm start: cheap, and it follows
   a slow drift) and, unless ``fresh_seeds`` is 0, a fresh
   :func:`~hyst_id.identification.identify` with a few seeds (it escapes a
   basin the drift has left); the one with the lower training error is the
   candidate;
3. :class:`SwapRule` decides on the held-out newest samples, which neither
   fit saw: the candidate replaces the current set only when its held-out
   error is lower by ``min_gain`` *and* significantly so (a one-sided
   t-test over ``blocks`` consecutive blocks of the held-out residuals,
   which tolerates their correlation better than a per-sample test), when
   the held-out stretch is excited (command spread and reversals) and not
   saturated (command or reading pinned at an extreme), and when the
   candidate passes the :class:`~hyst_id.live.gate.QualityGate`.

Every decision carries its reason (:class:`SwapDecision`), swap or not. No
ROS here: the identifier node runs this in a worker thread
(:class:`~hyst_id.live.jobs.SlidingJob`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import math
from typing import Any, Callable

import numpy as np
from scipy import stats

from hyst_id.errors import ConfigError, HystIdError
from hyst_id.identification import Identification, identify, IdentifySettings, SeedRun
from hyst_id.identification.quality import assess
from hyst_id.identification.refine import refine
from hyst_id.io.jsonable import jsonable
from hyst_id.io.recording import Recording
from hyst_id.live.gate import QualityGate
from hyst_id.signals.noise import noise_floor_percent
from hyst_id.signals.reversals import count_reversals

__all__ = ['SwapDecision', 'SwapRule', 'describe_settings', 'reidentify_window',
           'stretch_problems', 'tail_window']


@dataclass(frozen=True)
class SwapRule:
    """When a set fitted on a sliding window replaces the current one.

    Attributes
    ----------
    holdout_s : float
        Newest seconds of the window held out of the fit; the decision is
        taken on them.
    min_gain : float
        The candidate's held-out %e_r must be at most ``1 - min_gain`` times
        the current set's (0.1: 10 % lower).
    blocks : int
        Consecutive blocks of the held-out stretch for the paired test.
    max_p : float
        Largest one-sided p-value of the block test that counts as
        significant.
    min_excitation : float
        The held-out command's standard deviation must be at least this share
        of the whole window's.
    min_reversals : int
        Fewest command reversals in the held-out stretch.
    max_saturated : float
        Largest share of held-out samples with the command or the reading
        pinned at the window's extreme (a limit, a clipped sensor).
    """

    holdout_s: float = 10.0
    min_gain: float = 0.1
    blocks: int = 8
    max_p: float = 0.01
    min_excitation: float = 0.25
    min_reversals: int = 2
    max_saturated: float = 0.2

    def __post_init__(self) -> None:
        checks = ((self.holdout_s > 0, 'holdout_s must be > 0'),
                  (0.0 <= self.min_gain < 1.0, 'min_gain must be in [0, 1)'),
                  (self.blocks >= 3, 'blocks must be >= 3'),
                  (0.0 < self.max_p < 1.0, 'max_p must be in (0, 1)'),
                  (self.min_excitation >= 0, 'min_excitation must be >= 0'),
                  (self.min_reversals >= 0, 'min_reversals must be >= 0'),
                  (0.0 <= self.max_saturated <= 1.0, 'max_saturated must be in [0, 1]'))
        for ok, message in checks:
            if not ok:
                raise ConfigError(f'swap rule: {message}')


@dataclass
class SwapDecision:
    """What one sliding-window re-identification found, and whether it swaps.

    ``candidate`` is the fitted set (None when no fit was made: an unexcited
    or saturated stretch is refused before fitting).
    """

    swap: bool
    reason: str
    er_current_percent: float = math.nan
    er_candidate_percent: float = math.nan
    p_value: float = math.nan
    source: str = ''
    candidate: Identification | None = None
    window_s: float = math.nan
    n_samples: int = 0
    gate_reasons: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-ready form (without the candidate's parameters); NaN as null."""
        return jsonable({'swap': self.swap, 'reason': self.reason,
                         'holdout_er_current_percent': self.er_current_percent,
                         'holdout_er_candidate_percent': self.er_candidate_percent,
                         'p_value': self.p_value, 'candidate_source': self.source,
                         'window_s': self.window_s, 'n_samples': self.n_samples,
                         'gate_reasons': list(self.gate_reasons)})


def tail_window(rec: Recording, window_s: float) -> Recording:
    """The newest ``window_s`` seconds of ``rec`` (all of it when shorter)."""
    start = int(np.searchsorted(rec.t_s, rec.t_s[-1] - window_s, side='left'))
    return rec.window(start, rec.n_samples)


def _pinned(x: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Samples at ``lo`` or ``hi`` (within 0.1 % of the span) equal to a neighbour.

    A clipped signal repeats its limit exactly; a noisy one that only
    touches its extreme does not.
    """
    span = max(hi - lo, 1e-300)
    at = (np.abs(x - hi) <= 1e-3 * span) | (np.abs(x - lo) <= 1e-3 * span)
    same = np.abs(np.diff(x)) <= 1e-9 * span
    still = np.concatenate([same, [False]]) | np.concatenate([[False], same])
    return at & still


def stretch_problems(window: Recording, n_train: int, rule: SwapRule) -> list[str]:
    """Why the held-out stretch ``window[n_train:]`` cannot decide a swap ([] when it can)."""
    v, y = window.command, window.measurement
    v_new, y_new = v[n_train:], y[n_train:]
    out = []
    std_all, std_new = float(np.std(v)), float(np.std(v_new))
    if std_all <= 0 or std_new < rule.min_excitation * std_all:
        out.append(f'no excitation: the held-out command spread is {std_new:.3g}, under '
                   f"{rule.min_excitation:g} x the window's {std_all:.3g}")
    else:
        n_rev = count_reversals(v_new)
        if n_rev < rule.min_reversals:
            out.append(f'no excitation: {n_rev} command reversal(s) in the held-out stretch '
                       f'(need {rule.min_reversals})')
    for name, full, new in (('command', v, v_new), ('reading', y, y_new)):
        share = float(np.mean(_pinned(new, float(full.min()), float(full.max()))))
        if share > rule.max_saturated:
            out.append(f'saturated: the {name} is pinned at an extreme for {share:.0%} of the '
                       f'held-out stretch (limit {rule.max_saturated:.0%})')
    return out


def _block_test(r_cur: np.ndarray, r_new: np.ndarray, blocks: int) -> float:
    """One-sided p-value that the candidate's squared residuals are smaller, over blocks."""
    d = [float(np.mean(a ** 2) - np.mean(b ** 2))
         for a, b in zip(np.array_split(r_cur, blocks), np.array_split(r_new, blocks))]
    d = np.asarray(d)
    if np.all(d == d[0]):
        return 0.0 if d[0] > 0 else 1.0
    return float(stats.ttest_1samp(d, 0.0, alternative='greater').pvalue)


def _er(y: np.ndarray, pred: np.ndarray) -> float:
    r = y - pred
    return float(np.sqrt((r @ r) / max(float(y @ y), 1e-300)) * 100.0)


def _polish(current: Identification, train: Recording, max_nfev: int) -> Identification:
    """The current set polished on the training part, in a box around it.

    The stored bounds are the search domains of the fit's own gauge; the
    canonical set may lie outside them, so the polish gets its own box:
    half of each value either side plus a tenth of the largest (the
    chain's constraints are enforced by the polish itself).
    """
    x0 = current.x
    half = 0.5 * np.abs(x0) + 0.1 * float(np.max(np.abs(x0)))
    spec = current.spec().with_bounds(np.column_stack([x0 - half, x0 + half]),
                                      source='around the current set')
    x, fun, _ = refine(spec, x0, train.t_s, train.command, train.measurement,
                       max_nfev=max_nfev)
    pred = spec.simulate(x, train.t_s, train.command)
    params = dict(zip(current.names, (float(a) for a in x)))
    er = _er(train.measurement, pred)
    # one run of its own: the current set's seeds were fitted on other data, and their
    # spread must not speak for (or against) this set in the quality gate
    run = SeedRun(seed=-1, x_raw=np.asarray(x, dtype=float), x=np.asarray(x, dtype=float),
                  sign=current.output_sign, fun=float(fun), er_percent=er,
                  er_gaass_percent=er, nfev=0, nit=0, best_history=np.zeros(0),
                  message='current set polished on the window', initial=current.initial,
                  hold=current.hold)
    return replace(current, params=params, params_mean=dict(params), er_percent=er,
                   er_mean_params_percent=er, runs=[run], bounds=spec.bounds.copy(),
                   domain_source=spec.domain_source,
                   noise_floor_percent=noise_floor_percent(train.measurement),
                   warnings=[], poorly_determined={}, source=train.source)


def reidentify_window(current: Identification, window: Recording, *,
                      rule: SwapRule | None = None, gate: QualityGate | None = None,
                      fresh_settings: IdentifySettings | None = None,
                      polish_nfev: int = 2000,
                      should_stop: Callable[[], bool] | None = None) -> SwapDecision:
    """Fit ``window`` without its newest ``rule.holdout_s`` and decide whether to swap.

    Parameters
    ----------
    current : Identification
        The set the compensator runs on now (the warm start).
    window : Recording
        The newest live samples (:func:`tail_window`), same channel.
    rule : SwapRule, optional
        The swap rule (defaults).
    gate : QualityGate, optional
        The quality gate the candidate must pass (defaults).
    fresh_settings : IdentifySettings, optional
        Settings of the fresh identification; None fits only the warm start.
    polish_nfev : int
        Residual evaluations of the warm start's polish.
    should_stop : callable, optional
        Looked at between the steps; when true :class:`HystIdError` is raised.

    Returns
    -------
    SwapDecision
    """
    rule = rule or SwapRule()
    gate = gate or QualityGate()
    if window.channel != current.channel:
        raise ConfigError(f'window is {window.channel!r} but the current set is for '
                          f'{current.channel!r}')
    t = window.t_s
    n_train = int(np.searchsorted(t, t[-1] - rule.holdout_s, side='left'))
    base = {'window_s': float(t[-1] - t[0]), 'n_samples': int(window.n_samples)}
    n_new = window.n_samples - n_train
    if n_train < 20 or n_new < 2 * rule.blocks:
        return SwapDecision(False, f'window too short: {n_train} training and {n_new} held-out '
                            f'samples (need 20 and {2 * rule.blocks})', **base)
    problems = stretch_problems(window, n_train, rule)
    if problems:
        return SwapDecision(False, '; '.join(problems), **base)

    def stop_point() -> None:
        if should_stop is not None and should_stop():
            raise HystIdError('re-identification stopped')

    train = window.window(0, n_train)
    candidates = [('warm start (current set polished)', _polish(current, train, polish_nfev))]
    stop_point()
    failed = ''
    if fresh_settings is not None:
        try:
            fresh = identify(train, settings=fresh_settings, should_stop=should_stop,
                             on_generation=lambda *_: stop_point())
            candidates.append(('fresh identification', fresh))
        except HystIdError as exc:
            if should_stop is not None and should_stop():
                raise
            failed = f' (the fresh identification failed: {exc})'
    stop_point()
    source, cand = min(candidates, key=lambda sc: sc[1].er_percent)
    source += failed
    warnings, cand.poorly_determined = assess(cand, train)
    cand.warnings = list(warnings)
    y = window.measurement
    pred_cur = current.spec().simulate(current.x, t, window.command)
    pred_new = cand.spec().simulate(cand.x, t, window.command)
    er_cur, er_new = _er(y[n_train:], pred_cur[n_train:]), _er(y[n_train:], pred_new[n_train:])
    p = _block_test(y[n_train:] - pred_cur[n_train:], y[n_train:] - pred_new[n_train:],
                    rule.blocks)
    gate_reasons = gate.reasons(cand)
    found = {'er_current_percent': er_cur, 'er_candidate_percent': er_new, 'p_value': p,
             'source': source, 'candidate': cand, 'gate_reasons': gate_reasons, **base}
    if not er_new <= (1.0 - rule.min_gain) * er_cur:
        return SwapDecision(False, f'not better: held-out %e_r {er_new:.4g} vs the current '
                            f"set's {er_cur:.4g} (need {1.0 - rule.min_gain:.2f} x or less)",
                            **found)
    if not p <= rule.max_p:
        return SwapDecision(False, f'not significantly better: held-out %e_r {er_new:.4g} vs '
                            f'{er_cur:.4g}, block test p {p:.3g} (need <= {rule.max_p:g})',
                            **found)
    if gate_reasons:
        return SwapDecision(False, 'held back by the quality gate: ' + '; '.join(gate_reasons),
                            **found)
    return SwapDecision(True, f'better on the newest {rule.holdout_s:g} s: held-out %e_r '
                        f'{er_new:.4g} vs {er_cur:.4g} (p {p:.2g}), {source}', **found)


def describe_settings(rule: SwapRule) -> dict[str, Any]:
    """The rule's settings, JSON-ready."""
    return {k: getattr(rule, k) for k in rule.__dataclass_fields__}
