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

"""Plateaus: a measurement cut into flat stretches at its jumps (stick-slip's events).

Used by :mod:`hyst_id.diagnosis.stick_events`: at each cut the actuator
slipped, and between cuts it was stuck.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ['Plateaus', 'plateaus']


@dataclass(frozen=True)
class Plateaus:
    """A measurement cut into flat stretches at its jumps.

    Attributes
    ----------
    edges : numpy.ndarray
        Segment boundaries (sample indices): segment ``k`` is
        ``edges[k]:edges[k + 1]``; ``edges[0] = 0``, ``edges[-1] = n``.
    levels : numpy.ndarray
        Mean measurement of each segment.
    scatter : float
        Pooled standard deviation inside segments of 3 samples or more.
    held_fraction : float
        Share of samples in segments of 3 samples or more.
    """

    edges: np.ndarray
    levels: np.ndarray
    scatter: float
    held_fraction: float

    @property
    def n_slips(self) -> int:
        """Jumps between plateaus."""
        return int(self.levels.size - 1)

    def is_staircase(self, sigma: float, min_slips: int = 8) -> bool:
        """Whether the record looks like stick-slip: flat plateaus, most samples held."""
        return (self.n_slips >= min_slips and self.held_fraction >= 0.5
                and self.scatter <= 1.5 * sigma)


def plateaus(y: np.ndarray, sigma: float, threshold: float = 3.0, z_keep: float = 4.0,
             jump_share: float = 0.5) -> Plateaus:
    """Cut ``y`` into flat stretches at its jumps.

    Candidate cuts are steps beyond ``threshold * sigma`` (so that a slip of
    a few noise std is rarely missed); neighbouring stretches are then
    merged, the least different pair first, while their means differ by less
    than ``z_keep`` standard errors or by less than ``jump_share`` of the
    median difference (every slip moves by at least the band, so this only
    drops noise: a 5-sigma spike is rare, not absent).

    Parameters
    ----------
    y : numpy.ndarray
        Measurement.
    sigma : float
        Measurement noise standard deviation (robust to the jumps, e.g.
        :func:`hyst_id.diagnosis.locate.noise_std`).
    threshold : float
        Candidate step in noise std (a single difference has ``sqrt(2) sigma``).
    z_keep : float
        Standard errors by which neighbouring means must differ to stay apart.
    jump_share : float
        Share of the median difference between neighbours a cut must reach.

    Returns
    -------
    Plateaus
    """
    y = np.asarray(y, dtype=float)
    sigma = max(float(sigma), 1e-300)
    cuts = np.nonzero(np.abs(np.diff(y)) > threshold * sigma)[0] + 1
    edges = np.concatenate([[0], cuts, [y.size]]).astype(np.int64)
    if cuts.size <= y.size // 2:    # else it moves on most samples: no staircase to refine
        edges = _merge(edges, np.add.reduceat(y, edges[:-1]), sigma, z_keep, jump_share)
    lengths = np.diff(edges)
    levels = np.add.reduceat(y, edges[:-1]) / lengths
    dev = y - np.repeat(levels, lengths)
    long_ = np.repeat(lengths >= 3, lengths)
    n_long = int(np.count_nonzero(long_))
    dof = n_long - int(np.count_nonzero(lengths >= 3))
    scatter = float(np.sqrt(np.sum(dev[long_] ** 2) / dof)) if dof > 0 else float('inf')
    return Plateaus(edges=edges, levels=levels, scatter=scatter,
                    held_fraction=n_long / max(y.size, 1))


def _merge(edges: np.ndarray, sums: np.ndarray, sigma: float, z_keep: float,
           jump_share: float) -> np.ndarray:
    """Merge neighbouring stretches, least different first, until all differ clearly."""
    starts = list(edges[:-1])
    counts = list(np.diff(edges).astype(float))
    totals = list(sums)
    while len(starts) > 1:
        n = np.asarray(counts)
        mean = np.asarray(totals) / n
        diff = np.abs(np.diff(mean))
        z = diff / (sigma * np.sqrt(1.0 / n[:-1] + 1.0 / n[1:]))
        share = diff / max(float(np.median(diff)), 1e-300)
        weak = np.minimum(z / z_keep, share / jump_share)
        k = int(np.argmin(weak))
        if weak[k] >= 1.0:
            break
        counts[k] += counts.pop(k + 1)
        totals[k] += totals.pop(k + 1)
        starts.pop(k + 1)
    return np.asarray(starts + [int(edges[-1])], dtype=np.int64)
