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

"""The interface every mechanism of the library implements.

A mechanism is a parametric block inserted at its physical place in the
chain ``v -> [command] -> H -> B -> [position] -> [sensed quantity] ->
sensor -> [sensor] -> calibration -> [output] -> y``. It has

* *searched* parameters ``theta`` (nonlinear, fitted by a grid of starts and
  bounded least squares together with the chain's parameters), declared by
  :attr:`Mechanism.names` with bounds from :meth:`Mechanism.bounds`;
* optionally *linear* parameters, which join the affine calibration and
  are profiled out in closed form (:attr:`Mechanism.n_linear`);
* one hook per stage it acts in (the others are the identity);
* words: what it is physically, how to read its fitted values, which
  located evidence speaks for it.

Position-stage quantities (bands, stops, curvature) are expressed as
fractions of the travel that the *training* part of the record covers, so
they do not depend on the chain's gauge (the arbitrary scale and offset of
the signal between H and the calibration).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

__all__ = ['COMPENSATION_KINDS', 'EDGE_FRACTION', 'STAGES', 'Context', 'Mechanism', 'Quantity',
           'clip_theta', 'rate_correlation']

#: How a block is made up for in operation: by a correction in the compensator's
#: model (:mod:`hyst_id.compensation.augment`); by the compensator's tracking or the
#: identifier's sliding re-identification; by the command limits; by identifying
#: another H family; not needed (the block is in the reading, not the actuator); or
#: not at all in-line.
COMPENSATION_KINDS = ('in-line', 'tracking', 'limits', 'family', 'not needed', 'not in-line')

#: Stages in signal order.
STAGES = ('command', 'actuator', 'position', 'quantity', 'sensor', 'output')
#: A searched parameter within this share of its search's width from an edge is on it.
EDGE_FRACTION = 1e-3


@dataclass(frozen=True)
class Quantity:
    """A reported value with its unit and a short meaning."""

    value: float
    unit: str
    meaning: str = ''

    def to_dict(self) -> dict:
        """JSON-ready form."""
        return {'value': float(self.value), 'unit': self.unit, 'meaning': self.meaning}


@dataclass
class Context:
    """What mechanisms need to know about the recording and the fit.

    Attributes
    ----------
    channel : str
        Measured channel.
    t_s : numpy.ndarray
        Sample times of the whole record, seconds.
    n_train : int
        Samples in the training part (the first ones).
    command_scale : tuple of float
        ``(a, b)`` with ``command_original = a * command_model + b``.
    command_unit, measurement_unit : str
        Units for the words.
    measurement_name : str
        What the file calls the measurement (empty: unknown); see :attr:`quantity`.
    extra : dict
        Anything else (e.g. the baseline travel) a mechanism wants to keep.
    """

    channel: str
    t_s: np.ndarray
    n_train: int
    command_scale: tuple[float, float] = (1.0, 0.0)
    command_unit: str = ''
    measurement_unit: str = ''
    extra: dict = field(default_factory=dict)
    measurement_name: str = ''

    @property
    def quantity(self) -> str:
        """The measured quantity for the words: the file's name for it, else the channel."""
        return self.measurement_name or self.channel

    @property
    def dt_s(self) -> float:
        """Median sample interval, seconds."""
        return float(np.median(np.diff(self.t_s)))

    @property
    def train_duration_s(self) -> float:
        """Duration of the training part, seconds."""
        return float(self.t_s[self.n_train - 1] - self.t_s[0])

    @property
    def duration_s(self) -> float:
        """Duration of the whole record, seconds."""
        return float(self.t_s[-1] - self.t_s[0])

    @property
    def period_s(self) -> float:
        """Typical time between command reversals times two (a loop period)."""
        return float(self.extra.get('period_s', 10.0))

    def cmd(self, value_model_units: float) -> float:
        """Convert a command level from model units to the recording's units."""
        a, b = self.command_scale
        return a * value_model_units + b

    @property
    def cmd_unit(self) -> str:
        """Command unit for messages (``cmd`` when unknown)."""
        return self.command_unit or 'cmd'

    @property
    def meas_unit(self) -> str:
        """Measurement unit for messages (``units`` when unknown)."""
        return self.measurement_unit or 'units'


