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

"""In-line inverse compensation: desired output -> B^-1 -> H^-1 -> command.

The :class:`Compensator` keeps its own copy of the model state (last command
``v``, hysteresis output ``u`` and backlash output ``y``) and advances it
with the command it actually emits, after command limits, so the model
never drifts from what the actuator was sent. Parameters are in the
canonical gauge (:mod:`hyst_id.identification.gauge`): the hysteresis output
is in the measurement's units and the backlash has unit slope, so the
desired value is given in the measured channel's units. Sensor dynamics are
not inverted (as in the paper). H is any registered hysteresis family
(:mod:`hyst_id.models.registry`); each brings its exact inverse.

Parameter sets are immutable :class:`InverseModel` objects: swapping one in
is a single reference assignment (model and inverse state together), so an
update applies atomically between two samples.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Mapping

import numpy as np

from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.models.backlash import (
    backlash_inverse_step,
    BACKLASH_NAMES,
    backlash_step,
    check_backlash,
)
from hyst_id.models.family import HysteresisFamily, HysteresisInverse
from hyst_id.models.registry import DEFAULT_FAMILY, get_family

__all__ = ['InverseModel', 'CommandLimits', 'Compensator', 'warm_up']


@dataclass(frozen=True)
class InverseModel:
    """A validated hysteresis + backlash parameter set (canonical gauge).

    ``output_sign`` is the canonical calibration gain: -1 when the measured
    channel falls as the actuator output rises (the model then works on the
    negated measurement). ``family`` is H's family id (``tk``: the paper's).
    """

    hysteresis: tuple[float, ...]
    backlash: tuple[float, float, float]
    output_sign: float = 1.0
    family: str = DEFAULT_FAMILY

    @property
    def h_family(self) -> HysteresisFamily:
        """H's family object."""
        return get_family(self.family)

    @classmethod
    def names(cls, family: str | None = None) -> tuple[str, ...]:
        """Parameter names of a set: H's (per family), then the backlash's."""
        return tuple(get_family(family).names) + BACKLASH_NAMES

    @classmethod
    def from_mapping(cls, values: Mapping[str, float]) -> InverseModel:
        """Build from ``family`` (default tk), H's names, ``m_bl, c_bl, c_br``, ``output_sign``.

        Raises
        ------
        InvalidParametersError
            Unknown family, missing or non-numeric values, a set the family refuses.
        """
        try:
            family = get_family(str(values.get('family', DEFAULT_FAMILY)))
        except ConfigError as exc:
            raise InvalidParametersError(str(exc)) from None
        names = tuple(family.names) + BACKLASH_NAMES
        missing = [n for n in names if n not in values]
        if missing:
            raise InvalidParametersError(f'missing parameters: {", ".join(missing)}')
        try:
            h = family.check([float(values[n]) for n in family.names])
            b = check_backlash([float(values[n]) for n in BACKLASH_NAMES])
            sign = float(values.get('output_sign', 1.0))
        except (TypeError, ValueError) as exc:
            raise InvalidParametersError(f'parameters must be numbers: {exc}') from None
        if sign not in (1.0, -1.0):
            raise InvalidParametersError(f'output_sign must be +1 or -1, got {sign}')
        return cls(tuple(float(x) for x in h), (float(b[0]), float(b[1]), float(b[2])), sign,
                   family.id)

    @classmethod
    def from_vector(cls, params: np.ndarray, output_sign: float = 1.0,
                    family: str | None = None) -> InverseModel:
        """Build from a chain vector (H's parameters, then B's; sensor ones ignored)."""
        fam = get_family(family)
        nh = fam.n_params
        p = np.asarray(params, dtype=float).ravel()
        if p.shape[0] < nh + 3:
            raise InvalidParametersError(f'need at least {nh + 3} parameters (H and B)')
        if output_sign not in (1.0, -1.0):
            raise InvalidParametersError(f'output_sign must be +1 or -1, got {output_sign}')
        return cls(tuple(float(x) for x in fam.check(p[:nh])),
                   tuple(float(x) for x in check_backlash(p[nh:nh + 3])), float(output_sign),
                   fam.id)

    def as_mapping(self) -> dict[str, float | str]:
        """Name -> value (with ``family`` and ``output_sign``), as params files hold them."""
        out: dict[str, float | str] = dict(zip(self.names(self.family),
                                               self.hysteresis + self.backlash))
        out['output_sign'] = self.output_sign
        out['family'] = self.family
        return out

    def inverse(self) -> HysteresisInverse:
        """A fresh inverse of H with its own state."""
        return self.h_family.inverse(np.asarray(self.hysteresis, dtype=float))


@dataclass(frozen=True)
class CommandLimits:
    """Limits on the emitted command: range (command units) and rate (units/s)."""

    min_command: float = -math.inf
    max_command: float = math.inf
    max_rate_per_s: float = math.inf

    def __post_init__(self) -> None:
        if not self.min_command < self.max_command:
            raise InvalidParametersError('command limits need min_command < max_command')
        if not self.max_rate_per_s > 0:
            raise InvalidParametersError('max_rate_per_s must be positive')


