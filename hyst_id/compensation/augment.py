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

"""The compensator's model augmented with what a diagnosis accepted (issue 17).

:class:`Augmentation` holds in-line corrections around H⁻¹ and B⁻¹, each
from a diagnosis block (``Mechanism.correction``), in the measured channel's
units and seconds:

* ``dead_time_s`` (``dead_time``): the actuator acts ``L`` late, so the
  command at ``t`` is computed for the desired value at ``t + L``, predicted
  by the desired value's slope over the last ``predict_window_s`` (default 0:
  the last two samples; longer averages a noisy desired value but lags by
  half the window): ``d(t + L) ~ d(t) + L d'(t)``.
* a gain schedule (``supply_decay``: ``g = exp(-rate t)``, ``gain_drift``:
  ``g = 1 + rate t``) around ``gain_centre`` (the reading the gain leaves
  unchanged) and an offset ramp (``offset_drift``): the reading is
  ``y = c + g(t) / g_ref (y_model - c) + rate (t - t_ref)`` and the model is
  asked for ``(d - c - rate (t - t_ref)) g_ref / g(t) + c``. ``g_ref`` and
  ``t_ref`` say when the compensator's own H and B hold (a set identified on
  the whole record without the block holds on the record's average gain and
  offset: the defaults :func:`augmentation_from_findings` writes). ``t`` is
  the time since the compensator's first compensated, stamped sample (kept
  across :meth:`AugmentedCompensator.reset`, restarted by
  :meth:`AugmentedCompensator.restart_schedules`): a schedule holds for runs that start
  as the recording did (a supply vessel full again); it is held at its value
  at ``schedule_horizon_s`` (the fitted record's length) beyond that, and
  the gain never falls below :data:`MIN_GAIN`.
* command limits (``saturation``): ``min_command``/``max_command`` at the
  stops.
* an output map (``static_nonlinearity``): the reading is the cubic
  ``poly_c0 + poly_c1 z + poly_c2 z^2 + poly_c3 z^3`` of the model's output
  ``z`` (the diagnosis's travel normalised to [-1, 1] over the record: only
  with the diagnosis's own set, :func:`hyst_id.diagnosis.export.compensator_set`);
  the desired value is mapped back through its inverse (monotone over
  ``|z| <= POLY_RANGE`` or refused). Past the fitted travel (``|z| > 1``) the map
  continues as the straight line of its end slope, not as the cubic
  (:meth:`Augmentation.output_map`).

What has no in-line correction stays in the plant and the diagnosis report
says so (``compensation.how``); the compensator's tracking
(:mod:`hyst_id.compensation.tracking`) follows a drift from the measurement
instead of a fitted schedule.

May import: numpy, :mod:`hyst_id.compensation.inverse`.
"""

from __future__ import annotations

from collections import deque
from dataclasses import asdict, dataclass, fields
import math
from typing import Any, Iterable, Mapping

import numpy as np

from hyst_id.compensation.inverse import CommandLimits, Compensator, InverseModel
from hyst_id.errors import InvalidParametersError

__all__ = ['AUGMENT_PREFIX', 'Augmentation', 'AugmentedCompensator', 'GAIN_LAWS', 'MIN_GAIN',
           'POLY_RANGE', 'augmentation_from_findings', 'cubic_is_monotone']

#: Prefix of the augmentation's keys in a params file (``augment.dead_time_s`` ...).
AUGMENT_PREFIX = 'augment.'
#: Gain laws of a schedule: none, ``exp(-rate t)``, ``1 + rate t``.
GAIN_LAWS = ('none', 'exponential', 'linear')
#: The scheduled gain is never taken below this share of its reference.
MIN_GAIN = 0.05
#: The output map is inverted over ``|z| <= POLY_RANGE`` (the record's travel is [-1, 1]).
POLY_RANGE = 1.25
_IDENTITY_POLY = (0.0, 1.0, 0.0, 0.0)


def cubic_is_monotone(coef: tuple[float, ...], half_range: float) -> bool:
    """Whether ``c0 + c1 z + c2 z^2 + c3 z^3`` is strictly monotone on ``|z| <= half_range``.

    Exact: the slope ``c1 + 2 c2 z + 3 c3 z^2`` is checked at both ends and at
    its vertex when that lies inside.
    """
    c1, c2, c3 = (float(x) for x in coef[1:4])
    zs = [-half_range, half_range]
    if c3 != 0.0 and abs(c2 / (3.0 * c3)) < half_range:
        zs.append(-c2 / (3.0 * c3))
    slopes = [c1 + 2.0 * c2 * z + 3.0 * c3 * z * z for z in zs]
    return all(x > 0 for x in slopes) or all(x < 0 for x in slopes)


