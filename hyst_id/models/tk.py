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

"""The paper's hysteresis family ``tk``: Krasnosel'skii hysteron, Tao & Kokotovic form.

Parameters are ordered ``(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)``: slopes
and crossings of the left, right, top and bottom lines of the loop::

    left   u = m_l (v - c_l)        right  u = m_r (v - c_r)
    top    u = m_t v + c_t          bottom u = m_b v + c_b

One step rule holds the whole of the paper's Eq. 1 (see
``docs/model.md`` and the model notes)::

    rising  v > v_prev:  u = min(max(m_b v + c_u, m_r (v - c_r)), m_t v + c_t)
    falling v < v_prev:  u = max(min(m_t v + c_d, m_l (v - c_l)), m_b v + c_b)
    equal:               u = u_prev

with ``c_u = u_prev - m_b v_prev`` and ``c_d = u_prev - m_t v_prev``.

Initial state (the paper leaves it open): the output starts on the
*rising* boundary of the major loop at ``v(0)``, as if the actuator had
just been driven up to its starting command (:func:`initial_output`).

:data:`FAMILY` is the :class:`~hyst_id.models.family.HysteresisFamily` the
chain, the gauge, identification and the compensator use; the numba step
rules below are its kernels.
"""

from __future__ import annotations

from numba import njit
import numpy as np

from hyst_id.errors import InvalidParametersError
from hyst_id.models.family import HysteresisFamily, HysteresisInverse, LoopBox
from hyst_id.models.tk_lines import unexcited_lines

__all__ = [
    'FAMILY',
    'HYSTERESIS_NAMES',
    'TaoKokotovic',
    'TaoKokotovicInverse',
    'check_hysteresis',
    'hysteresis_feasible',
    'loop_corners',
    'loop_is_proper',
    'slopes_admitted',
    'initial_output',
    'hysteresis_step',
    'hysteresis_inverse_step',
    'simulate_hysteresis',
    'invert_hysteresis',
]

HYSTERESIS_NAMES = ('m_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b')
#: Unit kind of each parameter.
UNITS = {'m_l': 'out/cmd', 'm_r': 'out/cmd', 'm_t': 'out/cmd', 'm_b': 'out/cmd',
         'c_l': 'cmd', 'c_r': 'cmd', 'c_t': 'out', 'c_b': 'out'}
#: The paper's search domains (section 4).
PAPER_DOMAINS = {'m_l': (0.0, 5.0), 'm_r': (0.0, 5.0), 'm_t': (0.0, 5.0), 'm_b': (0.0, 5.0),
                 'c_l': (-5.0, 5.0), 'c_r': (-5.0, 5.0), 'c_t': (4.0, 20.0), 'c_b': (4.0, 20.0)}


@njit(cache=True, inline='always')
def slopes_admitted(m_l, m_r, m_t, m_b):
    """The paper's slope constraints: ``m_l, m_r > 0``, ``min(m_l, m_r) > m_t, m_b > 0``."""
    m_min = min(m_l, m_r)
    return m_l > 0.0 and m_r > 0.0 and 0.0 < m_t < m_min and 0.0 < m_b < m_min


