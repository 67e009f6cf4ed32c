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

"""The quality gate: whether an identified set may be handed to a compensator unasked.

An identification can end well above the noise floor (the model misses
physics) or leave parameters the recording pins down poorly; the CLI warns
about both, and a node that pushes such a set into a running compensator
would act on it silently. :class:`QualityGate` names the reasons to hold a
set back; the identifier node then publishes the result with
``compensator_params: null`` and the reasons, keeps its params file and the
compensator's set as they were, and reports WARN on ``/diagnostics``.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Any

__all__ = ['QualityGate']


@dataclass(frozen=True)
class QualityGate:
    """When an identified set is not handed over automatically.

    Attributes
    ----------
    max_floor_ratio : float
        Hold back a set whose %e_r exceeds this multiple of the noise floor
        (0 = no limit). 3 by default: a fit at the floor is about 1, a model
        that misses part of the response several times that.
    max_uncertainty : float
        Hold back a set in which a parameter's uncertainty (spread over the
        converged seeds or standard error, relative to its scale:
        ``Identification.poorly_determined``) exceeds this (0 = no limit).
        1 by default: the CLI warns from 5 %; a parameter known to no
        better than its own scale (or not at all: ``inf``) is what is meant
        by unidentifiable. (A 60 s simulated position run leaves a small
        backlash at about 60 % of its scale: near the gate, not over it.)
    """

    max_floor_ratio: float = 3.0
    max_uncertainty: float = 1.0

    def reasons(self, ident: Any) -> list[str]:
        """Why ``ident`` (an :class:`~hyst_id.identification.Identification`) is held back.

        An empty list means it passes.
        """
        out = []
        floor = float(getattr(ident, 'noise_floor_percent', math.nan))
        er = float(ident.er_percent)
        if self.max_floor_ratio > 0 and floor > 0 and math.isfinite(floor) \
                and er > self.max_floor_ratio * floor:
            out.append(f'%e_r {er:.4g} is {er / floor:.1f} x the noise floor {floor:.4g} '
                       f'(gate: {self.max_floor_ratio:g} x): the model misses part of the '
                       'response')
        poor = dict(getattr(ident, 'poorly_determined', None) or {})
        bad = {n: u for n, u in poor.items() if self.max_uncertainty > 0
               and not u <= self.max_uncertainty}
        if bad:
            out.append('not identifiable from this recording: ' + ', '.join(
                f'{n} (uncertainty {"unbounded" if not math.isfinite(u) else f"{u:.0%}"} of '
                'its scale)' for n, u in bad.items())
                + f' (gate: {self.max_uncertainty:.0%})')
        return out

    def to_dict(self, reasons: list[str]) -> dict:
        """The gate's settings and verdict, JSON-ready."""
        return {'passed': not reasons, 'reasons': list(reasons),
                'max_floor_ratio': self.max_floor_ratio,
                'max_uncertainty': self.max_uncertainty}