@dataclass(frozen=True)
class Augmentation:
    """In-line corrections around H⁻¹ (see the module docstring for each field)."""

    dead_time_s: float = 0.0
    predict_window_s: float = 0.0
    gain_law: str = 'none'
    gain_rate_per_s: float = 0.0
    gain_centre: float = 0.0
    gain_reference: float = 1.0
    offset_rate_per_s: float = 0.0
    offset_reference_s: float = 0.0
    schedule_horizon_s: float = 0.0
    min_command: float = -math.inf
    max_command: float = math.inf
    poly_c0: float = 0.0
    poly_c1: float = 1.0
    poly_c2: float = 0.0
    poly_c3: float = 0.0

    def __post_init__(self) -> None:
        if self.gain_law not in GAIN_LAWS:
            raise InvalidParametersError(f'augment.gain_law must be one of {GAIN_LAWS}, '
                                         f'got {self.gain_law!r}')
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == 'gain_law':
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float)) or math.isnan(v):
                raise InvalidParametersError(f'augment.{f.name} must be a number, got {v!r}')
            if f.name not in ('min_command', 'max_command') and not math.isfinite(v):
                raise InvalidParametersError(f'augment.{f.name} must be finite, got {v!r}')
        if not self.dead_time_s >= 0.0:
            raise InvalidParametersError('augment.dead_time_s must be >= 0')
        if not self.predict_window_s >= 0.0 or not self.schedule_horizon_s >= 0.0:
            raise InvalidParametersError('augment.predict_window_s and '
                                         'augment.schedule_horizon_s must be >= 0')
        if not self.gain_reference > 0.0:
            raise InvalidParametersError('augment.gain_reference must be > 0')
        if not self.min_command < self.max_command:
            raise InvalidParametersError('augment.min_command must be < augment.max_command')
        if self.has_output_map:
            if not cubic_is_monotone(self.poly, POLY_RANGE):
                raise InvalidParametersError(
                    'augment.poly_c0..c3: the output map is not monotone over |z| <= '
                    f'{POLY_RANGE}, so it has no inverse there')

    @property
    def poly(self) -> tuple[float, float, float, float]:
        """The output map's coefficients ``(c0, c1, c2, c3)``."""
        return (self.poly_c0, self.poly_c1, self.poly_c2, self.poly_c3)

    @property
    def has_output_map(self) -> bool:
        """Whether the output map is other than the identity."""
        return self.poly != _IDENTITY_POLY

    def output_map(self, z: float) -> float:
        """The mapped reading of model output ``z``: the cubic over the fitted travel.

        Over ``|z| <= 1`` (the diagnosis's travel) the cubic; beyond, the
        straight line through its end with its end slope. A cubic fitted over
        the travel says nothing about how the curve bends past it, and
        continued as a cubic it can flatten so that no command reaches a
        reading the plant still gives (the paper rig's column (b) in two of four
        round-off probes: a third of the compensation run's targets lay past
        the travel, ``docs/RESULTS.md``).
        """
        c0, c1, c2, c3 = self.poly
        if abs(z) <= 1.0:
            return c0 + z * (c1 + z * (c2 + z * c3))
        end = math.copysign(1.0, z)
        return self.output_map(end) + self._end_slope(end) * (z - end)

    def _end_slope(self, end: float) -> float:
        """The cubic's slope at ``end`` (+1 or -1): the straight continuation's."""
        _, c1, c2, c3 = self.poly
        return c1 + 2.0 * c2 * end + 3.0 * c3

    def invert_output_map(self, reading: float) -> float:
        """The model output ``z`` whose mapped reading (:meth:`output_map`) is ``reading``.

        Exact beyond the travel (the straight continuation); inside, by bisection
        (the map is monotone over ``|z| <= POLY_RANGE``, checked on construction).
        """
        if not self.has_output_map:
            return reading
        p_lo, p_hi = self.output_map(-1.0), self.output_map(1.0)
        rising = p_hi > p_lo
        if (reading <= p_lo) == rising:
            return -1.0 + (reading - p_lo) / self._end_slope(-1.0)
        if (reading >= p_hi) == rising:
            return 1.0 + (reading - p_hi) / self._end_slope(1.0)
        lo, hi = -1.0, 1.0
        for _ in range(60):                    # bisection: monotone, always converges
            mid = 0.5 * (lo + hi)
            if (self.output_map(mid) < reading) == rising:
                lo = mid
            else:
                hi = mid
            if hi - lo < 1e-13:
                break
        return 0.5 * (lo + hi)

    @property
    def has_schedule(self) -> bool:
        """Whether a gain schedule or an offset ramp is set."""
        return self.gain_law != 'none' or self.offset_rate_per_s != 0.0

    @property
    def uses_time(self) -> bool:
        """Whether the corrections need sample times."""
        return self.dead_time_s > 0.0 or self.has_schedule

    @property
    def active(self) -> bool:
        """Whether any correction changes what the plain compensator does (every sample)."""
        return (self.uses_time or self.has_output_map or math.isfinite(self.min_command)
                or math.isfinite(self.max_command))

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any]) -> Augmentation:
        """Build from ``augment.*`` keys (others ignored); absent keys keep their defaults.

        A stop given as NaN (``.nan`` in a params file or a ROS parameter, which
        cannot hold an infinity from every writer) means no stop.

        Raises
        ------
        InvalidParametersError
            A value of the wrong type or out of range.
        """
        kw: dict[str, Any] = {}
        for f in fields(cls):
            key = AUGMENT_PREFIX + f.name
            if key not in values:
                continue
            v = values[key]
            if f.name == 'gain_law':
                kw[f.name] = str(v)
                continue
            try:
                if isinstance(v, bool):
                    raise TypeError
                kw[f.name] = float(v)
                if f.name.endswith('_command') and math.isnan(kw[f.name]):
                    kw[f.name] = -math.inf if f.name == 'min_command' else math.inf
            except (TypeError, ValueError):
                raise InvalidParametersError(f'{key} must be a number, got {v!r}') from None
        return cls(**kw)

    def as_mapping(self) -> dict[str, Any]:
        """``augment.*`` key -> value, as a params file holds them."""
        return {AUGMENT_PREFIX + k: v for k, v in asdict(self).items()}

    def describe(self) -> str:
        """The active corrections in a few words (``none`` without any)."""
        parts = []
        if self.dead_time_s > 0.0:
            parts.append(f'predict {self.dead_time_s:.4g} s ahead')
        if self.gain_law != 'none':
            parts.append(f'{self.gain_law} gain schedule {self.gain_rate_per_s:+.4g}/s around '
                         f'{self.gain_centre:.4g} (set at gain {self.gain_reference:.4g})')
        if self.offset_rate_per_s != 0.0:
            parts.append(f'offset ramp {self.offset_rate_per_s:+.4g}/s')
        if self.schedule_horizon_s > 0.0 and self.has_schedule:
            parts.append(f'schedules held after {self.schedule_horizon_s:.4g} s')
        if math.isfinite(self.min_command) or math.isfinite(self.max_command):
            parts.append(f'stops [{self.min_command:.4g}, {self.max_command:.4g}]')
        if self.has_output_map:
            parts.append('output map ' + ' '.join(f'{c:+.4g}{t}' for c, t in zip(
                self.poly, ('', ' z', ' z^2', ' z^3'))))
        return ', '.join(parts) or 'none'

    def limits(self, base: CommandLimits) -> CommandLimits:
        """``base`` narrowed to the stops."""
        lo = max(base.min_command, self.min_command)
        hi = min(base.max_command, self.max_command)
        if not lo < hi:
            raise InvalidParametersError(f'the stops [{self.min_command}, {self.max_command}] '
                                         f'leave no command inside [{base.min_command}, '
                                         f'{base.max_command}]')
        return CommandLimits(lo, hi, base.max_rate_per_s)

    def gain(self, elapsed_s: float) -> float:
        """Scheduled gain relative to the model's (``g(t) / g_ref``), at least :data:`MIN_GAIN`."""
        if self.gain_law == 'none':
            return 1.0
        t = self._held(elapsed_s)
        g = (math.exp(-self.gain_rate_per_s * t) if self.gain_law == 'exponential'
             else 1.0 + self.gain_rate_per_s * t)
        return max(g / self.gain_reference, MIN_GAIN)

    def offset(self, elapsed_s: float) -> float:
        """Offset relative to the model's at ``elapsed_s``."""
        if self.offset_rate_per_s == 0.0:
            return 0.0
        return self.offset_rate_per_s * (self._held(elapsed_s) - self.offset_reference_s)

    def model_target(self, desired: float, elapsed_s: float | None) -> float:
        """What the model must output so that the reading is ``desired`` at ``elapsed_s``.

        Without a time (``None``) only the output map is undone.
        """
        if elapsed_s is not None:
            c = self.gain_centre
            desired = (desired - c - self.offset(elapsed_s)) / self.gain(elapsed_s) + c
        return self.invert_output_map(desired)

    def reading(self, model_output: float, elapsed_s: float | None) -> float:
        """The reading for ``model_output`` at ``elapsed_s``: :meth:`model_target` undone.

        Without a time (``None``) only the output map is applied.
        """
        y = self.output_map(model_output) if self.has_output_map else float(model_output)
        if elapsed_s is None:
            return y
        c = self.gain_centre
        return c + self.gain(elapsed_s) * (y - c) + self.offset(elapsed_s)

    def _held(self, elapsed_s: float) -> float:
        t = max(float(elapsed_s), 0.0)
        return min(t, self.schedule_horizon_s) if self.schedule_horizon_s > 0.0 else t