class Compensator:
    """Sample-by-sample inverse of backlash then hysteresis, with its own state.

    Parameters
    ----------
    model : InverseModel or None
        Parameters; ``None`` passes the desired value through unchanged.
    limits : CommandLimits, optional
        Range and rate limits applied to every emitted command.
    v0 : float
        Command the actuator holds before the first sample.
    """

    def __init__(self, model: InverseModel | None, limits: CommandLimits | None = None,
                 v0: float = 0.0) -> None:
        self.limits = limits or CommandLimits()
        #: True: pass the desired value through (within the limits) while the model
        #: state keeps following the commands sent, so that ending the bypass resumes
        #: from the actuator's real state.
        self.bypass = False
        self._active: tuple[InverseModel | None, HysteresisInverse | None] = (model, None)
        self._t_prev: float | None = None
        self.reset(v0)

    @property
    def model(self) -> InverseModel | None:
        """The parameter set in use (``None``: pass-through)."""
        return self._active[0]

    @property
    def state(self) -> tuple[float, float, float]:
        """Model state ``(v, u, y)``: last command, H output, backlash output."""
        return self._v, self._u, self._y

    def reset(self, v0: float) -> None:
        """Put the model state on the rising boundary at command ``v0``."""
        self._v = float(v0)
        self._t_prev = None
        model = self._active[0]
        if model is None:
            self._u = self._y = float(v0)
            self._active = (None, None)
            return
        inv = model.inverse()
        inv.reset(self._v)
        self._u = inv.output
        m_bl, c_bl, c_br = model.backlash
        self._y = m_bl * (self._u - c_br)
        self._active = (model, inv)

    def set_model(self, model: InverseModel | None) -> None:
        """Swap the parameter set between samples, keeping a consistent state.

        The current command is kept; the hysteresis and backlash outputs are
        projected into the new model's loop at that command.
        """
        if model is None:
            self._active = (None, None)
            return
        inv = model.inverse()
        inv.reset(self._v, self._u)
        self._u = inv.output
        m_bl, c_bl, c_br = model.backlash
        self._y = min(max(self._y, m_bl * (self._u - c_br)), m_bl * (self._u - c_bl))
        self._active = (model, inv)

    def step(self, desired: float, t_s: float | None = None) -> float:
        """Command for one desired output sample.

        Parameters
        ----------
        desired : float
            Desired output, in the measured channel's units.
        t_s : float, optional
            Sample time in seconds, needed for the rate limit.

        Returns
        -------
        float
            Command to send to the actuator (within the limits).
        """
        model, inv = self._active
        if model is not None:
            m_bl, c_bl, c_br = model.backlash
        if not math.isfinite(desired):
            v = math.nan                        # held: a non-finite value is never sent
        elif model is None or self.bypass:
            v = float(desired)
        else:
            target = model.output_sign * desired
            u_d = backlash_inverse_step(target, self._y, self._u, m_bl, c_bl, c_br)
            v = inv.command_for(u_d)
            if not math.isfinite(v) and not math.isnan(u_d):
                # a finite desired value far beyond the loop (1e308) overflows the inverse:
                # toward the limit on its side, as a reachable-but-large one goes
                v = math.inf if u_d > self._u else -math.inf
        v = self._limit(v, t_s)
        if model is not None:
            self._u = inv.advance(v)
            self._y = backlash_step(self._u, self._y, m_bl, c_bl, c_br)
        self._v = v
        return v

    def _limit(self, v: float, t_s: float | None) -> float:
        lim = self.limits
        if math.isnan(v):
            v = self._v
        if t_s is not None and math.isfinite(lim.max_rate_per_s):
            # the first sample after a reset starts from the held command: no time has
            # passed for the actuator to move (a 6 mA jump got through here before)
            elapsed = 0.0 if self._t_prev is None else max(t_s - self._t_prev, 0.0)
            dv_max = lim.max_rate_per_s * elapsed
            v = min(max(v, self._v - dv_max), self._v + dv_max)
        if t_s is not None:
            self._t_prev = t_s
        v = min(max(v, lim.min_command), lim.max_command)
        return v if math.isfinite(v) else self._v     # an infinite side without a limit

    def run(self, desired: np.ndarray, t_s: np.ndarray | None = None) -> np.ndarray:
        """Commands for a whole desired sequence (convenience over :meth:`step`)."""
        out = np.empty(len(desired))
        for j, d in enumerate(desired):
            out[j] = self.step(float(d), None if t_s is None else float(t_s[j]))
        return out


def warm_up(model: InverseModel, n_samples: int = 16) -> None:
    """Run a throwaway compensator over a short sweep so that its kernels are compiled.

    The first call of a numba kernel compiles it (or loads it from the
    cache), which can take seconds; a node calls this before it applies a
    new parameter set so that the first real sample is not late.
    """
    comp = Compensator(model, v0=0.0)
    for desired in np.linspace(-1.0, 1.0, n_samples):
        comp.step(float(desired), None)
