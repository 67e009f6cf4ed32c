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

"""Adaptive compensation: track the plant's slow gain and offset while compensating.

The identified H⁻¹ is right for the plant it was identified on; a supply
running down, a drifting gain or a drifting sensor offset then make the same
command give a different reading. Between identifications these slow
changes are tracked as an affine map of the model's own prediction,

``y_measured ~ gain * (y_predicted - centre) + centre + offset + rate * (t - t_now)``,

where ``y_predicted`` is the nominal chain's reading for the commands
actually sent (the compensator's model output through the identified sensor
dynamics, :class:`SensorPredictor`). ``gain`` and ``offset`` come from
recursive least squares with exponential forgetting (time constant
``forget_time_s``) and the compensator is asked for
``(desired - centre - offset) / gain + centre`` instead of ``desired``. The
``rate`` term (a local linear trend of the offset) removes the lag a
forgetting estimator has on a steady drift (about ``forget_time_s`` times
the drift rate without it: measured on the drifting-plant test, three times
the late error).

Acceptance: the correction is applied only once the estimate has taken
:data:`MIN_UPDATES` samples (before, it rests on too few: on the paper
rig's compensation run, a sample each 0.5 s, a correction applied after 13
samples held an offset of 8 kPa that was gone 8 samples later), only while it predicts the recent
readings clearly better than the nominal model does (exponentially weighted
a-priori squared error below :data:`ACCEPT_RATIO` x the nominal model's),
and while the gain is inside its bounds (an estimate pinned at a bound is
not believed): a tracker fed by a prediction that does not describe the
plant (wrong sensor dynamics) then leaves the inverse alone.

Guards: the estimate is frozen (no update, no forgetting) while the command
sits at a limit or the prediction has not moved by ``min_excitation`` over
the last ``forget_time_s`` (a flat stretch says nothing about a gain), and
the gain stays within ``gain_bounds``. Every change of state (tracking,
frozen and why, a gain clipped) is an event with its time and reason.

May import: numpy, :mod:`hyst_id.compensation.inverse`, :mod:`hyst_id.models`.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
import math

import numpy as np

from hyst_id.compensation.inverse import Compensator
from hyst_id.errors import InvalidParametersError
from hyst_id.models.sensors import first_order_coefficient, second_order_coefficients

__all__ = ['ACCEPT_RATIO', 'AdaptiveCompensator', 'GainOffsetTracker', 'MIN_UPDATES',
           'SensorPredictor', 'TrackerEvent']

#: Recent squared error of the tracked model / the nominal model's below which it is used.
ACCEPT_RATIO = 0.5
#: Samples an estimate must have taken before its correction is applied.
MIN_UPDATES = 40


class SensorPredictor:
    """The identified sensor dynamics, advanced one interval at a time.

    Parameters
    ----------
    kind : {'none', 'first_order', 'second_order'}
        Position: none; pressure: first-order ``tau_s``; flow: second-order
        ``zeta, omega_n_rad_s``.
    params : sequence of float
        The sensor's parameters in that order.
    hold : {'before', 'after'}
        As :attr:`hyst_id.identification.chains.ChainSpec.hold`: a sample's
        input is held over the interval before it (it acts on its own
        reading) or after it (a reading sees the previous sample's input).
    """

    KINDS = {'none': 0, 'first_order': 1, 'second_order': 2}
    CHANNEL_KIND = {'position': 'none', 'pressure': 'first_order', 'flow': 'second_order'}

    def __init__(self, kind: str = 'none', params: tuple[float, ...] = (),
                 hold: str = 'before') -> None:
        if hold not in ('before', 'after'):
            raise InvalidParametersError(f"hold must be 'before' or 'after', got {hold!r}")
        if kind not in self.KINDS or len(params) != self.KINDS[kind]:
            raise InvalidParametersError(f'sensor {kind!r} needs {self.KINDS.get(kind, "?")} '
                                         f'parameters, got {len(params)}')
        if any(not (math.isfinite(p) and p > 0) for p in params):
            raise InvalidParametersError(f'sensor parameters must be finite and > 0: {params}')
        self.kind = kind
        self.params = tuple(float(p) for p in params)
        self.hold = hold
        self._x: float | None = None
        self._u_prev: float | None = None
        self._xd = 0.0

    @classmethod
    def for_channel(cls, channel: str, params: tuple[float, ...] = (),
                    hold: str = 'before') -> SensorPredictor:
        """The sensor of a chain channel with its identified parameters."""
        return cls(cls.CHANNEL_KIND[channel], params, hold)

    def advance(self, u: float, dt_s: float) -> float:
        """Reading ``dt_s`` seconds on, ``u`` being this sample's sensor input."""
        if self.hold == 'after' and self._u_prev is not None:
            u, self._u_prev = self._u_prev, float(u)
        else:
            self._u_prev = float(u)
        if self._x is None or self.kind == 'none':
            self._x = float(u)
            return self._x
        if self.kind == 'first_order':
            a = first_order_coefficient(dt_s, self.params[0])
            self._x = a * self._x + (1.0 - a) * u
            return self._x
        p11, p12, p21, p22 = second_order_coefficients(dt_s, self.params[0], self.params[1])
        e = self._x - u
        self._x, self._xd = u + p11 * e + p12 * self._xd, p21 * e + p22 * self._xd
        return self._x


@dataclass(frozen=True)
class TrackerEvent:
    """A change of the tracker's state: when, what, why."""

    t_s: float
    state: str
    reason: str
    gain: float
    offset: float


@dataclass
class GainOffsetTracker:
    """Recursive least squares for ``y = gain (p - centre) + centre + offset + trend``.

    Parameters
    ----------
    forget_time_s : float
        Time constant of the exponential forgetting: how far back the estimate looks.
    min_excitation : float
        Range of the prediction over the last ``forget_time_s`` below which
        the estimate is frozen, in the channel's units.
    gain_bounds : tuple of float
        Limits of the gain.
    centre : float or None
        Reference level (default: the first prediction).
    """

    forget_time_s: float = 20.0
    min_excitation: float = 0.0
    gain_bounds: tuple[float, float] = (0.25, 4.0)
    centre: float | None = None
    gain: float = 1.0
    offset: float = 0.0
    events: list[TrackerEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not (self.forget_time_s > 0 and self.min_excitation >= 0
                and 0 < self.gain_bounds[0] < 1 < self.gain_bounds[1]):
            raise InvalidParametersError('tracker needs forget_time_s > 0, min_excitation >= 0 '
                                         'and gain bounds lo < 1 < hi')
        self._p = np.eye(3) * 1e3
        self.rate_per_s = 0.0
        self._t_ref: float | None = None
        self._recent: deque[tuple[float, float]] = deque()
        self._state = 'waiting'
        self._t_prev: float | None = None
        self._clipped = False
        self._sse = np.zeros(2)       # weighted squared a-priori errors: nominal, tracked
        self.n_updates = 0            # samples the estimate has taken (excited, free)
        self.applied = False

    @property
    def state(self) -> str:
        """``'waiting'``, ``'tracking'`` or ``'frozen'``."""
        return self._state

    def _set_state(self, t_s: float, state: str, reason: str) -> None:
        if state != self._state:
            self._state = state
            self.events.append(TrackerEvent(t_s, state, reason, self.gain, self.offset))

    def offset_at(self, t_s: float) -> float:
        """The offset extrapolated to ``t_s`` along the tracked trend."""
        if self._t_ref is None:
            return self.offset
        return self.offset + self.rate_per_s * (t_s - self._t_ref)

    def correct(self, desired: float, t_s: float | None = None) -> float:
        """What to ask the nominal model for so that the plant gives ``desired`` at ``t_s``."""
        if self.centre is None or not self.applied:
            return float(desired)
        offset = self.offset if t_s is None else self.offset_at(t_s)
        return (float(desired) - self.centre - offset) / self.gain + self.centre

    def update(self, t_s: float, predicted: float, measured: float,
               saturated: bool = False) -> None:
        """Take one measured sample and the nominal model's prediction for it."""
        if not (math.isfinite(predicted) and math.isfinite(measured)):
            self._set_state(t_s, 'frozen', 'non-finite sample')
            return
        if self.centre is None:
            self.centre = float(predicted)
        dt = 0.0 if self._t_prev is None else max(t_s - self._t_prev, 0.0)
        self._t_prev = t_s
        self._recent.append((t_s, predicted))
        while self._recent and self._recent[0][0] < t_s - self.forget_time_s:
            self._recent.popleft()
        span = max(p for _, p in self._recent) - min(p for _, p in self._recent)
        if saturated:
            self._set_state(t_s, 'frozen', 'command at a limit')
            return
        if span <= self.min_excitation:
            self._set_state(t_s, 'frozen', f'prediction moved {span:.3g} <= '
                                           f'{self.min_excitation:.3g} (no excitation)')
            return
        lam = math.exp(-dt / self.forget_time_s)
        self.n_updates += 1
        # the trend's origin moves with time: re-express (offset, rate) at t_s
        self.offset = self.offset_at(t_s)
        self._t_ref = t_s
        # the rate is carried per forget_time_s for a well-conditioned P
        theta = np.array([self.gain, self.offset, self.rate_per_s * self.forget_time_s])
        phi = np.array([predicted - self.centre, 1.0, 0.0])
        shift = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, dt / self.forget_time_s],
                          [0.0, 0.0, 1.0]])
        self._p = shift @ self._p @ shift.T
        err = measured - self.centre - phi @ theta
        self._sse = lam * self._sse + np.array([(measured - predicted) ** 2, err ** 2])
        p_phi = self._p @ phi
        k = p_phi / (lam + phi @ p_phi)
        gain, offset, rate = theta + k * err
        self._p = (self._p - np.outer(k, p_phi)) / lam
        self.rate_per_s = float(rate) / self.forget_time_s
        lo, hi = self.gain_bounds
        clipped = not lo <= gain <= hi
        if clipped and not self._clipped:       # logged when it starts, not every sample
            self.events.append(TrackerEvent(t_s, self._state, f'gain {gain:.3g} clipped to '
                                            f'[{lo:g}, {hi:g}]', self.gain, self.offset))
        self._clipped = clipped
        gain = min(max(gain, lo), hi)
        self.gain, self.offset = float(gain), float(offset)
        self._accept(t_s)
        self._set_state(t_s, 'tracking', 'excited and within limits')

    def _accept(self, t_s: float) -> None:
        """Apply the correction only while it predicts clearly better and is not clipped."""
        ratio = self._sse[1] / max(self._sse[0], 1e-300)
        young = self.n_updates < MIN_UPDATES
        applied = bool(ratio < ACCEPT_RATIO and not self._clipped and not young)
        if applied != self.applied:
            why = ('gain at its bound' if self._clipped else
                   f'recent error of the tracked model {ratio:.2f} x that of the nominal one')
            self.events.append(TrackerEvent(
                t_s, self._state, f'correction {"applied" if applied else "withheld"}: {why}',
                self.gain, self.offset))
            self.applied = applied