class AugmentedCompensator:
    """A :class:`Compensator` with an :class:`Augmentation` around it.

    Same interface as :class:`Compensator` (``step``, ``run``, ``reset``,
    ``set_model``, ``bypass``, ``state``); :meth:`set_augmentation` swaps
    the corrections between two samples, as ``set_model`` swaps the set.

    Parameters
    ----------
    model : InverseModel or None
        H and B (``None``: pass-through, corrections off).
    augmentation : Augmentation, optional
        Corrections (default none: exactly the plain compensator).
    limits : CommandLimits, optional
        Command limits; the augmentation's stops narrow them.
    v0 : float
        Command held before the first sample.
    """

    def __init__(self, model: InverseModel | None, augmentation: Augmentation | None = None,
                 limits: CommandLimits | None = None, v0: float = 0.0) -> None:
        self.base_limits = limits or CommandLimits()
        self.augmentation = augmentation or Augmentation()
        self.inner = Compensator(model, self.augmentation.limits(self.base_limits), v0)
        self._history: deque[tuple[float, float]] = deque()
        self._t0: float | None = None

    @property
    def model(self) -> InverseModel | None:
        """The parameter set in use."""
        return self.inner.model

    @property
    def state(self) -> tuple[float, float, float]:
        """The inner compensator's ``(v, u, y)``."""
        return self.inner.state

    @property
    def limits(self) -> CommandLimits:
        """Limits in force: the base limits narrowed to the stops."""
        return self.inner.limits

    @limits.setter
    def limits(self, base: CommandLimits) -> None:
        self.configure(self.augmentation, base)

    @property
    def bypass(self) -> bool:
        """Pass the desired value through (corrections off too)."""
        return self.inner.bypass

    @bypass.setter
    def bypass(self, value: bool) -> None:
        self.inner.bypass = bool(value)

    def reset(self, v0: float) -> None:
        """Reset the model state (the loop's memory) and the slope history.

        The schedules' time origin is kept: forgetting the loop's memory does not
        refill a supply (:meth:`restart_schedules` does that).
        """
        self.inner.reset(v0)
        self._history.clear()

    def restart_schedules(self) -> None:
        """Start the schedules' time again at the next compensated sample (a new run)."""
        self._t0 = None

    def set_model(self, model: InverseModel | None) -> None:
        """Swap H and B between samples (see :meth:`Compensator.set_model`)."""
        self.inner.set_model(model)

    def set_augmentation(self, augmentation: Augmentation) -> None:
        """Swap the corrections between samples (the schedule's time origin is kept)."""
        self.configure(augmentation, self.base_limits)

    def configure(self, augmentation: Augmentation, limits: CommandLimits) -> None:
        """Swap the corrections and the base limits together (checked before either changes).

        Raises
        ------
        InvalidParametersError
            The stops leave no command inside the limits (nothing is changed).
        """
        narrowed = augmentation.limits(limits)
        self.inner.limits = narrowed
        self.base_limits = limits
        self.augmentation = augmentation

    def predicted_desired(self, desired: float, t_s: float | None) -> float:
        """The desired value ``dead_time_s`` ahead, from its recent slope."""
        aug = self.augmentation
        if aug.dead_time_s <= 0.0 or t_s is None:
            return desired
        hist = self._history
        hist.append((t_s, desired))
        while len(hist) > 2 and t_s - hist[1][0] >= aug.predict_window_s:
            hist.popleft()
        t_old, d_old = hist[0]
        if t_s - t_old <= 0.0:
            return desired
        return desired + aug.dead_time_s * (desired - d_old) / (t_s - t_old)

    def predicted_reading(self, model_output: float, t_s: float | None) -> float:
        """The reading at ``t_s`` of ``model_output``: output map and schedules at ``t_s``.

        What a tracker on top compares the measurement with, so that a drift
        the schedule takes is not corrected twice (:mod:`~hyst_id.compensation.tracking`).
        """
        aug = self.augmentation
        if self.inner.model is None or self.inner.bypass or not aug.active:
            return float(model_output)
        elapsed = None if t_s is None or self._t0 is None else t_s - self._t0
        return aug.reading(model_output, elapsed)

    def step(self, desired: float, t_s: float | None = None) -> float:
        """Command for one desired output sample (``t_s`` needed by time-based corrections)."""
        aug = self.augmentation
        if self.inner.model is None or self.inner.bypass or not aug.active \
                or not math.isfinite(desired):
            return self.inner.step(desired, t_s)     # a non-finite value: the last command
        if t_s is not None and self._t0 is None:
            self._t0 = float(t_s)
        target = self.predicted_desired(float(desired), t_s)
        elapsed = None if t_s is None else t_s - self._t0 + aug.dead_time_s
        return self.inner.step(aug.model_target(target, elapsed), t_s)

    def run(self, desired: np.ndarray, t_s: np.ndarray | None = None) -> np.ndarray:
        """Commands for a whole desired sequence."""
        if t_s is None and self.augmentation.uses_time:
            raise InvalidParametersError('time-based corrections need the sample times')
        out = np.empty(len(desired))
        for j, d in enumerate(desired):
            out[j] = self.step(float(d), None if t_s is None else float(t_s[j]))
        return out


