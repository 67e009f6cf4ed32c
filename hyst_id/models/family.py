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

"""The interface every hysteresis family implements, and the loop box its domains come from.

A *family* is one way of writing the hysteresis H of the chain
``v -> H -> B -> sensor``: the paper's piecewise-linear loop
(:mod:`hyst_id.models.tk`) or a smooth one. The chain, identification, the
gauge, the compensator and the diagnosis only talk to H through
:class:`HysteresisFamily`, so a new family is one module that subclasses it
plus one line in :mod:`hyst_id.models.registry` (``docs/model.md``, "Adding a
hysteresis family", has the smallest example).

Conventions every family keeps:

* H's output rises with the command on every branch (strictly increasing
  branches), so its inverse is exact;
* the output starts on the *rising* boundary of the loop at the first
  command (the state an actuator has after being driven up to it);
* parameters carry units by kind: ``cmd`` (command units), ``out`` (H's
  output units), ``out/cmd``, ``1/out``, ``1/out^2`` and ``1``
  (dimensionless); the gauge map below and the reports rely on them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

__all__ = ['HysteresisFamily', 'HysteresisInverse', 'LoopBox', 'UNIT_KINDS']

#: The unit kinds a parameter may have.
UNIT_KINDS = ('cmd', 'out', 'out/cmd', '1/out', '1/out^2', '1')


@dataclass(frozen=True)
class LoopBox:
    """The region a loop fitted to a recording lives in, for search domains and starts.

    Attributes
    ----------
    v_lo, v_hi : float
        The visited command range, widened by the domain settings' margin.
    v_min, v_max : float
        The visited command range itself.
    u_lo, u_hi : float
        H's output box: the data's span plus room above and below.
    slope : float
        The loop's mean slope (output span over command span).
    steep : float
        Largest side slope to allow, in mean slopes.
    slope_min : float
        Smallest side slope to allow, in mean slopes.
    flat_max : float
        Largest flat (inner) slope, in mean slopes.
    loop_width : float
        Measured loop width where the output crosses its median (command units).
    """

    v_lo: float
    v_hi: float
    v_min: float
    v_max: float
    u_lo: float
    u_hi: float
    slope: float
    steep: float
    slope_min: float
    flat_max: float
    loop_width: float = 0.0

    @property
    def span_v(self) -> float:
        """Visited command span."""
        return self.v_max - self.v_min

    @property
    def span_u(self) -> float:
        """Output box height."""
        return self.u_hi - self.u_lo


class HysteresisInverse:
    """A family's exact inverse with its own copy of H's state (for in-line compensation).

    :meth:`command_for` answers "which command makes H output ``u_d`` next"
    without moving the state; :meth:`advance` then moves the state with the
    command actually sent (after the compensator's limits), so the model
    never drifts from what the actuator received.
    """

    def reset(self, v0: float, u0: float | None = None) -> None:
        """Put the state at command ``v0``: on the rising boundary, or as close to ``u0``."""
        raise NotImplementedError

    @property
    def command(self) -> float:
        """Last command of the state."""
        raise NotImplementedError

    @property
    def output(self) -> float:
        """H's output in the state."""
        raise NotImplementedError

    def command_for(self, u_d: float) -> float:
        """Command that makes H output ``u_d`` from the current state (nearest reachable)."""
        raise NotImplementedError

    def advance(self, v: float) -> float:
        """Move the state with command ``v``; return H's output."""
        raise NotImplementedError


class HysteresisFamily:
    """One way of writing H: parameters, kernels, gauge map, domains, starts, inverse.

    Subclasses set the class attributes and implement the methods; the
    simulation methods must be numba-compiled kernels underneath (they run
    for whole populations inside the optimisers).
    """

    #: Short id used on the command line and in params files (``tk``, ``smooth``).
    id: str = ''  # noqa: A003
    #: One-line description for reports.
    title: str = ''
    #: Parameter names, in vector order.
    names: tuple[str, ...] = ()
    #: Unit kind of each parameter (see :data:`UNIT_KINDS`).
    units: Mapping[str, str] = {}
    #: One-phrase meaning of each parameter (node parameter descriptions, reports).
    descriptions: Mapping[str, str] = {}
    #: Fixed search domains by name (a preset), or None.
    paper_domains: Mapping[str, tuple[float, float]] | None = None

    @property
    def n_params(self) -> int:
        """Number of parameters."""
        return len(self.names)

    # ------------------------------------------------------------- validity
    def check(self, params: np.ndarray) -> np.ndarray:
        """Return ``params`` as float64, or raise InvalidParametersError naming the rule.

        The rules must be gauge invariant (they hold for any positive scale
        and shift of the output), so canonical sets pass them too.
        """
        raise NotImplementedError

    def feasible_rows(self, pop: np.ndarray) -> np.ndarray:
        """Search-space constraints per row of ``pop`` (``(n, n_params)``), as a bool mask.

        They must hold in any command frame (any positive scale and offset of
        the command): a recording's command units are the user's.
        """
        raise NotImplementedError

    def loose_rows(self, pop: np.ndarray) -> np.ndarray:
        """A wider search set than :meth:`feasible_rows`, where the family has one.

        Default: the same rows. The paper's loop admits loops whose output jumps
        (:meth:`hyst_id.models.tk.TaoKokotovic.loose_rows`).
        """
        return self.feasible_rows(pop)

    def check_simulable(self, params: np.ndarray) -> np.ndarray:
        """Validate a set for simulation (of :meth:`loose_rows`); default :meth:`check`."""
        return self.check(params)

    def paper_frame_rows(self, pop: np.ndarray) -> np.ndarray:
        """Constraints of the paper that hold only in its command frame (mA), per row.

        Applied on top of :meth:`feasible_rows` when the search domains are the
        paper's own (``domain_source == 'paper'``): the paper's procedure keeps
        its constraints as printed. Default: none.
        """
        return np.ones(np.atleast_2d(pop).shape[0], dtype=bool)

    # ----------------------------------------------------------- simulation
    def simulate_rows(self, pop: np.ndarray, v: np.ndarray, ok: np.ndarray,
                      out: np.ndarray) -> None:
        """Write H's output for every row of ``pop`` with ``ok`` true into ``out[i]``."""
        raise NotImplementedError

    def simulate(self, params: np.ndarray, v: np.ndarray, *, validate: bool = True
                 ) -> np.ndarray:
        """H's output for one parameter set and a command sequence.

        The set is checked first unless ``validate`` is false (for a caller
        that has already checked it, or found it feasible).
        """
        p = self.check(params) if validate else params
        p = np.ascontiguousarray(p, dtype=np.float64)[None, :]
        out = np.empty((1, np.asarray(v).shape[0]))
        self.simulate_rows(p, np.ascontiguousarray(v, dtype=np.float64),
                           np.ones(1, dtype=np.bool_), out)
        return out[0]

    # ---------------------------------------------------------------- gauge
    def map_output(self, params: np.ndarray, alpha: float, delta: float) -> np.ndarray:
        """Parameters whose H output is ``alpha * H(v) + delta`` (``alpha > 0``)."""
        raise NotImplementedError

    def map_input(self, params: np.ndarray, a: float, b: float) -> np.ndarray:
        """Parameters of the same loop driven by ``v = a v_m + b`` instead of ``v_m`` (``a > 0``).

        ``H'(a v_m + b) == H(v_m)`` for every command sequence: what writes a set
        found on a normalised command in the recording's own command units.
        """
        raise NotImplementedError

    # ------------------------------------------------------ domains, starts
    def domains(self, box: LoopBox) -> dict[str, tuple[float, float]]:
        """Search domain of every parameter for a loop living in ``box``."""
        raise NotImplementedError

    def starts(self, box: LoopBox, width: float | None = None) -> list[np.ndarray]:
        """Parameter sets built from the data to start from: loops of width ``width``.

        ``width`` (command units) defaults to the measured ``box.loop_width``;
        :func:`hyst_id.identification.starts.data_starts` asks for several
        widths, sharing the measured one between H and the backlash.
        """
        return []

    # ------------------------------------------------------------- inverse
    def inverse(self, params: np.ndarray) -> HysteresisInverse:
        """A fresh inverse (state on the rising boundary at command 0)."""
        raise NotImplementedError

    # ----------------------------------------------------------- reporting
    def unexcited(self, params: np.ndarray, command: np.ndarray,
                  command_unit: str = '') -> tuple[list[str], set[str]]:
        """Warnings about parts of the loop the command never exercises, and their parameters."""
        return [], set()

    def describe(self, params: np.ndarray) -> dict[str, float]:
        """Derived figures of a parameter set for reports (loop width, corners, ...)."""
        return {}
