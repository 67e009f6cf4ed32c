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
canonical gauge (:mod:`hyst_id.identification.gauge`): the hysteresis output is in the
measurement's units and the backlash has unit slope, so the desired value
is given in the measured channel's units. Sensor dynamics are not inverted
(as in the paper).

Parameter sets are immutable :class:`InverseModel` objects: swapping one in
is a single reference assignment, so an update applies atomically between
two samples.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Mapping

import numpy as np

from hyst_id.errors import InvalidParametersError
from hyst_id.models.backlash import backlash_inverse_step, backlash_step, check_backlash
from hyst_id.models.tk import (
    check_hysteresis,
    hysteresis_inverse_step,
    HYSTERESIS_NAMES,
    hysteresis_step,
    initial_output,
)

__all__ = ['InverseModel', 'CommandLimits', 'Compensator']


@dataclass(frozen=True)
class InverseModel:
    """A validated hysteresis + backlash parameter set (canonical gauge).

    ``output_sign`` is the canonical calibration gain: -1 when the measured
    channel falls as the actuator output rises (the model then works on the
    negated measurement).
    """

    hysteresis: tuple[float, ...]
    backlash: tuple[float, float, float]
    output_sign: float = 1.0

    @classmethod
    def from_mapping(cls, values: Mapping[str, float]) -> 'InverseModel':
        """Build from ``m_l ... c_b, m_bl, c_bl, c_br``; raise InvalidParametersError."""
        missing = [n for n in HYSTERESIS_NAMES + ('m_bl', 'c_bl', 'c_br') if n not in values]
        if missing:
            raise InvalidParametersError(f'missing parameters: {", ".join(missing)}')
        try:
            h = check_hysteresis([float(values[n]) for n in HYSTERESIS_NAMES])
            b = check_backlash([float(values[n]) for n in ('m_bl', 'c_bl', 'c_br')])
            sign = float(values.get('output_sign', 1.0))
        except (TypeError, ValueError) as exc:
            raise InvalidParametersError(f'parameters must be numbers: {exc}') from None
        if sign not in (1.0, -1.0):
            raise InvalidParametersError(f'output_sign must be +1 or -1, got {sign}')
        return cls(tuple(float(x) for x in h), (float(b[0]), float(b[1]), float(b[2])), sign)

    @classmethod
    def from_vector(cls, params: np.ndarray, output_sign: float = 1.0) -> 'InverseModel':
        """Build from a chain vector (first 11 entries: H then B)."""
        p = np.asarray(params, dtype=float).ravel()
        if p.shape[0] < 11:
            raise InvalidParametersError('need at least 11 parameters (H and B)')
        if output_sign not in (1.0, -1.0):
            raise InvalidParametersError(f'output_sign must be +1 or -1, got {output_sign}')
        return cls(tuple(float(x) for x in check_hysteresis(p[:8])),
                   tuple(float(x) for x in check_backlash(p[8:11])), float(output_sign))

    def output_range(self, v: float) -> tuple[float, float]:
        """Lowest and highest H output reachable at command ``v`` (loop boundaries)."""
        m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = self.hysteresis
        lower = initial_output(v, m_r, m_t, m_b, c_r, c_t, c_b)
        upper = max(min(m_t * v + c_t, m_l * (v - c_l)), m_b * v + c_b)
        return lower, upper


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
        self._model = model
        self._t_prev: float | None = None
        self.reset(v0)

    @property
    def model(self) -> InverseModel | None:
        """The parameter set in use (``None``: pass-through)."""
        return self._model

    @property
    def state(self) -> tuple[float, float, float]:
        """Model state ``(v, u, y)``: last command, H output, backlash output."""
        return self._v, self._u, self._y

    def reset(self, v0: float) -> None:
        """Put the model state on the rising boundary at command ``v0``."""
        self._v = float(v0)
        self._t_prev = None
        if self._model is None:
            self._u = self._y = float(v0)
            return
        m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = self._model.hysteresis
        m_bl, c_bl, c_br = self._model.backlash
        self._u = initial_output(self._v, m_r, m_t, m_b, c_r, c_t, c_b)
        self._y = m_bl * (self._u - c_br)

    def set_model(self, model: InverseModel | None) -> None:
        """Swap the parameter set between samples, keeping a consistent state.

        The current command is kept; the hysteresis and backlash outputs are
        projected into the new model's loop at that command.
        """
        if model is not None:
            lower, upper = model.output_range(self._v)
            self._u = min(max(self._u, lower), upper)
            m_bl, c_bl, c_br = model.backlash
            self._y = min(max(self._y, m_bl * (self._u - c_br)), m_bl * (self._u - c_bl))
        self._model = model

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
        model = self._model
        if model is None:
            v = float(desired)
        else:
            m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = model.hysteresis
            m_bl, c_bl, c_br = model.backlash
            target = model.output_sign * desired
            u_d = backlash_inverse_step(target, self._y, self._u, m_bl, c_bl, c_br)
            v = hysteresis_inverse_step(u_d, self._v, self._u,
                                        m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
        v = self._limit(v, t_s)
        if model is not None:
            self._u = hysteresis_step(v, self._v, self._u, m_l, m_r, m_t, m_b, c_l, c_r,
                                      c_t, c_b)
            self._y = backlash_step(self._u, self._y, m_bl, c_bl, c_br)
        self._v = v
        return v

    def _limit(self, v: float, t_s: float | None) -> float:
        lim = self.limits
        if not math.isfinite(v):
            v = self._v
        if t_s is not None and self._t_prev is not None and math.isfinite(lim.max_rate_per_s):
            dv_max = lim.max_rate_per_s * max(t_s - self._t_prev, 0.0)
            v = min(max(v, self._v - dv_max), self._v + dv_max)
        if t_s is not None:
            self._t_prev = t_s
        return min(max(v, lim.min_command), lim.max_command)

    def run(self, desired: np.ndarray, t_s: np.ndarray | None = None) -> np.ndarray:
        """Commands for a whole desired sequence (convenience over :meth:`step`)."""
        out = np.empty(len(desired))
        for j, d in enumerate(desired):
            out[j] = self.step(float(d), None if t_s is None else float(t_s[j]))
        return out