#: A schedule referred to the record's start (the diagnosis's own set).
_AT_START = {'gain_reference': 1.0, 'offset_reference_s': 0.0}


def augmentation_from_findings(findings: Iterable[Any], record_duration_s: float,
                               model_from: str = 'identification'
                               ) -> tuple[Augmentation, list[tuple[str, str]]]:
    """The corrections of a diagnosis's accepted findings, and what each one became.

    Parameters
    ----------
    findings : iterable
        :class:`hyst_id.diagnosis.result.Finding` objects or their JSON dicts;
        each ``compensation['correction']`` holds ``augment.*`` values.
    record_duration_s : float
        Length of the diagnosed record: the schedules are held beyond it.
    model_from : {'identification', 'diagnosis'}
        Whose H and B the compensator runs: an output map (``poly_*``) is
        written in the diagnosis's own travel units, so it is applied only
        with the diagnosis's set. The diagnosis's set holds for the plant at
        the record's start, so its schedules are referred there
        (``gain_reference`` 1, ``offset_reference_s`` 0), in the values and
        in the words.

    Returns
    -------
    augmentation : Augmentation
    applied : list of (mechanism, words)
        Per finding, whether and how the compensator now makes up for it.
    """
    values: dict[str, Any] = {}
    applied: list[tuple[str, str]] = []
    for f in findings:
        d = f if isinstance(f, Mapping) else f.to_dict()
        corr = dict((d.get('compensation') or {}).get('correction') or {})
        if model_from == 'diagnosis':
            corr.update({AUGMENT_PREFIX + k: v for k, v in _AT_START.items()
                         if AUGMENT_PREFIX + k in corr})
        if not corr:
            applied.append((d['mechanism'], 'no in-line correction: '
                            + str((d.get('compensation') or {}).get('how', ''))))
            continue
        if model_from != 'diagnosis' and any(k.startswith(AUGMENT_PREFIX + 'poly_')
                                             for k in corr):
            applied.append((d['mechanism'], "not applied: its output map needs the diagnosis's "
                            'own set (hyst-id diagnose --params-out)'))
            continue
        clash = sorted(set(corr) & set(values))
        if clash:
            applied.append((d['mechanism'], 'not applied: ' + ', '.join(clash)
                            + ' already set by an earlier finding'))
            continue
        values.update(corr)
        applied.append((d['mechanism'], 'in-line: ' + ', '.join(
            f'{k[len(AUGMENT_PREFIX):]} = {v if isinstance(v, str) else f"{v:.4g}"}'
            for k, v in corr.items())))
    if any(k.startswith(AUGMENT_PREFIX + p) for k in values for p in ('gain', 'offset')):
        values.setdefault(AUGMENT_PREFIX + 'schedule_horizon_s', float(record_duration_s))
    return Augmentation.from_mapping(values), applied
