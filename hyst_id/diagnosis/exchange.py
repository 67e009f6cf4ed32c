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

"""The exchange step: a lag block chosen early, tried again once the later blocks are in.

A dead time, a sensor lag and a second-order actuator all make the reading lag
the command; which of them a round names is decided on the held-out part
around the chain of that round. When a second effect is still missing then (a
static curve, an end stop, a drift), the held-out part is mostly *its* miss,
and the lag block that predicts it best need not be the one the record has:
on the blind family (``bench/blind_family.py``) a sensor lag with a static
curve (#24) was named ``dead_time``, a sensor lag with an offset drift (#38)
``actuator_dynamics``, although the right block fitted the training part
better in that round.

Once the rounds are over, each finding of :data:`LAGS` is taken out (the rest
polished, :func:`hyst_id.diagnosis.control.without`) and its round's other
lag blocks that were accepted or fitted the training part (``training only``)
are fitted in its place with the later blocks in. A rival replaces the finding
only when, judged against the final model by the acceptance criteria
(:func:`hyst_id.diagnosis.select.compare`: a training BIC lower by 10, a
significant held-out improvement that explains a quarter of what is left above
the floor; not the relative gain, :func:`_better`), and it is plausible (its
own trial's verdict). The finding it replaces is stated beside it (kind
``exchanged``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from hyst_id.diagnosis.control import without
from hyst_id.diagnosis.locate import Localization
from hyst_id.diagnosis.mechanisms.base import Context, Mechanism
from hyst_id.diagnosis.result import DiagnoseSettings
from hyst_id.diagnosis.select import compare, Comparison, Criteria, Data, FitResult
from hyst_id.diagnosis.trial import try_all

__all__ = ['LAGS', 'Exchange', 'exchanged_call', 'exchanges']

#: Blocks that each make the reading lag the command, and may stand in for one another.
LAGS = frozenset({'dead_time', 'sensor_lag', 'actuator_dynamics'})


@dataclass
class Exchange:
    """One finding replaced: its index, the rival's comparison, the model it extended."""

    index: int
    replaced: str
    comparison: Comparison      # the rival judged against ``before`` (its own trial)
    before: FitResult           # the final model without the replaced block
    against_final: Comparison   # the rival's model judged against the final model
    replaced_final: FitResult   # that final model, the replaced block in


def exchanges(current: FitResult, found: list[str], rounds: dict[str, list[Comparison]],
              mechs: list[Mechanism], data: Data, ctx: Context, settings: DiagnoseSettings,
              chain_starts: list[np.ndarray], relocate: Callable[[FitResult], Localization],
              say: Callable[[str], None] = lambda text: None) -> list[Exchange]:
    """Try each lag finding's rivals in its place, the later blocks in; the exchanges made.

    Parameters
    ----------
    current : FitResult
        The final model of the rounds.
    found : list of str
        The findings' mechanisms, in order.
    rounds : dict
        Each finding's round: its comparisons (all candidates).
    mechs, data, ctx, settings, chain_starts :
        As the rounds had them.
    relocate : callable
        The localization of a model's residual (for the rivals' evidence).
    say : callable, optional
        Progress.

    Returns
    -------
    list of Exchange
        In the order made; each later one extends the model the one before made.
    """
    made: list[Exchange] = []
    found = list(found)
    by_id = {m.id: m for m in mechs}
    for i, mid in enumerate(list(found)):
        if mid not in LAGS or len(current.model.mechanisms) < 2:
            continue
        rivals = [by_id[c.mechanism] for c in rounds.get(mid, [])
                  if c.mechanism in LAGS and c.mechanism in by_id and c.mechanism not in found
                  and (c.accepted or c.status == 'training only')]
        before = without(current, mid, data, max_nfev=2 * settings.fit_budget) if rivals else None
        if before is None:
            continue
        say(f'exchange: {", ".join(m.id for m in rivals)} in the place of {mid}, '
            'with the other blocks in')
        tried = try_all(rivals, before, data, ctx, settings, relocate(before), chain_starts)
        judged = []
        for c in tried:
            j = compare(current, c.fit, data, c.mechanism, settings.criteria)
            ok = c.accepted and _better(j, settings.criteria)
            say(f'exchange: {c.mechanism} in the place of {mid}, against the final model: '
                f'training BIC {j.delta_bic:+.0f}, held-out z {j.holdout_z:+.1f}, share '
                f'{j.share:.0%}, gain {j.gain:.1%}, own trial {c.status}: '
                + ('better' if ok else 'not better'))
            if ok:
                judged.append((c, j))
        if not judged:
            continue
        comp, against = min(judged, key=lambda cj: data.judged_er_percent(cj[0].fit))
        say(f'exchange: {comp.mechanism} replaces {mid}')
        made.append(Exchange(index=i, replaced=mid, comparison=comp, before=before,
                             against_final=against, replaced_final=current))
        found[i], current = comp.mechanism, comp.fit
    return made


def _better(j: Comparison, criteria: Criteria) -> bool:
    """A rival in the place of a finding: the criteria, less the relative gain.

    An exchange adds nothing to the model, and near the floor what is left to gain is
    small (blind #24: a sensor lag in the place of a dead time, training BIC -120,
    held-out z 7.1, 58 % of the mismatch beyond the floor, a gain of 3.7 %).
    """
    return (j.delta_bic < -criteria.bic_drop and j.holdout_z > criteria.z_min
            and j.share >= criteria.min_share)


def exchanged_call(x: Exchange, data: Data) -> dict:
    """The replaced finding as its successor's stated alternative (kind ``exchanged``)."""
    return {'mechanism': x.replaced, 'kind': 'exchanged',
            'er_holdout_after_percent': float(x.replaced_final.er_holdout_percent),
            'er_judged_after_percent': float(data.judged_er_percent(x.replaced_final)),
            'er_judged_chosen_percent': float(data.judged_er_percent(x.comparison.fit)),
            'holdout_z': float(x.against_final.holdout_z),
            'delta_bic': float(x.against_final.delta_bic)}