@njit(cache=True, inline='always')
def loop_is_proper(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
    """Return True when the parameters describe a proper loop (gauge invariant).

    Slopes ``min(m_l, m_r) > m_t, m_b > 0`` and the four corners form a
    proper quadrilateral (see :func:`loop_corners`): the left line meets the
    bottom and the top lines before the right line does, and meets the bottom
    before the top. The corners put the top line above the bottom line over
    the whole loop (at D: ``top(v_D) = left(v_D) > left(v_A) + m_b (v_D - v_A)
    = bottom(v_D)``, likewise at B). These conditions survive any positive
    rescaling and shift of the output (the gauge of ``docs/model.md``) and of
    the command. The paper's ``c_t > c_b`` compares the lines at command 0 and
    changes with the command's offset (a loop recorded in volts from 100 V
    can break it), so it is kept only with the paper's own domains
    (:meth:`TaoKokotovic.paper_frame_rows`); the paper's ``c_l < c_r``
    compares where the lines extrapolate to zero output and is a
    search-space constraint (:func:`hysteresis_feasible`).
    """
    if not slopes_admitted(m_l, m_r, m_t, m_b):
        return False
    v_a = (c_b + m_l * c_l) / (m_l - m_b)
    v_b = (c_b + m_r * c_r) / (m_r - m_b)
    v_c = (c_t + m_r * c_r) / (m_r - m_t)
    v_d = (c_t + m_l * c_l) / (m_l - m_t)
    return v_a < v_b and v_d < v_c and v_a < v_d and v_b < v_c


@njit(cache=True, inline='always')
def hysteresis_feasible(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
    """Return True for the paper's constraints (incl. ``c_l < c_r``) on a proper loop.

    This is the search-space constraint of GAASS's rejecting strategy. The
    paper's constraints alone admit loops whose left and right lines cross
    inside the band, on which H jumps and H^-1 fails, hence
    :func:`loop_is_proper` as well.
    """
    return c_l < c_r and loop_is_proper(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)


@njit(cache=True, inline='always')
def initial_output(v0, m_r, m_t, m_b, c_r, c_t, c_b):
    """Output on the rising boundary of the major loop at command ``v0``."""
    return min(max(m_b * v0 + c_b, m_r * (v0 - c_r)), m_t * v0 + c_t)


@njit(cache=True, inline='always')
def hysteresis_step(v, v_prev, u_prev, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
    """Advance H by one sample: output for command ``v`` after ``(v_prev, u_prev)``."""
    if v > v_prev:
        c_u = u_prev - m_b * v_prev
        return min(max(m_b * v + c_u, m_r * (v - c_r)), m_t * v + c_t)
    if v < v_prev:
        c_d = u_prev - m_t * v_prev
        return max(min(m_t * v + c_d, m_l * (v - c_l)), m_b * v + c_b)
    return u_prev


@njit(cache=True, inline='always')
def hysteresis_inverse_step(u_d, v_prev, u_prev, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
    """Command ``v`` that makes H output ``u_d`` from state ``(v_prev, u_prev)``."""
    if u_d > u_prev:
        c_u = u_prev - m_b * v_prev
        return max(min((u_d - c_u) / m_b, u_d / m_r + c_r), (u_d - c_t) / m_t)
    if u_d < u_prev:
        c_d = u_prev - m_t * v_prev
        return min(max((u_d - c_d) / m_t, u_d / m_l + c_l), (u_d - c_b) / m_b)
    return v_prev


@njit(cache=True)
def _simulate(p, v, u0):
    n = v.shape[0]
    u = np.empty(n)
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    u[0] = u0
    for j in range(1, n):
        u[j] = hysteresis_step(v[j], v[j - 1], u[j - 1], m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
    return u


@njit(cache=True)
def _invert(p, u_d, v0, u0):
    n = u_d.shape[0]
    v = np.empty(n)
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    v_prev, u_prev = v0, u0
    for j in range(n):
        vj = hysteresis_inverse_step(u_d[j], v_prev, u_prev,
                                     m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
        u_prev = hysteresis_step(vj, v_prev, u_prev, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
        v_prev = vj
        v[j] = vj
    return v


def loop_corners(params: np.ndarray) -> dict[str, tuple[float, float]]:
    """Corners of the major loop as ``(v, u)``.

    ``A`` left-bottom, ``B`` right-bottom, ``C`` right-top (the paper's
    ``v_1``), ``D`` left-top; ``A`` is the paper's ``v_2``.
    """
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = np.asarray(params, dtype=float)
    v_a = (c_b + m_l * c_l) / (m_l - m_b)
    v_b = (c_b + m_r * c_r) / (m_r - m_b)
    v_c = (c_t + m_r * c_r) / (m_r - m_t)
    v_d = (c_t + m_l * c_l) / (m_l - m_t)
    return {'A': (v_a, m_b * v_a + c_b), 'B': (v_b, m_b * v_b + c_b),
            'C': (v_c, m_t * v_c + c_t), 'D': (v_d, m_t * v_d + c_t)}


def check_hysteresis(params: np.ndarray, proper: bool = True) -> np.ndarray:
    """Return ``params`` as float64, or raise if they do not describe a proper loop.

    The checks are gauge invariant (:func:`loop_is_proper`), so they hold for
    canonical parameter sets too; the paper's ``c_l < c_r`` is a search-space
    constraint only and is not required here.

    Parameters
    ----------
    params : array_like
        ``(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)``.
    proper : bool
        Require the corner order of a proper loop (the inverse needs it); without
        it only the slopes are checked: a set the step rule can simulate, as the
        paper's constraints admit (:meth:`TaoKokotovic.check_simulable`).

    Raises
    ------
    InvalidParametersError
        Wrong length, non-finite values or a violated constraint (named).
    """
    p = np.asarray(params, dtype=np.float64).ravel()
    if p.shape[0] != 8 or not np.all(np.isfinite(p)):
        raise InvalidParametersError('hysteresis needs 8 finite parameters '
                                     f'{HYSTERESIS_NAMES}, got {p.tolist()}')
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p
    checks = (
        (m_l > 0 and m_r > 0, 'm_l, m_r > 0'),
        (0 < m_t < min(m_l, m_r), 'min(m_l, m_r) > m_t > 0'),
        (0 < m_b < min(m_l, m_r), 'min(m_l, m_r) > m_b > 0'),
    )
    for ok, rule in checks:
        if not ok:
            raise InvalidParametersError(f'hysteresis parameters violate {rule}')
    if proper and not loop_is_proper(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b):
        corners = {k: round(float(v[0]), 4) for k, v in loop_corners(p).items()}
        raise InvalidParametersError(
            'hysteresis loop is not proper: the left line must stay left of the right line '
            f'between the bottom and top lines (corner commands {corners} need A < B, '
            'D < C, A < D, B < C)')
    return p


def simulate_hysteresis(params: np.ndarray, command: np.ndarray,
                        u0: float | None = None) -> np.ndarray:
    """Output of H for a command sequence.

    Parameters
    ----------
    params : array_like
        ``(m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)``.
    command : numpy.ndarray
        Input ``v`` per sample.
    u0 : float, optional
        Initial output; default the rising boundary at ``command[0]``.

    Returns
    -------
    numpy.ndarray
        Output ``u`` per sample.
    """
    p = check_hysteresis(params)
    v = np.ascontiguousarray(command, dtype=np.float64)
    if u0 is None:
        u0 = initial_output(v[0], p[1], p[2], p[3], p[5], p[6], p[7])
    return _simulate(p, v, float(u0))


def invert_hysteresis(params: np.ndarray, desired: np.ndarray, v0: float,
                      u0: float | None = None) -> np.ndarray:
    """Commands that make H follow ``desired`` (Tao & Kokotovic inverse).

    Parameters
    ----------
    params : array_like
        Hysteresis parameters.
    desired : numpy.ndarray
        Desired output ``u_d`` per sample.
    v0 : float
        Command before the first sample (the model state's input).
    u0 : float, optional
        Output before the first sample; default the rising boundary at ``v0``.

    Returns
    -------
    numpy.ndarray
        Command ``v`` per sample; ``simulate_hysteresis`` of it from the
        same state reproduces ``desired`` wherever ``desired`` is reachable.
    """
    p = check_hysteresis(params)
    if u0 is None:
        u0 = initial_output(v0, p[1], p[2], p[3], p[5], p[6], p[7])
    return _invert(p, np.ascontiguousarray(desired, dtype=np.float64), float(v0), float(u0))


@njit(cache=True)
def _feasible_rows(pop, proper):
    """Per row: finite and a proper loop with ``c_l < c_r``, or (not ``proper``) the loose set.

    The loose set: the paper's slopes, the corners in any order. The paper's
    ``c_l < c_r`` compares the lines at output 0, which the profiled
    calibration moves (any output shift is the same chain): in the loose set
    it cuts shifts of the true loop out of the search when ``m_l != m_r``
    (``bench/improper_loops.py`` #16: 1.12 x the true noise with it, 1.02 x
    without), so only the paper's own frame keeps it
    (:meth:`TaoKokotovic.paper_frame_rows`).
    """
    ok = np.empty(pop.shape[0], dtype=np.bool_)
    for i in range(pop.shape[0]):
        p = pop[i]
        good = True
        for q in range(8):
            if not np.isfinite(p[q]):
                good = False
        if not good:
            ok[i] = False
        elif proper:
            ok[i] = hysteresis_feasible(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7])
        else:
            ok[i] = slopes_admitted(p[0], p[1], p[2], p[3])
    return ok


@njit(cache=True)
def _simulate_rows(pop, v, ok, out):
    for i in range(pop.shape[0]):
        if not ok[i]:
            continue
        m_l, m_r, m_t, m_b = pop[i, 0], pop[i, 1], pop[i, 2], pop[i, 3]
        c_l, c_r, c_t, c_b = pop[i, 4], pop[i, 5], pop[i, 6], pop[i, 7]
        u = initial_output(v[0], m_r, m_t, m_b, c_r, c_t, c_b)
        out[i, 0] = u
        for j in range(1, v.shape[0]):
            u = hysteresis_step(v[j], v[j - 1], u, m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b)
            out[i, j] = u


def _crossing_range(v_lo: float, v_hi: float, u_lo: float, u_hi: float,
                    m_lo: float, m_hi: float) -> tuple[float, float]:
    """Range of ``c = v - u / m`` over the box and slopes ``[m_lo, m_hi]``."""
    q = [u / m for u in (u_lo, u_hi) for m in (m_lo, m_hi)]
    return v_lo - max(q), v_hi - min(q)


def _intercept_range(v_lo: float, v_hi: float, u_lo: float, u_hi: float,
                     m_hi: float) -> tuple[float, float]:
    """Range of ``c = u - m v`` over the box and slopes ``[0, m_hi]``."""
    mv = [0.0, m_hi * v_lo, m_hi * v_hi]
    return u_lo - max(mv), u_hi - min(mv)


class TaoKokotovicInverse(HysteresisInverse):
    """Exact inverse of the ``tk`` loop with its own state ``(v, u)`` (model notes section 1)."""

    def __init__(self, params: np.ndarray) -> None:
        self.p = tuple(float(x) for x in check_hysteresis(params))
        self._v = 0.0
        self._u = 0.0
        self.reset(0.0)

    def output_range(self, v: float) -> tuple[float, float]:
        """Lowest and highest output reachable at command ``v`` (the loop's boundaries)."""
        m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = self.p
        lower = initial_output(v, m_r, m_t, m_b, c_r, c_t, c_b)
        upper = max(min(m_t * v + c_t, m_l * (v - c_l)), m_b * v + c_b)
        return lower, upper

    def reset(self, v0: float, u0: float | None = None) -> None:
        """State at ``v0``: on the rising boundary, or ``u0`` projected into the loop."""
        lower, upper = self.output_range(float(v0))
        self._v = float(v0)
        self._u = lower if u0 is None else min(max(float(u0), lower), upper)

    @property
    def command(self) -> float:
        """Last command."""
        return self._v

    @property
    def output(self) -> float:
        """Output in the state."""
        return self._u

    def command_for(self, u_d: float) -> float:
        """Command that makes the loop output ``u_d`` next."""
        return hysteresis_inverse_step(u_d, self._v, self._u, *self.p)

    def advance(self, v: float) -> float:
        """Move the state with command ``v``."""
        self._u = hysteresis_step(v, self._v, self._u, *self.p)
        self._v = float(v)
        return self._u


class TaoKokotovic(HysteresisFamily):
    """The paper's 8-parameter piecewise-linear loop (family ``tk``)."""

    id = 'tk'  # noqa: A003
    title = "Krasnosel'skii / Tao-Kokotovic piecewise-linear loop (the paper's)"
    names = HYSTERESIS_NAMES
    units = UNITS
    paper_domains = PAPER_DOMAINS

    def check(self, params: np.ndarray) -> np.ndarray:
        """Validate (see :func:`check_hysteresis`)."""
        return check_hysteresis(params)

    def feasible_rows(self, pop: np.ndarray) -> np.ndarray:
        """``c_l < c_r`` and a proper loop, per row (any command frame)."""
        return _feasible_rows(np.ascontiguousarray(pop, dtype=np.float64), True)

    def loose_rows(self, pop: np.ndarray) -> np.ndarray:
        """The paper's slopes only, per row: loops whose output jumps are admitted.

        With the corners out of order (the left line meeting the bottom or the top
        line right of where the right line does) the step rule jumps at some
        reversals; an independent simulator of the paper's equations draws such
        loops, so :mod:`hyst_id.identification.loose_phase` searches them too.
        """
        return _feasible_rows(np.ascontiguousarray(pop, dtype=np.float64), False)

    def check_simulable(self, params: np.ndarray) -> np.ndarray:
        """Validate for simulation only: the slopes, the corners in any order."""
        return check_hysteresis(params, proper=False)

    def paper_frame_rows(self, pop: np.ndarray) -> np.ndarray:
        """The paper's ``c_t > c_b`` (at command 0) and ``c_l < c_r`` (at output 0), per row."""
        pop = np.atleast_2d(pop)
        return (pop[:, 6] > pop[:, 7]) & (pop[:, 4] < pop[:, 5])

    def simulate_rows(self, pop: np.ndarray, v: np.ndarray, ok: np.ndarray,
                      out: np.ndarray) -> None:
        """H's output per feasible row, from the rising boundary at ``v[0]``."""
        _simulate_rows(pop, v, ok, out)

    def map_output(self, params: np.ndarray, alpha: float, delta: float) -> np.ndarray:
        """Slopes times ``alpha``; output lines shifted by ``delta``, side lines moved to match."""
        p = np.array(params, dtype=np.float64)
        p[0:4] *= alpha
        p[4] -= delta / p[0]
        p[5] -= delta / p[1]
        p[6] = alpha * p[6] + delta
        p[7] = alpha * p[7] + delta
        return p

    def map_input(self, params: np.ndarray, a: float, b: float) -> np.ndarray:
        """The loop for ``v = a v_m + b``: every slope over ``a``, the lines moved to match.

        Side lines ``u = m (v_m - c)`` cross at ``a c + b``; flat lines
        ``u = m v_m + c`` get the intercept ``c - m b / a``.
        """
        p = np.array(params, dtype=np.float64)
        m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p[:8]
        p[:8] = (m_l / a, m_r / a, m_t / a, m_b / a, a * c_l + b, a * c_r + b,
                 c_t - m_t * b / a, c_b - m_b * b / a)
        return p

    def domains(self, box: LoopBox) -> dict[str, tuple[float, float]]:
        """Domains of a loop in ``box``.

        Side slopes up to ``steep``, flat ones up to ``flat_max`` mean slopes;
        crossings of every such line through the output box at a command in
        the widened range.
        """
        side = (box.slope_min * box.slope, box.steep * box.slope)
        c_side = _crossing_range(box.v_lo, box.v_hi, box.u_lo, box.u_hi, *side)
        c_flat = _intercept_range(box.v_lo, box.v_hi, box.u_lo, box.u_hi,
                                  box.flat_max * box.slope)
        return {'m_l': (0.0, box.steep * box.slope), 'm_r': (0.0, box.steep * box.slope),
                'm_t': (0.0, box.flat_max * box.slope), 'm_b': (0.0, box.flat_max * box.slope),
                'c_l': c_side, 'c_r': c_side, 'c_t': c_flat, 'c_b': c_flat}

    def starts(self, box: LoopBox, width: float | None = None) -> list[np.ndarray]:
        """Loops of width ``width`` (default the measured one) centred in the box.

        Side slopes of one and two mean slopes, flat inner lines (a tenth of
        the mean slope), top and bottom lines met a tenth of the span inside
        the commanded range's ends.
        """
        w = box.loop_width if width is None else width
        v_mid = 0.5 * (box.v_min + box.v_max)
        u_mid = 0.5 * (box.u_lo + box.u_hi)
        span = box.span_v or 1.0
        v1, v2 = box.v_max - 0.1 * span, box.v_min + 0.1 * span
        out = []
        for k in (1.0, 2.0):
            m, m_t = k * box.slope, 0.1 * box.slope
            c_l = v_mid - 0.5 * w - u_mid / m
            c_r = v_mid + 0.5 * w - u_mid / m
            c_t = m * (v1 - c_r) - m_t * v1
            c_b = m * (v2 - c_l) - m_t * v2
            out.append(np.array([m, m, m_t, m_t, c_l, c_r, c_t, c_b]))
        return [x for x in out if self.feasible_rows(x[None, :])[0]]

    def inverse(self, params: np.ndarray) -> TaoKokotovicInverse:
        """Exact inverse with its own state."""
        return TaoKokotovicInverse(params)

    def unexcited(self, params: np.ndarray, command: np.ndarray,
                  command_unit: str = '') -> tuple[list[str], set[str]]:
        """Lines of the loop the command never drives H along (see :mod:`.tk_lines`)."""
        try:    # an improper loop (the loose phase's) has lines too
            p = check_hysteresis(np.asarray(params, dtype=float)[:8], proper=False)
        except InvalidParametersError:
            return [], set()
        return unexcited_lines(p, command, self.simulate(p, command, validate=False),
                               loop_corners(p), command_unit)

    def describe(self, params: np.ndarray) -> dict[str, float]:
        """Corner commands and outputs of the major loop, and its width at mid height."""
        c = loop_corners(params)
        out = {}
        for k, (v, u) in c.items():
            out[f'corner_{k}_cmd'] = float(v)
            out[f'corner_{k}_out'] = float(u)
        return out


#: The family instance the registry holds.
FAMILY = TaoKokotovic()
