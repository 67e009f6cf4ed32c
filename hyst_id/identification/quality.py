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

"""Warnings about an identification: what the data could not tell.

:func:`identification_warnings` returns one-line sentences for
``Identification.warnings`` (the report prints them):

* **measurement artefacts** -- frozen or clipped stretches, glitches, a
  coarse A/D, irregular sampling (:func:`hyst_id.signals.artefacts.find_artefacts`):
  the sensor or the logger, not the plant; first, as they colour every figure after.
* **loop shape** -- in the sign identified (``output_sign``) the model's loop
  runs counter-clockwise and its output never moves against the command
  right after a reversal; a friction force against displacement does both.
* **fit** -- the best %e_r well above the noise floor; seeds in other optima.
* **domain edges** -- judged in the search space (raw ``x_raw`` against the
  search bounds) and reported only when a short refinement with that one
  domain widened lowers the cost: a gauge parameter, or one the cost does
  not depend on, may rest on an edge harmlessly.
* **unexcited lines** -- the identified loop's geometry against the commands
  visited: a line that never sets the output (the top line on the paper's
  rig, as in its Table 1) leaves its parameters undetermined; a near-vertical
  left or right line leaves its slope undetermined.
* **poorly determined parameters** -- spread over the seeds that reached the
  best fit, and the standard error from the output's sensitivity and the
  noise, both relative to the parameter's natural scale.
"""

from __future__ import annotations

from dataclasses import replace

from typing import TYPE_CHECKING

import numpy as np

from hyst_id.errors import InvalidParametersError
from hyst_id.identification.chains import ChainSpec
from hyst_id.identification.loop import loop_orientation, reversal_response
from hyst_id.identification.refine import refine
from hyst_id.identification.result import Identification
from hyst_id.signals.artefacts import find_artefacts
from hyst_id.signals.noise import estimate_noise_std, offset_words
from hyst_id.signals.reversals import half_period_s
from hyst_id.solvers.gaass import GaassSolver

if TYPE_CHECKING:
    from hyst_id.io.recording import Recording

__all__ = [
    'NOISE_FREE_RATIO',
    'UNDER_FLOOR',
    'artefact_warnings',
    'assess',
    'domain_edge_warnings',
    'explained_share',
    'fit_follows',
    'fit_warnings',
    'FOLLOWS_SHARE',
    'floor_estimate_warnings',
    'floor_says_nothing',
    'identification_warnings',
    'orientation_warnings',
    'parameter_scales',
    'poorly_determined',
    'poorly_determined_warnings',
    'response_warnings',
    'unexcited_warnings',
]

#: %e_r over the noise floor above which the fit is called incomplete.
FIT_FACTOR = 1.5
#: A fit this many times its noise floor or more is read as a fit to a noise-free (or
#: smoothed) record, whose floor is about 0: a ratio to it says nothing.
NOISE_FREE_RATIO = 1000.0
#: A fit below this share of its noise floor (after what fitting the parameters takes
#: off the noise) says the floor was estimated too high.
UNDER_FLOOR = 0.8
#: A fit explaining less than this share of the measurement's variance says the
#: measurement does not follow the command (:func:`response_warnings`).
FOLLOWS_SHARE = 0.1
#: Seeds within this factor of the best %e_r count as converged.
CONVERGED_FACTOR = 1.1
#: Relative spread or standard error above which a parameter is poorly determined.
POOR_RELATIVE = 0.05
#: Where a parameter counts as on its domain edge, in domain widths.
EDGE_TOL = 1e-3
#: Relative cost drop that makes a domain edge matter.
EDGE_GAIN = 0.01

#: Parameters other than H's slopes whose lower domain edge at 0 is a physical limit.
_PHYSICAL_ZERO = ('m_bl', 'tau_s', 'zeta', 'omega_n')


def identification_warnings(ident: Identification, rec: Recording,
                            spec: ChainSpec | None = None) -> list[str]:
    """Every warning about an identification, as one-line sentences.

    Parameters
    ----------
    ident : Identification
        The result (``runs`` with ``x_raw`` and canonical ``x``).
    rec : Recording
        The recording it was identified from.
    spec : ChainSpec, optional
        The search spec (bounds, calibration); default a profiled spec with
        ``ident.bounds``.

    Returns
    -------
    list of str
        Warnings, most fundamental first.
    """
    return assess(ident, rec, spec)[0]


