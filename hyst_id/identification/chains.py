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

"""The actuator chains of the paper's Fig. 1, one per measured channel and hysteresis family.

``v -> H -> B -> sensor -> calibration -> y``

=========  =================================================  =========================
channel    parameters (in vector order)                       count with the ``tk`` H
=========  =================================================  =========================
position   H's (``tk``: m_l m_r m_t m_b c_l c_r c_t c_b),     11
           then m_bl c_bl c_br
pressure   ... + tau_s (first-order sensor)                   12
flow       ... + zeta omega_n (second-order sensor)           13
=========  =================================================  =========================

H is any registered hysteresis family (:mod:`hyst_id.models.registry`; the
paper's ``tk`` by default). Measurements arrive in the sensor's own units
(mm, kPa, psi, g/s), so an affine calibration ``y = k s + b`` follows the
sensor dynamics. By default ``k`` and ``b`` are *profiled out*: for every
candidate the best ``(k, b)`` is the closed-form linear least-squares fit, so
the optimiser searches only the physical parameters and the calibration is
always exact for the candidate (variable projection). A fixed one can be
given (the paper's position chain: ``k = 1, b = 0``). Results are in the
canonical gauge (:mod:`hyst_id.identification.gauge`): calibration ``(1, 0)``.

The population cost (:meth:`ChainSpec.cost_function`) runs in two numba
passes per block of candidates: the family's kernel writes H's output, then
:func:`_tail_costs` runs backlash, sensor and calibration and returns the
paper's cost J (Eq. 6); no Python runs per sample.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable, Mapping

import numpy as np

from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.identification.chain_kernels import (fit_affine, sum_squares, tail_costs,
                                                  tail_feasible_rows, tail_signal)
from hyst_id.models.backlash import BACKLASH_NAMES, check_backlash
from hyst_id.models.family import HysteresisFamily
from hyst_id.models.registry import DEFAULT_FAMILY, get_family
from hyst_id.models.sensors import intervals_and_uniform

__all__ = ['CHAIN_NAMES', 'CHANNELS', 'HOLDS', 'INITIAL_STATES', 'PAPER_DOMAINS', 'PARAM_UNITS',
           'SENSOR_NAMES', 'ChainResiduals', 'ChainSpec', 'chain_names', 'chain_spec',
           'er_percent', 'param_units']

CHANNELS = ('position', 'pressure', 'flow')
#: Sensor-dynamics parameters of each channel.
SENSOR_NAMES = {'position': (), 'pressure': ('tau_s',), 'flow': ('zeta', 'omega_n')}
_KIND = {'position': 0, 'pressure': 1, 'flow': 2}
#: States a chain can start in at the first sample (:attr:`ChainSpec.initial`).
INITIAL_STATES = ('rising', 'falling')
#: Zero-order-hold conventions of the sensor input (:attr:`ChainSpec.hold`).
HOLDS = ('before', 'after')

#: Units of the parameters that do not belong to H.
TAIL_UNITS = {'m_bl': '1', 'c_bl': 'out', 'c_br': 'out', 'tau_s': 's', 'zeta': '1',
              'omega_n': 'rad/s'}
#: Search domains of the backlash and sensors in the paper (section 4).
TAIL_PAPER_DOMAINS = {'m_bl': (0.0, 10.0), 'c_bl': (-10.0, 10.0), 'c_br': (-10.0, 10.0),
                      'tau_s': (0.0, 20.0), 'zeta': (0.0, 0.99), 'omega_n': (0.0, 10.0)}


def chain_names(channel: str, family: str | HysteresisFamily | None = None) -> tuple[str, ...]:
    """Parameter names of a channel's chain with a hysteresis family, in vector order."""
    if channel not in SENSOR_NAMES:
        raise ConfigError(f'unknown channel {channel!r}; expected one of {CHANNELS}')
    return tuple(get_family(family).names) + BACKLASH_NAMES + SENSOR_NAMES[channel]


def param_units(family: str | HysteresisFamily | None = None) -> dict[str, str]:
    """Unit of every parameter of the chains with ``family`` (``cmd``, ``out``, ...)."""
    return {**dict(get_family(family).units), **TAIL_UNITS}


#: Names of the chains with the paper's ``tk`` loop, per channel.
CHAIN_NAMES = {ch: chain_names(ch, DEFAULT_FAMILY) for ch in CHANNELS}
#: Units of every parameter of the ``tk`` chains.
PARAM_UNITS = param_units(DEFAULT_FAMILY)
#: The paper's search domains (section 4), a named preset (``tk`` only).
PAPER_DOMAINS = {**dict(get_family(DEFAULT_FAMILY).paper_domains), **TAIL_PAPER_DOMAINS}


