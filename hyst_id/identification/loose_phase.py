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

"""The loose phase of :func:`~hyst_id.identification.driver.identify`: loops whose output jumps.

The package searches *proper* loops (the corner order of ``docs/model.md``:
the left line meets the bottom and the top lines left of where the right line
does), because only on those is H⁻¹ an exact inverse. The paper's constraints
(``m_l, m_r > 0``, ``min(m_l, m_r) > m_t, m_b > 0``, ``c_l < c_r``) admit more:
loops whose corners are out of order, on which the same step rule makes the
output jump at some reversals. An independent simulator of the paper's
equations that draws its parameters under the paper's constraints makes such
loops often (most of an independent reviewer's random chains), and the proper
search then stopped well above the noise floor where a plain CMA-ES over the
paper's set reached it (``bench/improper_loops.py --without-loose``).

So when the proper identification ends above ``settings.global_factor`` x the
floor, it runs again over the loose set (:attr:`ChainSpec.proper` false: the
seeds, hopping and the global phase; beyond :data:`LOOSE_WITHIN` x the floor only
when a quick loose fit comes within it first): the
paper's slopes, the corners in any order; the paper's ``c_l < c_r`` only in its
own frame (it compares the lines at output 0, which the profiled calibration
moves). The loose fit is kept only when its %e_r is below :data:`LOOSE_GAIN`
times the proper one's, or when it reaches the floor (``global_factor`` x) and the
proper one is ``global_factor`` times above it (:func:`kept_loose`). Its first
warning then says the loop is not proper, where its corners are and that the
compensator refuses it (``check_hysteresis``: H⁻¹ is no exact inverse of a loop
that jumps). ``python bench/improper_loops.py``
prints what it does on proper and improper chains of the reference simulator.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

from hyst_id.identification.chains import ChainSpec
from hyst_id.identification.result import Identification, IdentifySettings
from hyst_id.models.tk import loop_corners

__all__ = ['improper_words', 'kept_loose', 'LOOSE_GAIN', 'LOOSE_WITHIN', 'loose_retry',
           'misordered_corners']

#: The loose search runs in full when the proper fit ends within this multiple of the floor.
#: Further off the misfit is mostly physics the chain lacks (the shared real recordings end at
#: 44-108 x, ``bench/real_recordings.py``), so a quick loose fit (two seeds, no restarts,
#: hopping or global phase) looks first, and the full search follows only when it ends within this
#: multiple: ``bench/cmaes_review.py --seeds 1 2`` (draws 1:r1 and 2:r1, improper loops the
#: proper search left at 42 x the true noise).
LOOSE_WITHIN = 20.0

#: A loose fit is kept when its %e_r is below this share of the proper fit's.
LOOSE_GAIN = 0.8


def loose_retry(ident: Identification, spec: ChainSpec, settings: IdentifySettings,
                run: Callable[[ChainSpec, IdentifySettings, bool], Identification]
                ) -> Identification:
    """``ident``, or the identification over the paper's wider set when it fits clearly better.

    Parameters
    ----------
    ident : Identification
        The identification over proper loops.
    spec : ChainSpec
        The chain it searched (proper).
    settings : IdentifySettings
        ``loose_loops`` (off: ``ident`` as it is), ``refine``, ``global_factor``.
    run : callable
        ``run(spec, settings, quiet)`` identifies again in another chain spec
        (``quiet``: without reporting its runs as progress, for the quick look).

    Returns
    -------
    Identification
        The loose identification (a warning first when its loop is not proper, and
        ``ident`` as its ``proper_alternative``) when it beats ``ident``'s %e_r clearly
        (:func:`kept_loose`); else ``ident``, with the loose search's evaluations counted
        in ``other_nfev``.
    """
    floor = ident.noise_floor_percent
    if (not settings.loose_loops or not settings.refine or spec.family.id != 'tk'
            or not spec.proper or settings.global_runs <= 0 or settings.global_evals <= 0
            or not ident.er_percent > settings.global_factor * floor):
        return ident
    loose_spec, loose_settings = replace(spec, proper=False), replace(settings, loose_loops=False)
    if ident.er_percent > LOOSE_WITHIN * floor:
        # far off: physics the chain lacks, unless a quick look at the loose set comes near
        probe = run(loose_spec, replace(loose_settings, seeds=settings.seeds[:2], restarts=0,
                                        global_runs=0, hops=0), True)
        if probe.er_percent > LOOSE_WITHIN * floor:
            ident.other_nfev += probe.nfev
            return ident
        ident.other_nfev += probe.nfev
    loose = run(loose_spec, loose_settings, False)
    if not kept_loose(loose.er_percent, ident.er_percent, floor, settings.global_factor):
        ident.other_nfev += loose.nfev
        return ident
    loose.other_nfev += ident.nfev
    words = improper_words(loose, ident.er_percent / floor)
    if words:   # none when the wider search found a better proper loop
        loose.warnings.insert(0, words)
    if not loose.proper:    # what a compensator can still invert
        loose.proper_alternative = ident
    return loose


def kept_loose(loose_percent: float, proper_percent: float, floor_percent: float,
               at_floor: float) -> bool:
    """Whether a loose fit (%e_r) beats the proper one clearly enough to be kept.

    Below :data:`LOOSE_GAIN` x the proper %e_r; or at the floor (within ``at_floor``
    x, ``settings.global_factor``) where the proper fit is ``at_floor`` times above it
    (``bench/improper_loops.py`` #19: the proper loop 1.23 x the true noise, the loose one
    0.99 x, a gain of 0.81).
    """
    return bool(loose_percent < LOOSE_GAIN * proper_percent
                or (loose_percent <= at_floor * floor_percent
                    and loose_percent * at_floor <= proper_percent))


def misordered_corners(h, command_scale: tuple[float, float] = (1.0, 0.0)) -> str:
    """The corner pairs of loop ``h`` that are out of a proper loop's order, in words.

    ``command_scale`` ``(k, b)`` maps the loop's command to the recording's (``k v + b``).
    """
    k, b = command_scale
    corners = {name: k * vu[0] + b for name, vu in loop_corners(h).items()}
    return ', '.join(f'{p} {corners[p]:.4g} > {q} {corners[q]:.4g}'
                     for p, q in (('A', 'B'), ('D', 'C'), ('A', 'D'), ('B', 'C'))
                     if corners[p] > corners[q])


def improper_words(ident: Identification, proper_ratio: float) -> str:
    """What a loop outside the proper set means, or '' for a proper one."""
    if ident.proper:
        return ''
    out = misordered_corners([ident.params[n] for n in ident.names[:8]])
    return (f'the loop that fits is not a proper one: no proper loop came below '
            f"{proper_ratio:.2f} x the noise floor, and the paper's constraints admit loops "
            f'whose corners are out of order (command at the corners: {out}; '
            'A, D: the left line at the bottom and top lines, B, C: the right line). The '
            "paper's step rule makes such a loop's output jump at reversals between those "
            'corners (so does an actuator that snaps). H^-1 is not an exact inverse of it: '
            'the compensator refuses this set')