def assess(ident: Identification, rec: Recording,
           spec: ChainSpec | None = None) -> tuple[list[str], dict[str, float]]:
    """The warnings of :func:`identification_warnings` and the poorly determined names.

    Returns
    -------
    warnings : list of str
        As :func:`identification_warnings`.
    poorly_determined : dict of str to float
        Parameters whose spread over converged seeds or standard error
        exceeds 5 % of their scale (:func:`poorly_determined`), each with
        that relative uncertainty: what a quality gate looks at. Parameters
        of unexcited lines are not among them: they do not act on commands
        the recording visited.
    """
    if spec is None:
        spec = replace(ident.spec(), calibration=None)
    out = artefact_warnings(rec)
    out += response_warnings(ident.er_percent, rec.measurement)
    out += [w for w in [offset_words(ident.er_percent, rec.measurement,
                                     rec.measurement_unit)] if w]
    out += orientation_warnings(rec, _sign(ident), followed=fit_follows(
        ident.er_percent, ident.noise_floor_percent))
    out += fit_warnings(ident) + floor_estimate_warnings(ident, rec.n_samples)
    out += domain_edge_warnings(ident, rec, spec)
    unexcited, names = unexcited_warnings(ident, rec)
    out += unexcited
    poor = poorly_determined(ident, rec, skip=names)
    out += _poor_warning(poor)
    return out, {name: rel for name, (rel, _) in sorted(poor.items())}


def artefact_warnings(rec: Recording) -> list[str]:
    """The recording's measurement artefacts, one sentence each (the sensor, not the plant)."""
    return [f'measurement artefact ({a.kind}): {a.words}'
            for a in find_artefacts(rec.t_s, rec.command, rec.measurement,
                                    rec.measurement_unit)]


def explained_share(er_percent: float, measurement: np.ndarray) -> float:
    """Share of the measurement's variance about its mean that a fit of ``er_percent`` explains.

    %e_r (Eq. 7) is relative to the measurement itself; its mean alone
    (a constant model) gives ``100 sqrt(var / mean square)``.
    """
    y = np.asarray(measurement, dtype=float)
    var, mean_square = float(np.var(y)), float(np.mean(y * y))
    if not var > 0.0:
        return 1.0
    return 1.0 - (er_percent / 100.0) ** 2 * mean_square / var


def response_warnings(er_percent: float, measurement: np.ndarray) -> list[str]:
    """Warn when the fit explains almost none of the measurement: it does not follow the command.

    A disconnected sensor reading noise, or the wrong column, is fitted by a flat
    chain at ``1.00 x`` a noise floor estimated from the measurement itself.
    """
    share = explained_share(er_percent, measurement)
    if share >= FOLLOWS_SHARE:
        return []
    return [f"the model explains {100 * max(share, 0.0):.1f} % of the measurement's "
            'variation: the measurement does not follow the command (a disconnected or wrong '
            'sensor, the wrong column, or no response). The noise floor is estimated from the '
            "measurement's own sample-to-sample changes, so a ratio to it means nothing here"]


def orientation_warnings(rec: Recording, sign: float = 1.0, *,
                         followed: bool = False) -> list[str]:
    """Warn about loop shapes the model cannot make, in the sign identified.

    The model's loop runs counter-clockwise in ``sign * measurement`` and
    its output never moves against the command right after a reversal.
    ``followed``: the fit is within :data:`FIT_FACTOR` x the noise floor, so the
    chain does make what the data show (a loop whose output jumps, a ringing
    sensor): only the output sign is said.
    """
    y = sign * np.asarray(rec.measurement, dtype=float)
    out = []
    if sign < 0:
        out.append('output sign -1: the measurement falls as the chain output rises, so the '
                   'parameters describe -measurement (their output-side values in negated '
                   'measurement units)')
    if followed:
        return out
    orientation = loop_orientation(rec.command, y)
    if orientation > 0.005:
        out.append(f'the loop runs clockwise (orientation {orientation:+.2f}): the model makes '
                   'counter-clockwise loops only, so it can only approximate this one')
    against = reversal_response(rec.command, y)
    if against >= 0.5:
        out.append(f'after {100 * against:.0f} % of the command reversals the response first '
                   'moves against the command (a transition right after each reversal, as a '
                   'friction force against displacement makes); the branches of the '
                   'model are monotone and switch before the reversal, so it cannot follow these '
                   'transitions')
    return out


def floor_says_nothing(er_percent: float, floor_percent: float) -> bool:
    """Whether a ratio of ``er_percent`` to the noise floor means nothing.

    True when the floor is about 0 next to the fit (:data:`NOISE_FREE_RATIO`): a
    noise-free or smoothed record, whose ratio only measures round-off.
    """
    return not er_percent < NOISE_FREE_RATIO * floor_percent


