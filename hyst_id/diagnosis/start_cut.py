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

"""A diagnosis of a record that starts inside the play: cut it at the first reversal.

The chain starts on an edge of its loop
(:mod:`hyst_id.identification.start_state`). An actuator resting inside
its play is on neither edge until the command first reverses, and a
baseline fitted to the whole training part bends to meet that stretch.
What is left then looks like physics: a 20 s rest inside a play was named
``rate_dependence`` and ``creep``, a start inside it with no rest
``unknown``.

:func:`start_cut` decides, after the baseline, whether to diagnose the
record from its first reversal on instead. It asks for what identify asks
(:func:`~hyst_id.identification.start_state.refit_start`: a baseline above
1.5 x its floor, three reversals, half the record after the first) and
more: a probe (the baseline's GAASS seeds refined, no global phase, no
hopping) on the cut record's training part must end within
:data:`PROBE_NEAR` x its floor and :data:`~hyst_id.identification.quality.
FIT_FACTOR` x closer to it than the baseline. A missing block that the cut
does not remove keeps the probe away from its floor, so a record with an
effect is diagnosed whole, as before.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from hyst_id.diagnosis.baseline import identify_base
from hyst_id.diagnosis.result import DiagnoseSettings
from hyst_id.diagnosis.split_notes import MIN_HELDOUT_SAMPLES, MIN_TRAIN_SAMPLES
from hyst_id.errors import NoExcitationError
from hyst_id.identification import identify, IdentifySettings
from hyst_id.identification.chains import ChainSpec
from hyst_id.identification.quality import FIT_FACTOR
from hyst_id.identification.start_state import left_out_note, refit_start
from hyst_id.io.recording import Recording
from hyst_id.signals.split import split_index

__all__ = ['other_boundary', 'PROBE_NEAR', 'StartCut', 'start_cut']

#: The probe from the first reversal must end within this many times its noise floor.
PROBE_NEAR = 1.3


@dataclass(frozen=True)
class StartCut:
    """Where to cut the record, and the words that say why."""

    index: int
    before_ratio: float
    probe_ratio: float
    note: str


def start_cut(rec: Recording, command_model: np.ndarray, spec: ChainSpec,
              settings: DiagnoseSettings, er_train_percent: float,
              floor_train_percent: float) -> StartCut | None:
    """The first reversal's sample when the record is better diagnosed from there, else None.

    Parameters
    ----------
    rec : Recording
        The whole record, in its own units.
    command_model : numpy.ndarray
        Its command in the chain's units (what ``spec`` is searched in).
    spec : ChainSpec
        The baseline's chain and domains.
    settings : DiagnoseSettings
        The diagnosis's settings (the probe takes its seeds and GAASS sizes).
    er_train_percent, floor_train_percent : float
        The baseline's training %e_r and the training part's noise floor.

    Returns
    -------
    StartCut or None
    """
    k = refit_start(rec.command, er_train_percent, floor_train_percent, factor=FIT_FACTOR)
    if k is None:
        return None
    rest_t = rec.t_s[k:]
    n_train = split_index(rest_t, settings.train_fraction)
    if n_train < MIN_TRAIN_SAMPLES or rest_t.size - n_train < MIN_HELDOUT_SAMPLES:
        return None     # the record from there is too short to diagnose (require_split)
    part = Recording(rest_t[:n_train], command_model[k:k + n_train],
                     rec.measurement[k:k + n_train], rec.channel, source=rec.source)
    try:
        probe = identify(part, spec=spec, settings=IdentifySettings(**{
            **identify_base(settings), 'seeds': tuple(settings.seeds)[:2], 'hops': 0,
            'global_runs': 0}), should_stop=settings.should_stop)
    except NoExcitationError:
        return None     # from its first reversal on, the record no longer excites the loop
    if not probe.noise_floor_percent > 0:
        return None
    before = er_train_percent / floor_train_percent
    after = probe.er_percent / probe.noise_floor_percent
    if after > PROBE_NEAR or after * FIT_FACTOR > before:
        return None
    words = left_out_note(rec.t_s, k, before, after)
    note = (words.replace('left out of the fit', 'left out of the diagnosis')
            + ' (the training part from there, identified without a global phase); '
            'everything below is of the record from there on')
    return StartCut(k, before, after, note)


def other_boundary(initial: str, spec: ChainSpec, mechs: list) -> tuple[ChainSpec, list, str]:
    """The spec and the library for a baseline that starts on the other boundary, and words.

    :func:`hyst_id.diagnosis.challenge.chain_fit` keeps a chain starting on the
    other boundary of its loops only where the training part says so clearly; the
    whole diagnosis then runs in it. Blocks that simulate the actuator themselves
    (stage ``'actuator'``) start it rising and are left out. An independent
    reviewer's clean record, whose actuator started near its falling edge, was
    diagnosed rising and claimed an offset drift.
    """
    if initial == spec.initial:
        return spec, mechs, ''
    left = [m.id for m in mechs if m.stage == 'actuator']
    note = (f'the chain starts on the {initial} boundary of its loops: its training part '
            f'fits clearly better so, at its start, than on the {spec.initial} one (as after '
            f'a command that came {"down from above" if initial == "falling" else "up"} '
            'before the record), and the whole diagnosis runs so'
            + (f'; {", ".join(left)}, which start the actuator rising, not tried' if left
               else ''))
    return (replace(spec, initial=initial), [m for m in mechs if m.stage != 'actuator'],
            note)
