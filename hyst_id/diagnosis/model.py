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

"""The paper's chain with mechanism blocks inserted at their physical places.

``v -> [command] -> H -> B -> [position] -> [quantity] -> sensor -> [sensor]
-> (linear calibration + [output] regressors) -> y``

The parameter vector is the chain's own (:meth:`hyst_id.identification.chains.ChainSpec.names`,
in the chain's search space) followed by each mechanism's searched
parameters. Everything that enters linearly (the affine calibration ``k,
b``, the static nonlinearity's polynomial terms, the drift rate, the
supply-decay offset) is a column of a regressor matrix and is profiled by
linear least squares on the training samples only; the same coefficients
then predict the held-out samples (variable projection).

Every dynamic element after the static loop (the channel's sensor, the
``sensor``-stage blocks) is a zero-order-hold filter, in one of the two
conventions of :data:`hyst_id.identification.chains.HOLDS` (the model's
``hold``): ``before`` takes sample ``j``'s input as held over
``(t(j-1), t(j)]``, ``after`` holds ``x(j-1)`` over ``[t(j-1), t(j))``,
one sample later, as other simulators and sampled rigs do. The diagnosis
lets the data choose (:func:`held`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Sequence

import numpy as np

from hyst_id.diagnosis.mechanisms.base import Context, Mechanism, STAGES
from hyst_id.errors import ConfigError
from hyst_id.identification.chains import chain_spec, HOLDS, INITIAL_STATES
from hyst_id.models.sensors import simulate_first_order, simulate_second_order

__all__ = ['ComposedModel', 'Evaluation', 'held', 'solve_linear']


def held(x: np.ndarray, hold: str) -> np.ndarray:
    """A filter's input in the package's convention for the ``hold`` convention.

    The package's filters (:mod:`hyst_id.models.sensors`) hold sample ``j``
    over ``(t(j-1), t(j)]``; with ``hold='after'`` it is ``x(j-1)`` that is
    held there, so the input is moved one sample later (the first kept).
    """
    x = np.asarray(x, dtype=float)
    if hold == 'before' or x.size < 2:
        return x
    return np.concatenate([x[:1], x[:-1]])


class Evaluation:
    """Regressor columns of one parameter vector over some samples."""

    __slots__ = ('columns', 'labels', 'span', 'travel_raw')

    def __init__(self, columns: list[np.ndarray], labels: list[str],
                 span: tuple[float, float], travel_raw: np.ndarray) -> None:
        self.columns = columns
        self.labels = labels
        self.span = span
        self.travel_raw = travel_raw

    def matrix(self, rows: slice | None = None) -> np.ndarray:
        """Regressor matrix (samples x columns)."""
        a = np.column_stack(self.columns)
        return a if rows is None else a[rows]


class ComposedModel:
    """A channel's chain plus an ordered set of mechanisms.

    Parameters
    ----------
    channel : str
        ``position``, ``pressure`` or ``flow``.
    mechanisms : sequence of Mechanism
        Blocks to insert (sorted into signal order here).
    ctx : Context
        Recording facts the blocks need.
    chain_bounds : numpy.ndarray
        ``(n_chain, 2)`` bounds of the chain's parameters.
    family : str, optional
        H's family (default the paper's ``tk``).
    swapped_by : str, optional
        Id of the mechanism that swapped H's family in (listed first in :attr:`ids`).
    hold : {'before', 'after'}, optional
        Zero-order-hold convention of every dynamic element (see the module docstring).
    initial : {'rising', 'falling'}, optional
        The boundary of their loops H and B start on (``ChainSpec.initial``); blocks
        that simulate the actuator themselves (:attr:`Mechanism.stage` ``'actuator'``)
        start it rising and are not used with a falling start.
    proper : bool, optional
        Whether H's loops must be proper (``ChainSpec.proper``, the default) or may
        be any the paper's constraints admit (a baseline that only such a loop
        fits: :func:`hyst_id.diagnosis.loose_baseline.loose_baseline`).
    """

    def __init__(self, channel: str, mechanisms: Sequence[Mechanism], ctx: Context,
                 chain_bounds: np.ndarray, family: str | None = None,
                 swapped_by: str = '', hold: str = 'before', initial: str = 'rising',
                 proper: bool = True) -> None:
        if hold not in HOLDS:
            raise ConfigError(f'hold must be one of {HOLDS}, got {hold!r}')
        if initial not in INITIAL_STATES:
            raise ConfigError(f'initial must be one of {INITIAL_STATES}, got {initial!r}')
        if initial != 'rising' and any(m.stage == 'actuator' for m in mechanisms):
            raise ConfigError('blocks that simulate the actuator start it rising: '
                              + ', '.join(m.id for m in mechanisms if m.stage == 'actuator'))
        self.channel = channel
        self.hold = hold
        self.initial = initial
        self.swapped_by = swapped_by
        self.ctx = ctx
        self.mechanisms = tuple(sorted(mechanisms, key=lambda m: STAGES.index(m.stage)))
        self.spec = replace(chain_spec(channel, family=family, initial=initial), proper=proper)
        self.position_spec = replace(chain_spec('position', family=family, initial=initial),
                                     proper=proper)
        self.n_chain = self.spec.n_params
        bounds = [np.asarray(chain_bounds, dtype=float)]
        self.slices: dict[str, slice] = {}
        k = self.n_chain
        for m in self.mechanisms:
            nb = m.bounds(ctx)
            bounds.append(nb)
            self.slices[m.id] = slice(k, k + nb.shape[0])
            k += nb.shape[0]
        self.bounds = np.vstack(bounds) if bounds else np.zeros((0, 2))
        self.n_params = k

    @property
    def ids(self) -> tuple[str, ...]:
        """Mechanism ids in signal order (a family swap first)."""
        return ((self.swapped_by,) if self.swapped_by else ()) + tuple(
            m.id for m in self.mechanisms)

    @property
    def dynamic(self) -> bool:
        """Whether any element is a filter, i.e. whether :attr:`hold` matters."""
        return self.channel != 'position' or any(m.stage == 'sensor' for m in self.mechanisms)

    @property
    def n_linear(self) -> int:
        """Linear (profiled) parameters: calibration and the blocks' own."""
        return 2 + sum(m.n_linear for m in self.mechanisms)

    @property
    def n_free(self) -> int:
        """Parameter count for the information criterion.

        The chain's gauge (two directions between H and B, two between B and
        the calibration, see :mod:`hyst_id.identification.gauge`) leaves ``n_chain - 2``
        identifiable parameters for the chain and its calibration together.
        """
        return self.n_chain - 2 + (self.n_linear - 2) + (self.n_params - self.n_chain)

    def theta(self, p: np.ndarray, mech_id: str) -> np.ndarray:
        """Searched parameters of one mechanism within ``p``."""
        return p[self.slices[mech_id]]

    def pack(self, x_chain: np.ndarray, thetas: dict[str, np.ndarray]) -> np.ndarray:
        """Full parameter vector from the chain's and each block's."""
        parts = [np.asarray(x_chain, dtype=float)]
        for m in self.mechanisms:
            parts.append(np.asarray(thetas.get(m.id, m.null(self.ctx)), dtype=float))
        return np.concatenate(parts)

    def feasible(self, p: np.ndarray) -> bool:
        """Chain constraints and finiteness."""
        if not np.all(np.isfinite(p)):
            return False
        return bool(self.spec.feasible(p[None, :self.n_chain])[0])

    def evaluate(self, p: np.ndarray, t_s: np.ndarray, v: np.ndarray,
                 n_span: int) -> Evaluation:
        """Regressor columns for samples ``t_s, v`` (the first ``n_span`` set the travel).

        ``p`` must be feasible (see :meth:`feasible`).
        """
        x_chain = p[:self.n_chain]
        th = {m.id: p[self.slices[m.id]] for m in self.mechanisms}
        vv = v
        for m in self.mechanisms:
            if m.stage == 'command':
                vv = m.command(th[m.id], t_s, vv)
        x = None
        for m in self.mechanisms:
            if m.stage == 'actuator':
                x = m.actuator(th[m.id], x_chain, t_s, vv)
        if x is None:
            x = self.position_spec.signal(x_chain[:self.spec.sensor_slice.start], t_s, vv,
                                          validate=False)     # p is feasible
        seg = x[:max(2, n_span)]
        lo, hi = float(np.min(seg)), float(np.max(seg))
        if not hi > lo:
            hi = lo + 1e-12
        span = (lo, hi)
        travel_raw = x
        for m in self.mechanisms:
            if m.stage == 'position':
                x = m.position(th[m.id], x, span)
        basis = [x]
        terms: list[np.ndarray] = []
        term_labels: list[str] = []
        for m in self.mechanisms:
            if m.stage == 'quantity':
                b = m.quantity(th[m.id], x, span)
                if b is not None:
                    basis = b
                own = m.quantity_terms(th[m.id], x, span)
                terms += own
                term_labels += [f'{m.id}:{i}' for i in range(len(own))]
        n_basis = len(basis)
        basis = [self._sensor(x_chain, t_s, b) for b in basis + terms]
        for m in self.mechanisms:
            if m.stage == 'sensor':
                basis = [m.sensor(th[m.id], t_s, held(b, self.hold)) for b in basis]
        labels = (['sensor'] + [f'quantity:{i}' for i in range(1, n_basis)] + term_labels
                  + ['offset'])
        columns = basis + [np.ones_like(t_s)]
        for m in self.mechanisms:
            if m.stage == 'output':
                new = m.output(th[m.id], t_s, columns, self.ctx)
                added = len(new) - len(columns)
                labels = labels[:-1] + [f'{m.id}:{i}' for i in range(added)] + labels[-1:]
                columns = new
        return Evaluation(columns, labels, span, travel_raw)

    def _sensor(self, x_chain: np.ndarray, t_s: np.ndarray, s: np.ndarray) -> np.ndarray:
        sensor = x_chain[self.spec.sensor_slice]
        if self.channel != 'position':
            s = held(s, self.hold)
        if self.channel == 'pressure':
            return simulate_first_order(s, t_s, float(sensor[0]))
        if self.channel == 'flow':
            return simulate_second_order(s, t_s, float(sensor[0]), float(sensor[1]))
        return s


def solve_linear(a: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares coefficients of ``y ~ a @ coef`` and the residual sum of squares.

    Normal equations on norm-scaled columns (a handful of columns: much
    cheaper than an SVD per call), with a tiny ridge for collinear columns;
    the residual is then computed directly, so coefficient round-off only
    enters the sum of squares at second order.
    """
    g = a.T @ a
    scale = np.sqrt(np.diagonal(g))
    scale = np.where(scale > 0, scale, 1.0)
    g = g / np.outer(scale, scale)
    g.flat[::g.shape[0] + 1] += 1e-12
    try:
        coef = np.linalg.solve(g, (a.T @ y) / scale)
    except np.linalg.LinAlgError:
        coef, *_ = np.linalg.lstsq(a / scale, y, rcond=1e-10)
    coef = coef / scale
    r = y - a @ coef
    return coef, float(r @ r)