class Mechanism:
    """Base class: a block that is the identity until a subclass overrides a hook.

    Attributes
    ----------
    id : str
        Mechanism id as the diagnosis issue lists it.
    title : str
        A few words naming the physics.
    stage : str
        One of :data:`STAGES`, where the block sits.
    placement : str
        Where in the chain, in words.
    names, units : tuple of str
        Searched parameters and their units.
    n_linear : int
        Extra linear parameters profiled with the calibration.
    smooth : bool
        Whether the cost is smooth enough in ``theta`` for least squares
        (else ``theta`` is searched on a grid / pattern search).
    families : tuple of str or None
        Hysteresis families the block works with (None: any); a block that
        rewrites H itself needs the family it was written for.
    channels : tuple of str or None
        Channels whose physics the block can be (None: any): a supply running
        down changes pressure and flow, never the valve's position reading.
    maps_travel : bool
        Whether :meth:`quantity` replaces the reading's map of the travel by a
        basis of its own (a static curve); blocks that only add terms
        (:meth:`quantity_terms`, friction) leave the map alone.
    fits_as : str
        The id of a block whose fit is this block's under another name (the same
        parameters, bounds, starts and model; only the sense it accepts and its
        words differ), or ''. In a round that tries both the fit is made once
        (:func:`hyst_id.diagnosis.trial.try_all`).
    """

    id = ''  # noqa: A003 - the issue's word for a mechanism's name
    title = ''
    stage = 'output'
    placement = ''
    physics = ''
    names: tuple[str, ...] = ()
    units: tuple[str, ...] = ()
    n_linear = 0
    smooth = True
    families: tuple[str, ...] | None = None
    channels: tuple[str, ...] | None = None
    maps_travel = False
    fits_as = ''

    # -- fitting -----------------------------------------------------------
    def bounds(self, ctx: Context) -> np.ndarray:
        """``(len(names), 2)`` bounds of ``theta``."""
        return np.zeros((0, 2))

    def starts(self, ctx: Context) -> list[np.ndarray]:
        """Starting values of ``theta`` for the local fits (a coarse grid)."""
        return [np.zeros(0)]

    def grid(self, ctx: Context) -> list[np.ndarray]:
        """Dense grid of ``theta`` for blocks that are not smooth (default: the starts)."""
        return self.starts(ctx)

    def null(self, ctx: Context) -> np.ndarray:
        """``theta`` at which the block is the identity (the baseline)."""
        return np.zeros(0)

    def data_starts(self, model: Any, data: Any, p_prev: np.ndarray,
                    chain_starts: list[np.ndarray]) -> list[np.ndarray]:
        """Full parameter vectors of ``model`` built from the measured data (default: none).

        For blocks whose fit cannot start from the baseline (stiction): these
        are scored with the grid's candidates and kept as they are when best.
        """
        return []

    def at_edges(self, theta: np.ndarray, ctx: Context) -> list[str]:
        """Searched parameters that ended on an edge of their search, one sentence each.

        An edge at zero is the physics' own limit (no lag, no width) and is not
        named. An independent reviewer's creep of 1.5 s was reported as 2 s, the
        lower end of its search, as if measured.
        """
        bounds = self.bounds(ctx)
        out = []
        for i, name in enumerate(self.names[:len(bounds)]):
            lo, hi = (float(x) for x in bounds[i])
            x, unit = float(theta[i]), (self.units[i] if i < len(self.units) else '')
            for edge, side in ((lo, 'lower'), (hi, 'upper')):
                if edge != 0.0 and hi > lo and abs(x - edge) <= EDGE_FRACTION * (hi - lo):
                    out.append(f'{name} = {x:.4g} {unit} sits at the {side} end of its search '
                               f'({edge:.4g} {unit}): the data may want a value beyond it, so '
                               'read it as a bound, not a measurement')
        return out

    def implausible(self, theta: np.ndarray, coef: np.ndarray, span: tuple[float, float],
                    noise_std: float, ctx: Context | None = None,
                    labels: Sequence[str] | None = None) -> str:
        """Why the fitted block cannot be what the data show ('' when it can).

        A block whose own effect is below what the data can resolve (e.g.
        stick-slip jumps smaller than the noise) may still lower the error by
        letting the chain refit; that gain is not evidence for the block.
        ``ctx`` (the record's context) gives the bounds of ``theta``;
        ``labels`` name the linear coefficients ``coef`` (``'sensor'``,
        ``'<mechanism>:<i>'``, ``'offset'``; ``None`` when not known).
        """
        return ''

    def doubt(self, theta: np.ndarray, coef: np.ndarray, labels: Sequence[str],
              readings: np.ndarray) -> str:
        """Why the fit, though possible, goes against the block's own physics ('' if not).

        Not a rejection: among candidates tied on the held-out part, one with
        a doubt steps back for one without (:func:`hyst_id.diagnosis.ties.choose`),
        and the report says why. ``readings``: the training part's measurement.
        """
        return ''

    # -- stage hooks (identity by default) ----------------------------------
    def command(self, theta: np.ndarray, t_s: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Transform the command before the actuator."""
        return v

    def actuator(self, theta: np.ndarray, x_chain: np.ndarray, t_s: np.ndarray,
                 v: np.ndarray) -> np.ndarray | None:
        """Replace the actuator ``B(H(v))``; ``None`` keeps the paper's."""
        return None

    def position(self, theta: np.ndarray, x: np.ndarray, span: tuple[float, float]
                 ) -> np.ndarray:
        """Transform the actuator position; ``span`` is the training travel (lo, hi)."""
        return x

    def quantity(self, theta: np.ndarray, x: np.ndarray, span: tuple[float, float]
                 ) -> list[np.ndarray] | None:
        """Basis of the sensed quantity as a function of position (``None``: ``[x]``)."""
        return None

    def quantity_terms(self, theta: np.ndarray, x: np.ndarray, span: tuple[float, float]
                       ) -> list[np.ndarray]:
        """Terms added to the sensed quantity, each with its own linear coefficient.

        They pass through the sensor like the quantity itself and are labelled
        ``'<id>:<i>'`` after the quantity's basis (default: none). A force
        that depends on the path of the position, not on its value (friction),
        is one: it is no function of ``x`` that :meth:`quantity` could give.
        """
        return []

    def sensor(self, theta: np.ndarray, t_s: np.ndarray, s: np.ndarray) -> np.ndarray:
        """Extra sensor dynamics after the modelled ones."""
        return s

    def output(self, theta: np.ndarray, t_s: np.ndarray, columns: list[np.ndarray],
               ctx: Context) -> list[np.ndarray]:
        """Regressors of the linear calibration (last one is the constant)."""
        return columns

    def undo(self, theta: np.ndarray, t_s: np.ndarray, v: np.ndarray, y: np.ndarray,
             terms: dict[str, np.ndarray], ctx: Context
             ) -> tuple[np.ndarray, np.ndarray] | None:
        """The command and measurement with this block taken out, or ``None``.

        What the chain alone would have been given and would have produced,
        so that the chain can be searched again globally once the block is
        accepted (:mod:`hyst_id.diagnosis.refit`). ``terms`` maps each
        regressor label of the fitted model to its fitted contribution
        (coefficient times column). By default a command-stage block is
        applied to the command and an output-stage block's own terms are
        subtracted from the measurement; blocks at the other stages are not
        inverted (``None``): a filter's or an end stop's inverse applied to
        noisy samples is no data.
        """
        if self.stage == 'command':
            return self.command(theta, t_s, v), y
        if self.stage == 'output':
            own = [c for k, c in terms.items() if k.startswith(f'{self.id}:')]
            return v, (y - np.sum(own, axis=0)) if own else y
        return None

    def undo_terms(self, theta: np.ndarray, t_s: np.ndarray, terms: dict[str, np.ndarray],
                   ctx: Context) -> dict[str, np.ndarray]:
        """The fitted terms as the record with this block undone holds them.

        Called after :meth:`undo` succeeded, before the next block is undone;
        returns a new mapping (``terms`` is not changed). By default the
        terms are the same; a block that scales the others (a gain in time)
        returns them with its scaling taken out.
        """
        return dict(terms)

    # -- words -------------------------------------------------------------
    def describe(self, theta: np.ndarray, coef: np.ndarray, info: dict,
                 ctx: Context) -> dict[str, Quantity]:
        """Fitted values with units; ``info`` holds the fit's calibration and travel."""
        return {n: Quantity(float(v), u) for n, v, u in zip(self.names, theta, self.units)}

    def explain(self, values: dict[str, Quantity], where: dict, ctx: Context) -> str:
        """One or two sentences a control engineer can act on."""
        return self.title

    def evidence(self, loc: Any) -> tuple[float, dict]:
        """Score in [0, 1] of how well the located mismatch fits this physics, and where."""
        return 0.0, {}

    # -- compensation --------------------------------------------------------
    #: How the package makes up for the block in operation, one of
    #: :data:`COMPENSATION_KINDS`.
    compensation = 'not in-line'

    def compensation_note(self, values: dict[str, Quantity], ctx: Context) -> str:
        """Whether and how the compensator makes up for the fitted block, in words."""
        return ('not compensated in-line: the compensator inverts H and B only; the block '
                'stays in the plant')

    def correction(self, theta: np.ndarray, coef: np.ndarray, info: dict,
                   ctx: Context) -> dict[str, float | str]:
        """The compensator's in-line correction for the fitted block, or ``{}``.

        Keys are :class:`hyst_id.compensation.augment.Augmentation` fields with
        the ``augment.`` prefix, values in the measured channel's units, the
        command's units and seconds (``info`` as for :meth:`describe`).
        """
        return {}


def clip_theta(theta: Sequence[float], bounds: np.ndarray) -> np.ndarray:
    """Clip a parameter vector into its bounds (strictly inside)."""
    t = np.asarray(theta, dtype=float)
    lo, hi = bounds[:, 0], bounds[:, 1]
    eps = 1e-9 * np.maximum(1.0, np.abs(hi - lo))
    return np.minimum(np.maximum(t, lo + eps), hi - eps)


def rate_correlation(loc: Any) -> dict:
    """Where-evidence of a residual correlated with the command rate (peak r and its lag)."""
    return {'correlation_with_rate': {'r': loc.ccf_rate['peak_r'],
                                      'lag_s': loc.ccf_rate['peak_lag_s']}}
