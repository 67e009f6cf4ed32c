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

"""The actuator chains of the paper's Fig. 1, one per measured channel.

``v -> H -> B -> sensor -> calibration -> y``

=========  ==========================================  ===========
channel    parameters (in vector order)                count
=========  ==========================================  ===========
position   m_l m_r m_t m_b c_l c_r c_t c_b m_bl c_bl c_br   11
pressure   ... + tau_s (first-order sensor)                 12
flow       ... + zeta omega_n (second-order sensor)         13
=========  ==========================================  ===========

Measurements arrive in the sensor's own units (mm, kPa, psi, g/s), so an
affine calibration ``y = k s + b`` follows the sensor dynamics. By default
``k`` and ``b`` are *profiled out*: for every candidate the best ``(k, b)`` is
the closed-form linear least-squares fit, so the optimiser searches only the
physical parameters and the calibration is always exact for the candidate
(variable projection). A fixed calibration can be given instead (the
paper's position chain is ``k = 1, b = 0``). Results are reported in the
canonical gauge (:mod:`hyst_id.identification.gauge`), where the calibration is ``(1, 0)``.

The population kernel :func:`population_cost` simulates the chain for a
whole population and returns the paper's cost J (Eq. 6) per candidate with
no Python in the per-sample loop.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable, Mapping

from numba import njit
import numpy as np

from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.models.backlash import BACKLASH_NAMES, backlash_step, check_backlash
from hyst_id.models.sensors import first_order_coefficient, second_order_coefficients
from hyst_id.models.tk import (
    check_hysteresis,
    hysteresis_feasible,
    HYSTERESIS_NAMES,
    hysteresis_step,
    initial_output,
)

__all__ = [
    'CHAIN_NAMES',
    'PAPER_DOMAINS',
    'PARAM_UNITS',
    'ChainSpec',
    'chain_spec',
    'population_cost',
    'er_percent',
]

SENSOR_NAMES = {'position': (), 'pressure': ('tau_s',), 'flow': ('zeta', 'omega_n')}
CHAIN_NAMES = {ch: HYSTERESIS_NAMES + BACKLASH_NAMES + extra
               for ch, extra in SENSOR_NAMES.items()}
_KIND = {'position': 0, 'pressure': 1, 'flow': 2}

#: Units of each parameter; ``cmd`` is the command's unit (mA on the paper's
#: rig) and ``out`` the hysteresis output's unit (position units).
PARAM_UNITS = {
    'm_l': 'out/cmd', 'm_r': 'out/cmd', 'm_t': 'out/cmd', 'm_b': 'out/cmd',
    'c_l': 'cmd', 'c_r': 'cmd', 'c_t': 'out', 'c_b': 'out',
    'm_bl': '1', 'c_bl': 'out', 'c_br': 'out',
    'tau_s': 's', 'zeta': '1', 'omega_n': 'rad/s',
}

#: The paper's search domains (section 4), a named preset.
PAPER_DOMAINS = {
    'm_l': (0.0, 5.0), 'm_r': (0.0, 5.0), 'm_t': (0.0, 5.0), 'm_b': (0.0, 5.0),
    'c_l': (-5.0, 5.0), 'c_r': (-5.0, 5.0), 'c_t': (4.0, 20.0), 'c_b': (4.0, 20.0),
    'm_bl': (0.0, 10.0), 'c_bl': (-10.0, 10.0), 'c_br': (-10.0, 10.0),
    'tau_s': (0.0, 20.0), 'zeta': (0.0, 0.99), 'omega_n': (0.0, 10.0),
}


@njit(cache=True)
def _feasible(p):
    return (hysteresis_feasible(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7])
            and p[8] > 0.0 and p[9] < p[10])


@njit(cache=True)
def _feasible_rows(pop):
    ok = np.empty(pop.shape[0], dtype=np.bool_)
    for i in range(pop.shape[0]):
        ok[i] = np.all(np.isfinite(pop[i])) and _feasible(pop[i])
    return ok


@njit(cache=True)
def _chain_signal(p, kind, v, dt_s, uniform, out):
    """Write the pre-calibration chain output for one candidate into ``out``."""
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    m_bl, c_bl, c_br = p[8], p[9], p[10]
    u = initial_output(v[0], m_r, m_t, m_b, c_r, c_t, c_b)
    y = m_bl * (u - c_br)
    out[0] = y
    n = v.shape[0]
    if kind == 0:
        for j in range(1, n):
            u = hysteresis_step(v[j], v[j - 1], u, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
            y = backlash_step(u, y, m_bl, c_bl, c_br)
            out[j] = y
    elif kind == 1:
        tau = p[11]
        a = first_order_coefficient(dt_s[1], tau)
        x = y
        for j in range(1, n):
            u = hysteresis_step(v[j], v[j - 1], u, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
            y = backlash_step(u, y, m_bl, c_bl, c_br)
            if not uniform:
                a = first_order_coefficient(dt_s[j], tau)
            x = a * x + (1.0 - a) * y
            out[j] = x
    else:
        zeta, omega = p[11], p[12]
        p11, p12, p21, p22 = second_order_coefficients(dt_s[1], zeta, omega)
        x = y
        xd = 0.0
        for j in range(1, n):
            u = hysteresis_step(v[j], v[j - 1], u, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
            y = backlash_step(u, y, m_bl, c_bl, c_br)
            if not uniform:
                p11, p12, p21, p22 = second_order_coefficients(dt_s[j], zeta, omega)
            e = x - y
            x = y + p11 * e + p12 * xd
            xd = p21 * e + p22 * xd
            out[j] = x


@njit(cache=True)
def _fit_affine(s, y):
    """Least-squares ``(k, b)`` of ``y ~ k s + b`` and its residual sum of squares."""
    n = s.shape[0]
    s_ref = s[0]
    ss = 0.0
    sss = 0.0
    sy = 0.0
    ssy = 0.0
    syy = 0.0
    for j in range(n):
        sj = s[j] - s_ref
        ss += sj
        sss += sj * sj
        sy += y[j]
        ssy += sj * y[j]
        syy += y[j] * y[j]
    var_s = sss - ss * ss / n
    cov = ssy - ss * sy / n
    var_y = syy - sy * sy / n
    if var_s <= 1e-300 * max(1.0, sss):
        return 0.0, sy / n, max(var_y, 0.0)
    k = cov / var_s
    b = (sy - k * ss) / n - k * s_ref
    return k, b, max(var_y - k * cov, 0.0)


@njit(cache=True)
def _sse(s, y, k, b):
    acc = 0.0
    for j in range(s.shape[0]):
        r = y[j] - (k * s[j] + b)
        acc += r * r
    return acc


@njit(cache=True)
def population_cost(pop, kind, v, y, dt_s, uniform, profile, k_fixed, b_fixed):
    """Cost J (Eq. 6) of every row of ``pop``; infeasible rows cost ``inf``.

    Parameters
    ----------
    pop : numpy.ndarray
        ``(n_candidates, n_params)`` parameter vectors.
    kind : int
        0 position, 1 first-order sensor, 2 second-order sensor.
    v, y, dt_s : numpy.ndarray
        Command, measurement and sample intervals (seconds).
    uniform : bool
        All intervals equal (sensor coefficients computed once).
    profile : bool
        Fit the affine calibration per candidate (else use the fixed one).
    k_fixed, b_fixed : float
        The fixed calibration when ``profile`` is False.

    Returns
    -------
    numpy.ndarray
        J per candidate.
    """
    n_pop = pop.shape[0]
    costs = np.empty(n_pop)
    s = np.empty(v.shape[0])
    for i in range(n_pop):
        p = pop[i]
        ok = _feasible(p)
        for q in range(p.shape[0]):
            if not np.isfinite(p[q]):
                ok = False
        if not ok:
            costs[i] = np.inf
            continue
        _chain_signal(p, kind, v, dt_s, uniform, s)
        if profile:
            k, b, _ = _fit_affine(s, y)
            costs[i] = _sse(s, y, k, b)   # second pass: no cancellation
        else:
            costs[i] = _sse(s, y, k_fixed, b_fixed)
    return costs


def er_percent(cost_j: float | np.ndarray, measurement: np.ndarray) -> float | np.ndarray:
    """Relative percentage error %e_r (Eq. 7) from the cost J."""
    return np.sqrt(np.asarray(cost_j) / float(np.sum(np.square(measurement)))) * 100.0


def _intervals(t_s: np.ndarray) -> tuple[np.ndarray, bool]:
    d = np.diff(np.asarray(t_s, dtype=np.float64))
    dt = np.ascontiguousarray(np.concatenate([d[:1], d]))
    uniform = bool(np.all(np.abs(d - d[0]) <= 1e-9 * abs(d[0])))
    return dt, uniform


@dataclass(frozen=True)
class ChainSpec:
    """Parameter table, constraints and simulator of one channel's chain.

    Attributes
    ----------
    channel : str
        ``position``, ``pressure`` or ``flow``.
    bounds : numpy.ndarray
        ``(n_params, 2)`` search domain per parameter, in :attr:`names` order.
    calibration : tuple of float or None
        Fixed ``(k, b)`` of ``y = k s + b``; ``None`` profiles it per candidate.
    """

    channel: str
    bounds: np.ndarray
    calibration: tuple[float, float] | None = None
    domain_source: str = 'paper'
    extra: dict = field(default_factory=dict)

    @property
    def names(self) -> tuple[str, ...]:
        """Parameter names in vector order."""
        return CHAIN_NAMES[self.channel]

    @property
    def units(self) -> tuple[str, ...]:
        """Unit of each parameter (see :data:`PARAM_UNITS`)."""
        return tuple(PARAM_UNITS[n] for n in self.names)

    @property
    def n_params(self) -> int:
        """Number of searched parameters."""
        return len(self.names)

    @property
    def profiled(self) -> bool:
        """Whether the affine calibration is fitted per candidate."""
        return self.calibration is None

    def with_bounds(self, bounds: Mapping[str, tuple[float, float]] | np.ndarray,
                    source: str = 'given') -> 'ChainSpec':
        """Return a copy with some or all search domains replaced."""
        return replace(self, bounds=_bounds_array(self.channel, bounds, self.bounds),
                       domain_source=source)

    def feasible(self, pop: np.ndarray) -> np.ndarray:
        """Boolean mask of the rows of ``pop`` that satisfy every constraint."""
        pop = np.ascontiguousarray(np.atleast_2d(pop), dtype=np.float64)
        return _feasible_rows(pop)

    def cost_function(self, t_s: np.ndarray, command: np.ndarray,
                      measurement: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """Vectorised cost J for a recording: ``(n, m)`` population -> ``(n,)``."""
        v = np.ascontiguousarray(command, dtype=np.float64)
        y = np.ascontiguousarray(measurement, dtype=np.float64)
        dt, uniform = _intervals(t_s)
        kind = _KIND[self.channel]
        profile = self.profiled
        k, b = (1.0, 0.0) if profile else self.calibration

        def cost(pop: np.ndarray) -> np.ndarray:
            pop = np.ascontiguousarray(np.atleast_2d(pop), dtype=np.float64)
            return population_cost(pop, kind, v, y, dt, uniform, profile, k, b)

        return cost

    def signal(self, params: np.ndarray, t_s: np.ndarray, command: np.ndarray) -> np.ndarray:
        """Pre-calibration chain output ``s`` (sensor output in H's units)."""
        p = self.check(params)
        dt, uniform = _intervals(t_s)
        out = np.empty(len(command))
        _chain_signal(p, _KIND[self.channel], np.ascontiguousarray(command, dtype=np.float64),
                      dt, uniform, out)
        return out

    def residual(self, params: np.ndarray, t_s: np.ndarray, command: np.ndarray,
                 measurement: np.ndarray) -> np.ndarray:
        """Measurement minus chain output, with the calibration profiled if it is."""
        s = self.signal(params, t_s, command)
        y = np.ascontiguousarray(measurement, dtype=np.float64)
        if self.profiled:
            k, b, _ = _fit_affine(s, y)
        else:
            k, b = self.calibration
        return y - (k * s + b)

    def fit_calibration(self, params: np.ndarray, t_s: np.ndarray, command: np.ndarray,
                        measurement: np.ndarray) -> tuple[float, float]:
        """Calibration ``(k, b)`` for ``params``: fitted if profiled, else the fixed one."""
        if not self.profiled:
            return self.calibration
        s = self.signal(params, t_s, command)
        k, b, _ = _fit_affine(s, np.ascontiguousarray(measurement, dtype=np.float64))
        return float(k), float(b)

    def simulate(self, params: np.ndarray, t_s: np.ndarray, command: np.ndarray,
                 calibration: tuple[float, float] | None = None) -> np.ndarray:
        """Chain output in measurement units: ``k * signal + b``."""
        if calibration is None:
            calibration = (1.0, 0.0) if self.profiled else self.calibration
        k, b = calibration
        return k * self.signal(params, t_s, command) + b

    def check(self, params: np.ndarray) -> np.ndarray:
        """Validate a parameter vector (length, finiteness, constraints)."""
        p = np.asarray(params, dtype=np.float64).ravel()
        if p.shape[0] != self.n_params:
            raise InvalidParametersError(
                f'{self.channel} chain needs {self.n_params} parameters {self.names}, '
                f'got {p.shape[0]}')
        check_hysteresis(p[:8])
        check_backlash(p[8:11])
        if not np.all(np.isfinite(p)):
            raise InvalidParametersError('parameters must be finite')
        if self.channel == 'pressure' and p[11] < 0:
            raise InvalidParametersError('tau_s must be >= 0')
        if self.channel == 'flow' and (p[11] < 0 or p[12] < 0):
            raise InvalidParametersError('zeta and omega_n must be >= 0')
        return np.ascontiguousarray(p)

    def as_dict(self, params: np.ndarray) -> dict[str, float]:
        """Map parameter names to values."""
        return {n: float(x) for n, x in zip(self.names, np.asarray(params).ravel())}

    def from_dict(self, values: Mapping[str, float]) -> np.ndarray:
        """Parameter vector from a name -> value mapping (all names required)."""
        missing = [n for n in self.names if n not in values]
        if missing:
            raise ConfigError(f'missing parameters for the {self.channel} chain: {missing}')
        return np.array([float(values[n]) for n in self.names])


def _bounds_array(channel: str, bounds, base: np.ndarray | None) -> np.ndarray:
    names = CHAIN_NAMES[channel]
    if isinstance(bounds, Mapping):
        out = (np.array([PAPER_DOMAINS[n] for n in names], dtype=float)
               if base is None else np.array(base, dtype=float))
        unknown = set(bounds) - set(names)
        if unknown:
            raise ConfigError(f'unknown parameters for the {channel} chain: {sorted(unknown)}')
        for name, lohi in bounds.items():
            out[names.index(name)] = lohi
    else:
        out = np.array(bounds, dtype=float)
    if out.shape != (len(names), 2):
        raise ConfigError(f'{channel} chain needs {len(names)} (low, high) bounds')
    if not np.all(np.isfinite(out)) or np.any(out[:, 0] >= out[:, 1]):
        bad = [names[i] for i in range(len(names))
               if not (np.isfinite(out[i]).all() and out[i, 0] < out[i, 1])]
        raise ConfigError(f'search domain must be finite with low < high for {bad}')
    return out


def chain_spec(channel: str, domains: Mapping[str, tuple[float, float]] | None = None,
               calibration: tuple[float, float] | None = None) -> ChainSpec:
    """Build the spec of a channel's chain with the paper's domains by default.

    Parameters
    ----------
    channel : str
        ``position``, ``pressure`` or ``flow``.
    domains : mapping, optional
        Search domains overriding the paper's, by parameter name.
    calibration : tuple of float, optional
        Fixed ``(k, b)``; default profiled (fitted per candidate), for the
        position channel too: H and B already carry a scale and an offset, so
        profiling adds no freedom, but it lets the search run in the
        command's scale whatever units the measurement has.
    """
    if channel not in CHAIN_NAMES:
        raise ConfigError(f'unknown channel {channel!r}; expected one of {tuple(CHAIN_NAMES)}')
    base = np.array([PAPER_DOMAINS[n] for n in CHAIN_NAMES[channel]], dtype=float)
    spec = ChainSpec(channel=channel, bounds=base, calibration=calibration)
    if domains:
        spec = spec.with_bounds(domains, source='given')
    return spec