class AdaptiveCompensator:
    """A :class:`Compensator` whose desired value is corrected by a :class:`GainOffsetTracker`.

    Call :meth:`step` with each desired sample (returns the command), then
    :meth:`observe` with the reading that command produced.

    The compensator may be an
    :class:`~hyst_id.compensation.augment.AugmentedCompensator` (what a
    diagnosis found, in-line): the prediction is then the augmented model's
    (its output map and schedules at the reading's time, the model output
    sent its dead time before), so the tracker follows only what the
    schedules leave, and its correction is asked of the augmented model.
    """

    def __init__(self, compensator: Compensator, tracker: GainOffsetTracker,
                 sensor: SensorPredictor) -> None:
        self.compensator = compensator
        self.tracker = tracker
        self.sensor = sensor
        self._nominal: float | None = None
        self._sent: deque[tuple[float, float]] = deque()   # (t_s, model output) still due
        self._saturated = False
        self._t_cmd: float | None = None
        self._t_obs: float | None = None

    @property
    def dead_time_s(self) -> float:
        """How long before a reading the model output it is compared with was sent."""
        aug = getattr(self.compensator, 'augmentation', None)
        return 0.0 if aug is None else float(aug.dead_time_s)

    def step(self, desired: float, t_s: float) -> float:
        """Command for one desired sample at ``t_s``."""
        v = self.compensator.step(self.tracker.correct(desired, t_s), t_s)
        lim = self.compensator.limits
        self._saturated = v <= lim.min_command or v >= lim.max_command
        model = self.compensator.model
        sign = 1.0 if model is None else model.output_sign
        self._nominal = sign * self.compensator.state[2]
        self._t_cmd = t_s
        if self.dead_time_s > 0.0:
            self._sent.append((t_s, self._nominal))
        return v

    def _due(self, t_s: float) -> float | None:
        """The model output sent a dead time before ``t_s`` (the last one without a delay)."""
        delay = self.dead_time_s
        if delay <= 0.0:
            return self._nominal
        sent, due = self._sent, t_s - delay + 1e-6     # stamps to the microsecond
        while len(sent) > 1 and sent[1][0] <= due:
            sent.popleft()
        if not sent or sent[0][0] > due:
            return None                  # nothing sent that long ago yet
        return sent[0][1]

    def observe(self, measured: float, t_s: float, dt_s: float | None = None) -> float:
        """Update the tracker with the reading at ``t_s``, ``dt_s`` after the previous one.

        ``dt_s`` defaults to the time since the previous :meth:`observe`.
        Returns the nominal prediction the reading was compared with.
        """
        if dt_s is None:
            dt_s = 0.0 if self._t_obs is None else max(t_s - self._t_obs, 0.0)
        self._t_obs = t_s
        nominal = self._due(t_s)
        if nominal is None:
            return float('nan')
        predicted = self.sensor.advance(nominal, dt_s)
        reading = getattr(self.compensator, 'predicted_reading', None)
        if reading is not None:
            predicted = reading(predicted, t_s)
        self.tracker.update(t_s, predicted, measured, self._saturated)
        return predicted