def fit_follows(er_percent: float, floor_percent: float) -> bool:
    """Whether a fit is within :data:`FIT_FACTOR` x a meaningful noise floor."""
    return bool(floor_percent > 0 and not floor_says_nothing(er_percent, floor_percent)
                and er_percent <= FIT_FACTOR * floor_percent)


def fit_warnings(ident: Identification) -> list[str]:
    """Warn about a fit above the noise floor and about seeds in other optima."""
    out = []
    floor = ident.noise_floor_percent
    if ident.er_percent > 1e-9 and floor_says_nothing(ident.er_percent, floor):
        out.append(f'the noise floor is about 0 (a noise-free or smoothed record) and the fit '
                   f'misses by %e_r {ident.er_percent:.4g}: the model misses part of the '
                   'response; look at the residual plot')
    elif floor > 0 and ident.er_percent > FIT_FACTOR * floor:
        hint = ('; curved branches (a piezo stack, a ferrite core, a Bouc-Wen loop) are the '
                "smooth family's: try --model auto" if ident.family == 'tk'
                else '')
        hint += ('; a measurement that follows the command with a lag has sensor dynamics '
                 'the position chain lacks: try --channel pressure (a first-order sensor) or '
                 'flow (second order)' if ident.channel == 'position' else '')
        out.append(f'the best %e_r is {ident.er_percent / floor:.1f} x the noise floor: the '
                   'model misses part of the response (unmodelled dynamics, drift, a loop '
                   "shape it cannot make); look at the residual plot, and 'hyst-id diagnose' "
                   f'names what is missing where its library has it{hint}. The floor is '
                   "estimated from the measurement's sample-to-sample changes, which filtered "
                   '(coloured) noise or a slow interference hides: with such noise the ratio '
                   'overstates the miss')
    er = np.array([r.er_percent for r in ident.runs])
    off = int(np.sum(er > CONVERGED_FACTOR * er.min()))
    if off:
        out.append(f'{off} of {len(er)} runs (seeds and later runs) ended more than '
                   f'{100 * (CONVERGED_FACTOR - 1):.0f} % above the best %e_r (other local '
                   'optima): the best run is reported; the mean over seeds mixes optima')
    return out


def floor_estimate_warnings(ident: Identification, n_samples: int) -> list[str]:
    """Warn when the fit is further below the noise floor than noise allows.

    A least-squares fit of ``p`` parameters (H, B, the sensor and the
    calibration) to ``n`` samples of white noise leaves about ``sqrt(1 - p/n)``
    of it. A fit below :data:`UNDER_FLOOR` of that says the floor, estimated
    from differences of neighbouring samples, is too high: a signal that moves
    much between samples (few samples per loop, coarse or uneven sampling)
    adds to those differences.
    """
    floor = ident.noise_floor_percent
    p = len(ident.names) + 2
    left = np.sqrt(max(0.0, 1.0 - p / max(n_samples, 1)))
    if not (floor > 0.0 and ident.er_percent < UNDER_FLOOR * left * floor):
        return []
    return [f'the fit is {ident.er_percent / floor:.2f} x the noise floor, below what noise '
            'allows: the floor is estimated too high here (it is estimated from differences of '
            'neighbouring samples, which a signal that moves much between samples inflates: '
            'few samples per loop, coarse or uneven sampling), so a ratio to it flatters the '
            'fit; judge the fit by its residual plot']