def _rows_feasible(family: HysteresisFamily, h: np.ndarray, tail: np.ndarray,
                   paper_frame: bool, proper: bool = True) -> np.ndarray:
    """Every constraint per row: H's family, B's and the sensor's, the paper's frame-bound ones."""
    ok = (family.feasible_rows(h) if proper else family.loose_rows(h)) & tail_feasible_rows(tail)
    return ok & family.paper_frame_rows(h) if paper_frame else ok


def er_percent(cost_j: float | np.ndarray, measurement: np.ndarray) -> float | np.ndarray:
    """Relative percentage error %e_r (Eq. 7) from the cost J."""
    y = np.ascontiguousarray(measurement, dtype=np.float64)
    return np.sqrt(np.asarray(cost_j) / sum_squares(y)) * 100.0


#: Largest number of H outputs (candidates x samples) held at once by the population cost.
_BLOCK_VALUES = 262_144


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
    domain_source : str
        Where the bounds came from (``paper``, ``auto``, ``given``); with
        ``paper`` the family's frame-bound constraints apply too
        (:meth:`hyst_id.models.family.HysteresisFamily.paper_frame_rows`).
    extra : dict
        Scales of the data the domains were derived from.
    family : HysteresisFamily
        The hysteresis H (the paper's ``tk`` by default).
    initial : {'rising', 'falling'}
        State at the first sample: H and B on the rising boundary of their
        loops (the model notes' suggestion, the default), or on the falling
        one, as after a command that came down from far above. Another
        simulator or a real rig may start either way
        (:func:`hyst_id.identification.driver.identify` chooses).
    hold : {'before', 'after'}
        Zero-order-hold convention of the sensor's input: sample ``j``'s value
        held over the interval before it (the default: the command changed
        right after the previous sample) or after it (a sample is taken just
        before the command of its instant acts; so do some simulators).
    proper : bool
        Search and validate proper loops only (the default; the inverse needs
        them). ``False``: the family's wider set (:meth:`~hyst_id.models.family.
        HysteresisFamily.loose_rows`; for the paper's loop, its own constraints,
        output jumps admitted), searched by :mod:`~hyst_id.identification.loose_phase`.
    """

    channel: str
    bounds: np.ndarray
    calibration: tuple[float, float] | None = None
    domain_source: str = 'paper'
    extra: dict = field(default_factory=dict)
    family: HysteresisFamily = field(default_factory=lambda: get_family(DEFAULT_FAMILY))
    initial: str = 'rising'
    hold: str = 'before'
    proper: bool = True

    def __post_init__(self) -> None:
        if self.initial not in INITIAL_STATES:
            raise ConfigError(f'initial state must be one of {INITIAL_STATES}, '
                              f'got {self.initial!r}')
        if self.hold not in HOLDS:
            raise ConfigError(f'hold must be one of {HOLDS}, got {self.hold!r}')

    @property
    def falling(self) -> bool:
        """Whether the chain starts on the falling boundary."""
        return self.initial == 'falling'

    def _h_command(self, v: np.ndarray) -> np.ndarray:
        """H's command: with a falling start, one sample from far above comes first.

        H starts on its rising boundary there (far up its top line) and falls
        to ``v[0]``: exactly the falling boundary at ``v[0]``, for any family
        whose branches are monotone. The extra output sample is dropped.
        """
        if not self.falling:
            return v
        far = float(np.max(v)) + 1e3 * max(float(np.ptp(v)), 1.0)
        return np.ascontiguousarray(np.concatenate(([far], v)))

    @property
    def names(self) -> tuple[str, ...]:
        """Parameter names in vector order."""
        return chain_names(self.channel, self.family)

    @property
    def units(self) -> tuple[str, ...]:
        """Unit of each parameter (see :func:`param_units`)."""
        units = param_units(self.family)
        return tuple(units[n] for n in self.names)

    @property
    def n_params(self) -> int:
        """Number of searched parameters."""
        return len(self.names)

    @property
    def n_h(self) -> int:
        """Number of H's parameters (they come first)."""
        return self.family.n_params

    @property
    def backlash_slice(self) -> slice:
        """Where ``m_bl, c_bl, c_br`` sit in a parameter vector."""
        return slice(self.n_h, self.n_h + 3)

    @property
    def sensor_slice(self) -> slice:
        """Where the sensor's parameters sit (empty for position)."""
        return slice(self.n_h + 3, self.n_params)

    @property
    def profiled(self) -> bool:
        """Whether the affine calibration is fitted per candidate."""
        return self.calibration is None

    def with_bounds(self, bounds: Mapping[str, tuple[float, float]] | np.ndarray,
                    source: str = 'given') -> ChainSpec:
        """Return a copy with some or all search domains replaced."""
        return replace(self, bounds=_bounds_array(self.names, bounds, self.bounds, self.channel),
                       domain_source=source)

    def feasible(self, pop: np.ndarray) -> np.ndarray:
        """Boolean mask of the rows of ``pop`` that satisfy every constraint."""
        pop = np.ascontiguousarray(np.atleast_2d(pop), dtype=np.float64)
        nh = self.n_h
        return _rows_feasible(self.family, np.ascontiguousarray(pop[:, :nh]),
                              np.ascontiguousarray(pop[:, nh:]), self.domain_source == 'paper',
                              self.proper)

    def cost_function(self, t_s: np.ndarray, command: np.ndarray,
                      measurement: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """Vectorised cost J for a recording: ``(n, m)`` population -> ``(n,)``."""
        v = np.ascontiguousarray(command, dtype=np.float64)
        y = np.ascontiguousarray(measurement, dtype=np.float64)
        dt, uniform = intervals_and_uniform(t_s)
        kind = _KIND[self.channel]
        profile = self.profiled
        k, b = (1.0, 0.0) if profile else self.calibration
        nh, family = self.n_h, self.family
        block = max(1, _BLOCK_VALUES // max(1, v.shape[0]))
        v_h, falling, hold_after = self._h_command(v), self.falling, self.hold == 'after'
        paper_frame, proper = self.domain_source == 'paper', self.proper

        def cost(pop: np.ndarray) -> np.ndarray:
            pop = np.ascontiguousarray(np.atleast_2d(pop), dtype=np.float64)
            costs = np.empty(pop.shape[0])
            for a in range(0, pop.shape[0], block):
                rows = pop[a:a + block]
                h = np.ascontiguousarray(rows[:, :nh])
                tail = np.ascontiguousarray(rows[:, nh:])
                ok = _rows_feasible(family, h, tail, paper_frame, proper)
                u = np.empty((rows.shape[0], v_h.shape[0]))
                family.simulate_rows(h, v_h, ok, u)
                if falling:
                    u = np.ascontiguousarray(u[:, 1:])
                tail_costs(u, tail, ok, kind, y, dt, uniform, falling, hold_after, profile,
                           k, b, costs[a:a + block])
            return costs

        return cost

    def signal(self, params: np.ndarray, t_s: np.ndarray, command: np.ndarray, *,
               validate: bool = True) -> np.ndarray:
        """Pre-calibration chain output ``s`` (sensor output in H's units).

        ``validate=False`` skips :meth:`check`, for a caller that has already
        found ``params`` feasible (:meth:`feasible` implies every rule of it).
        """
        p = self.check(params) if validate else np.ascontiguousarray(params, dtype=np.float64)
        v = np.ascontiguousarray(command, dtype=np.float64)
        return self._signal(p, self._h_command(v), intervals_and_uniform(t_s), v.shape[0])

    def _signal(self, p: np.ndarray, v_h: np.ndarray, intervals: tuple[np.ndarray, bool],
                n: int) -> np.ndarray:
        return self._tail(self.family.simulate(p[:self.n_h], v_h, validate=False), p, intervals,
                          n)

    def _tail(self, u: np.ndarray, p: np.ndarray, intervals: tuple[np.ndarray, bool],
              n: int) -> np.ndarray:
        """B and the sensor after H's output ``u`` (its extra first sample dropped if falling)."""
        out = np.empty(n)
        tail_signal(np.ascontiguousarray(u[1:] if self.falling else u),
                    np.ascontiguousarray(p[self.n_h:]), _KIND[self.channel], *intervals,
                    self.falling, self.hold == 'after', out)
        return out

    def _minus_calibrated(self, s: np.ndarray, y: np.ndarray) -> np.ndarray:
        k, b = fit_affine(s, y)[:2] if self.profiled else self.calibration
        return y - (k * s + b)

    def residual(self, params: np.ndarray, t_s: np.ndarray, command: np.ndarray,
                 measurement: np.ndarray) -> np.ndarray:
        """Measurement minus chain output, with the calibration profiled if it is."""
        s = self.signal(params, t_s, command)
        return self._minus_calibrated(s, np.ascontiguousarray(measurement, dtype=np.float64))

    def residual_function(self, t_s: np.ndarray, command: np.ndarray,
                          measurement: np.ndarray) -> ChainResiduals:
        """:meth:`residual` on one recording, for parameters already found :meth:`feasible`.

        What every call shares (sample intervals, H's command) is computed once
        and nothing is validated: the function a least-squares loop calls after
        its own feasibility test. Returns the same numbers as :meth:`residual`;
        :meth:`ChainResiduals.rows` gives them for many sets with H run once.
        """
        return ChainResiduals(self, t_s, command, measurement)

    def fit_calibration(self, params: np.ndarray, t_s: np.ndarray, command: np.ndarray,
                        measurement: np.ndarray) -> tuple[float, float]:
        """Calibration ``(k, b)`` for ``params``: fitted if profiled, else the fixed one."""
        if not self.profiled:
            return self.calibration
        s = self.signal(params, t_s, command)
        k, b, _ = fit_affine(s, np.ascontiguousarray(measurement, dtype=np.float64))
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
                f'{self.channel} chain ({self.family.id}) needs {self.n_params} parameters '
                f'{self.names}, got {p.shape[0]}')
        if not np.all(np.isfinite(p)):
            raise InvalidParametersError('parameters must be finite')
        if self.proper:
            self.family.check(p[:self.n_h])
        else:
            self.family.check_simulable(p[:self.n_h])
        check_backlash(p[self.backlash_slice])
        sensor = p[self.sensor_slice]
        if self.channel == 'pressure' and sensor[0] < 0:
            raise InvalidParametersError('tau_s must be >= 0')
        if self.channel == 'flow' and (sensor[0] < 0 or sensor[1] < 0):
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


class ChainResiduals:
    """:meth:`ChainSpec.residual` of feasible sets on one recording (see ``residual_function``)."""

    def __init__(self, spec: ChainSpec, t_s: np.ndarray, command: np.ndarray,
                 measurement: np.ndarray) -> None:
        self.spec = spec
        self.v = np.ascontiguousarray(command, dtype=np.float64)
        self.y = np.ascontiguousarray(measurement, dtype=np.float64)
        self.v_h, self.intervals = spec._h_command(self.v), intervals_and_uniform(t_s)

    def __call__(self, params: np.ndarray) -> np.ndarray:
        """Residual of one feasible set."""
        p = np.ascontiguousarray(params, dtype=np.float64)
        s = self.spec._signal(p, self.v_h, self.intervals, self.v.shape[0])
        return self.spec._minus_calibrated(s, self.y)

    def rows(self, pop: np.ndarray, ok: np.ndarray) -> list[np.ndarray | None]:
        """Residual of each row of ``pop`` with ``ok`` true (``None`` for the others).

        H runs once over the rows (its kernel takes each row alone, so every
        residual has the bits of :meth:`__call__`); the rest row by row.
        """
        spec = self.spec
        pop = np.ascontiguousarray(pop, dtype=np.float64)
        u = np.empty((pop.shape[0], self.v_h.shape[0]))
        spec.family.simulate_rows(np.ascontiguousarray(pop[:, :spec.n_h]), self.v_h,
                                  np.ascontiguousarray(ok, dtype=np.bool_), u)
        n = self.v.shape[0]
        return [spec._minus_calibrated(spec._tail(u[i], pop[i], self.intervals, n), self.y)
                if ok[i] else None for i in range(pop.shape[0])]


def _bounds_array(names: tuple[str, ...], bounds, base: np.ndarray | None,
                  channel: str) -> np.ndarray:
    if isinstance(bounds, Mapping):
        if base is None:
            raise ConfigError('bounds by name need a base table')
        out = np.array(base, dtype=float)
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
               calibration: tuple[float, float] | None = None,
               family: str | HysteresisFamily | None = None,
               initial: str = 'rising') -> ChainSpec:
    """Build the spec of a channel's chain.

    Parameters
    ----------
    channel : str
        ``position``, ``pressure`` or ``flow``.
    domains : mapping, optional
        Search domains by parameter name. With the ``tk`` family the others
        are the paper's; another family has no paper domains, so its H
        domains must all be given (or derived from the data:
        :func:`hyst_id.identification.domains.domains_from_data`).
    calibration : tuple of float, optional
        Fixed ``(k, b)``; default profiled (fitted per candidate), for position
        too (no freedom added; the search runs in any measurement units).
    family : str or HysteresisFamily, optional
        The hysteresis family (default ``tk``, the paper's).
    initial : {'rising', 'falling'}
        State at the first sample (:attr:`ChainSpec.initial`).
    """
    fam = get_family(family)
    names = chain_names(channel, fam)
    preset = {**dict(fam.paper_domains or {}), **TAIL_PAPER_DOMAINS}
    base = np.array([preset.get(n, (-1.0, 1.0)) for n in names], dtype=float)
    spec = ChainSpec(channel=channel, bounds=base, calibration=calibration, family=fam,
                     initial=initial)
    if domains:
        spec = spec.with_bounds(domains, source='given')
    return spec