def _at_edge(x: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """-1 on the lower edge, +1 on the upper, 0 inside, per parameter."""
    tol = EDGE_TOL * (bounds[:, 1] - bounds[:, 0])
    return np.where(x <= bounds[:, 0] + tol, -1, np.where(x >= bounds[:, 1] - tol, 1, 0))


def _probe(spec: ChainSpec, rec: Recording, x0: np.ndarray, generations: int,
           max_nfev: int) -> float:
    """Best cost of a short GAASS run seeded with ``x0``, then a refinement."""
    cost = spec.cost_function(rec.t_s, rec.command, rec.measurement)
    res = GaassSolver(cost, spec.bounds, feasible=spec.feasible, pop_size=10,
                      maxiter=generations, x0=x0, rng=0).solve()
    _, fun, _ = refine(spec, res.x, rec.t_s, rec.command, rec.measurement, max_nfev=max_nfev)
    return min(float(res.fun), fun)


def domain_edge_warnings(ident: Identification, rec: Recording, spec: ChainSpec, *,
                         probe_generations: int = 50, probe_nfev: int = 1000) -> list[str]:
    """Warn about parameters on a domain edge whose domain was too narrow.

    Parameters
    ----------
    ident : Identification
        The result; ``x_raw`` of each run is compared with ``spec.bounds``.
    rec : Recording
        The recording.
    spec : ChainSpec
        The search spec.
    probe_generations, probe_nfev : int
        Size of each probe: GAASS generations (population 10, seeded with
        the best run) and refinement evaluations.

    Returns
    -------
    list of str
        One warning per parameter on an edge of the best run for which a
        short search from the best run in the domain widened past that edge
        ends more than 1 % lower than the same search in the original domain.
    """
    y = np.asarray(rec.measurement, dtype=float)
    bounds = np.asarray(spec.bounds, dtype=float)
    edges = np.array([_at_edge(r.x_raw, bounds) for r in ident.runs])
    best = min(ident.runs, key=lambda r: r.fun)
    best_edge = _at_edge(best.x_raw, bounds)
    out, f_same = [], None
    units = spec.units
    for i, name in enumerate(spec.names):
        side = int(best_edge[i])
        if side == 0 or (name == 'm_bl' and spec.profiled):
            continue
        zero = name in _PHYSICAL_ZERO or units[i] == 'out/cmd'
        if side < 0 and zero and bounds[i, 0] <= 0.0:
            continue            # a physical limit, not a chosen domain
        width = bounds[i, 1] - bounds[i, 0]
        wide = bounds.copy()
        if side < 0:
            wide[i, 0] -= width
            if zero:
                wide[i, 0] = max(wide[i, 0], 0.0)
        else:
            wide[i, 1] += width
        if f_same is None:
            f_same = min(best.fun, _probe(spec, rec, best.x_raw, probe_generations, probe_nfev))
        f_wide = _probe(spec.with_bounds(wide, source=spec.domain_source), rec, best.x_raw,
                        probe_generations, probe_nfev)
        if not f_wide < (1.0 - EDGE_GAIN) * f_same:
            continue
        er_now = 100.0 * np.sqrt(f_same / np.sum(y ** 2))
        er_wide = 100.0 * np.sqrt(f_wide / np.sum(y ** 2))
        n_edge = int(np.sum(edges[:, i] == side))
        lo, hi = bounds[i]
        out.append(f'{name} sits on the {"lower" if side < 0 else "upper"} edge of its search '
                   f'domain [{lo:.4g}, {hi:.4g}] in {n_edge} of {len(ident.runs)} seeds, and '
                   f'widening that domain lowers %e_r from {er_now:.3f} to {er_wide:.3f}: the '
                   'domain is too narrow (give wider domains with --domains FILE.yaml)')
    return out


def unexcited_warnings(ident: Identification, rec: Recording) -> tuple[list[str], set[str]]:
    """Warn about parts of the identified loop that the command never exercises.

    The family decides what that means (``tk``: lines of the loop never
    followed, :func:`hyst_id.models.tk_lines.unexcited_lines`); returns the
    warnings and the parameters they leave undetermined.
    """
    family = ident.spec().family
    return family.unexcited(np.asarray(ident.x, dtype=float)[:family.n_params], rec.command,
                            rec.command_unit)


def parameter_scales(ident: Identification, rec: Recording) -> dict[str, float]:
    """Natural scale of each canonical parameter, for relative spreads.

    By unit: slopes (``out/cmd``) the loop's mean slope (output span over
    command span); command positions (``cmd``) the command span plus the
    lever of a crossing at zero output far from the data; output levels
    (``out``) the output span plus the lever of an intercept at zero
    command; ``1/out`` and ``1/out^2`` the inverse output span (squared).
    ``tau_s``: the excitation's half period; ``zeta`` and other
    dimensionless ones: 1; ``omega_n``: its value.
    """
    sign = _sign(ident)
    v = np.asarray(rec.command, dtype=float)
    y = sign * np.asarray(rec.measurement, dtype=float)
    span_v, span_y = float(np.ptp(v)), float(np.ptp(y))
    slope = span_y / span_v
    v_mid, y_mid = 0.5 * (v.max() + v.min()), 0.5 * (y.max() + y.min())
    by_unit = {'out/cmd': slope, 'cmd': span_v + abs(y_mid) / slope,
               'out': span_y + abs(v_mid) * slope, '1/out': 1.0 / span_y,
               '1/out^2': 1.0 / span_y ** 2, '1': 1.0,
               's': half_period_s(rec.t_s, rec.command)}
    units = ident.spec().units
    scales = {n: by_unit.get(u, 1.0) for n, u in zip(ident.names, units)}
    scales.update({'c_bl': span_y, 'c_br': span_y})
    if 'omega_n' in ident.names:
        scales['omega_n'] = max(abs(ident.params['omega_n']), 1e-12)
    scales.pop('m_bl', None)
    return scales


def _standard_errors(ident: Identification, rec: Recording, sign: float) -> dict[str, float]:
    """Estimate standard errors from the output sensitivity at the best canonical parameters.

    Canonical parameters free: H (8), the backlash half width (``c_br = -c_bl``),
    sensor parameters. Covariance ``sigma^2 (J^T J)^+``.
    """
    spec = replace(ident.spec(), calibration=(1.0, 0.0))
    x0 = np.asarray(ident.x, dtype=float)
    free = [i for i, n in enumerate(ident.names) if n not in ('m_bl', 'c_bl')]
    y = sign * np.asarray(rec.measurement, dtype=float)
    sigma = estimate_noise_std(y)
    scales = parameter_scales(ident, rec)

    def output(x: np.ndarray) -> np.ndarray | None:
        x = x.copy()
        x[ident.names.index('c_bl')] = -x[ident.names.index('c_br')]
        try:
            return spec.simulate(x, rec.t_s, rec.command)
        except InvalidParametersError:
            return None

    base = output(x0)
    if base is None or sigma <= 0:
        return {}
    cols = []
    for i in free:
        h = 1e-4 * scales[ident.names[i]]
        step = np.zeros_like(x0)
        step[i] = h
        hi, lo = output(x0 + step), output(x0 - step)
        if hi is not None and lo is not None:
            cols.append((hi - lo) / (2 * h))
        elif hi is not None:
            cols.append((hi - base) / h)
        elif lo is not None:
            cols.append((base - lo) / h)
        else:
            cols.append(np.zeros_like(base))
    jac = np.array(cols).T
    cov = sigma ** 2 * np.linalg.pinv(jac.T @ jac)
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    zero = ~np.any(jac != 0.0, axis=0)
    return {ident.names[i]: (np.inf if zero[k] else float(se[k])) for k, i in enumerate(free)}


def poorly_determined_warnings(ident: Identification, rec: Recording,
                               skip: set[str] | frozenset = frozenset()) -> list[str]:
    """Warn about parameters the data pins down poorly (:func:`poorly_determined`)."""
    return _poor_warning(poorly_determined(ident, rec, skip))


def _poor_warning(found: dict[str, tuple[float, str]]) -> list[str]:
    if not found:
        return []
    return ['poorly determined by this recording: ' + '; '.join(t for _, t in found.values())
            + ' -- treat these values with care (a longer or wider excitation helps)']


def poorly_determined(ident: Identification, rec: Recording,
                      skip: set[str] | frozenset = frozenset()) -> dict[str, tuple[float, str]]:
    """Parameters the data pins down poorly: ``{name: (relative uncertainty, words)}``.

    A parameter is poorly determined when its spread (standard deviation)
    over the converged seeds (``%e_r`` within 10 % of the best; at least 3)
    or its standard error from the output sensitivity exceeds 5 % of its
    scale (:func:`parameter_scales`). Parameters in ``skip`` (already
    reported as unexcited) and the gauge-fixed backlash are left out. The
    relative uncertainty is the larger of the two over the scale (``inf``
    when the output does not depend on the parameter at all).
    """
    sign = _sign(ident)
    scales = parameter_scales(ident, rec)
    er = np.array([r.er_percent for r in ident.runs])
    good = [r for r, e in zip(ident.runs, er) if e <= CONVERGED_FACTOR * er.min()]
    spread = {}
    if len(good) >= 3:
        xs = np.array([r.x for r in good])
        spread = dict(zip(ident.names, xs.std(axis=0)))
    errors = _standard_errors(ident, rec, sign)
    found = {}
    for name, scale in scales.items():
        if name in skip or name == 'c_bl':
            continue
        rel_spread = spread.get(name, 0.0) / scale
        rel_error = errors.get(name, 0.0) / scale
        if rel_spread > POOR_RELATIVE or rel_error > POOR_RELATIVE:
            parts = []
            if name in spread:
                parts.append(f'spread over {len(good)} converged seeds '
                             f'{_percent(rel_spread)}')
            if name in errors:
                parts.append(f'standard error {_percent(rel_error)}')
            found[name] = (float(max(rel_spread, rel_error)),
                           f'{name} ({", ".join(parts)} of its scale {scale:.3g})')
    return found


def _sign(ident: Identification) -> float:
    """Canonical calibration sign: the canonical chain predicts ``sign * measurement``."""
    return float(getattr(ident, 'output_sign', 1.0))


def _percent(fraction: float) -> str:
    return 'unbounded' if not np.isfinite(fraction) else f'{100 * fraction:.0f} %'
