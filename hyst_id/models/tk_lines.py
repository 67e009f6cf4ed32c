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

"""Which line of the ``tk`` loop sets H's output at each sample, and which lines go unused.

A line that the command never drives H along leaves its parameters
undetermined; identification warns about it
(:meth:`hyst_id.models.tk.TaoKokotovic.unexcited`).
"""

from __future__ import annotations

import numpy as np

from hyst_id.io.numbers import level

__all__ = ['BARELY', 'FAR_SPANS', 'LINE_PARAMS', 'active_lines', 'unexcited_lines']

#: A line followed over less than this fraction of the command span is barely excited.
BARELY = 0.02

#: A corner more than this many command spans (and this many times the largest command)
#: beyond the commands is not a level to drive to: the fit has placed the line anywhere (a
#: new user's dropout record: the top-right corner at 744942 for commands within +-1).
FAR_SPANS = 10.0

#: Parameters each line of the loop determines.
LINE_PARAMS = {'left': ('m_l', 'c_l'), 'right': ('m_r', 'c_r'), 'top': ('m_t', 'c_t'),
               'bottom': ('m_b', 'c_b')}


def _line_terms(params: np.ndarray, command: np.ndarray, u: np.ndarray
                ) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, np.ndarray]]:
    """H's output, and per line the samples it sets and how much it moves the output there.

    The *depth* of a line at a sample is how far the output would be from
    its value if that line were absent (the right line lifts the output off
    the inner rising line, the top line caps it, ...).
    """
    p = np.asarray(params, dtype=float)[:8]
    m_l, m_r, m_t, m_b, c_l, c_r, c_t, c_b = p
    v = np.asarray(command, dtype=float)
    u = np.asarray(u, dtype=float)
    vp, up, vj, uj = v[:-1], u[:-1], v[1:], u[1:]
    tol = 1e-9 * (1.0 + np.abs(uj))
    rise = vj > vp
    fall = vj < vp
    inner_up = m_b * vj + (up - m_b * vp)
    right = m_r * (vj - c_r)
    top = m_t * vj + c_t
    inner_down = m_t * vj + (up - m_t * vp)
    left = m_l * (vj - c_l)
    bottom = m_b * vj + c_b
    on_top = rise & (top <= np.maximum(inner_up, right) + tol)
    on_right = rise & ~on_top & (right >= inner_up - tol)
    on_bottom = fall & (bottom >= np.minimum(inner_down, left) - tol)
    on_left = fall & ~on_bottom & (left <= inner_down + tol)
    masks = {'left': on_left, 'right': on_right, 'top': on_top, 'bottom': on_bottom,
             'rising': rise & ~on_top & ~on_right, 'falling': fall & ~on_bottom & ~on_left}
    depth = {'top': np.where(on_top, np.maximum(inner_up, right) - top, 0.0),
             'right': np.where(on_right, np.minimum(right, top) - inner_up, 0.0),
             'bottom': np.where(on_bottom, bottom - np.minimum(inner_down, left), 0.0),
             'left': np.where(on_left, inner_down - np.maximum(left, bottom), 0.0)}
    pad = np.zeros(1, dtype=bool)
    return (u, {k: np.concatenate([pad, m]) for k, m in masks.items()},
            {k: np.concatenate([[0.0], d]) for k, d in depth.items()})


def active_lines(params: np.ndarray, command: np.ndarray,
                 u: np.ndarray) -> dict[str, np.ndarray]:
    """Which line of the loop sets H's output at each sample.

    Parameters
    ----------
    params : numpy.ndarray
        Hysteresis parameters (the first 8 of a chain vector).
    command : numpy.ndarray
        Command per sample.
    u : numpy.ndarray
        H's output for that command (:func:`hyst_id.models.tk.simulate_hysteresis`).

    Returns
    -------
    dict
        Boolean masks ``left``, ``right``, ``top``, ``bottom``, ``rising``
        (inner lines of slope ``m_b``) and ``falling`` (slope ``m_t``); the
        first sample and samples where the command holds belong to none.
    """
    return _line_terms(params, command, u)[1]


def unexcited_lines(params: np.ndarray, command: np.ndarray, u: np.ndarray,
                    corners: dict[str, tuple[float, float]],
                    command_unit: str = '') -> tuple[list[str], set[str]]:
    """Warn about lines of the identified loop that the command never drives H along.

    A line that H follows over less than 2 % of the command span, and that
    moves the output off the other lines by less than 2 % of the output span
    (a top line touched only at its corner), leaves its parameters
    undetermined; a left or right line that moves the output over a short
    stretch of command is a jump whose slope is undetermined.

    Returns
    -------
    warnings : list of str
        One per line never (or barely) followed, or steeper than resolved.
    names : set of str
        Parameters left undetermined by those lines.
    """
    v = np.asarray(command, dtype=float)
    span = float(np.ptp(v))
    x = np.asarray(params, dtype=float)[:8]
    u, masks, depth = _line_terms(x, v, u)
    unit = f' {command_unit}' if command_unit else ''
    where = {
        'top': ('rises', 'above', corners['C'][0], 'top-right corner'),
        'bottom': ('falls', 'below', corners['A'][0], 'bottom-left corner'),
        'right': ('rises', 'above', corners['B'][0], 'bottom-right corner'),
        'left': ('falls', 'below', corners['D'][0], 'top-left corner'),
    }
    inner = {'top': 'falling', 'bottom': 'rising'}
    span_u = float(np.ptp(u)) or 1.0
    out, names = [], set()
    for line, (verb, side, v_corner, corner) in where.items():
        mask = masks[line]
        travel_v = float(np.ptp(v[mask])) / span if mask.sum() >= 2 else 0.0
        travel_u = float(np.ptp(u[mask])) / span_u if mask.sum() >= 2 else 0.0
        reach = float(np.max(depth[line])) / span_u
        if travel_v < BARELY <= max(travel_u, reach) and line in ('left', 'right'):
            slope = LINE_PARAMS[line][0]
            names.add(slope)
            out.append(f'the {line} line of the loop is steeper than the recording '
                       f'resolves (the output crosses {100 * max(travel_u, reach):.0f} % of '
                       f'its span within {100 * travel_v:.1f} % of the command span): {slope} '
                       f'only says "a jump", {LINE_PARAMS[line][1]} places it')
        if max(travel_v, travel_u, reach) >= BARELY:
            continue
        undetermined = list(LINE_PARAMS[line])
        if line in inner and masks[inner[line]].sum() >= 3:
            undetermined = undetermined[1:]      # the slope still shows on inner lines
        names.update(undetermined)
        extreme = float(v.max() if verb == 'rises' else v.min())
        what = (f'{" and ".join(undetermined)} '
                f'{"is" if len(undetermined) == 1 else "are"} not identifiable from this '
                'recording')
        short = (extreme < v_corner) if verb == 'rises' else (extreme > v_corner)
        vspan = float(np.ptp(v))
        far = FAR_SPANS * max(vspan, float(np.max(np.abs(v))))
        if short and abs(v_corner - extreme) > far:
            out.append(f'the {line} line of the loop is never reached: the fit puts the '
                       f'{corner} at {level(v_corner, vspan)}{unit}, far beyond any command '
                       f'recorded ({abs(v_corner - extreme) / vspan:.0f} command spans past '
                       f'{level(extreme, vspan)}{unit}): the recording does not say where it '
                       f'is, and it is no level to drive to; {what}')
        elif short:
            out.append(f'the {line} line of the loop is never reached: the command {verb} '
                       f'to {level(extreme, vspan)}{unit} but the {corner} of the loop is at '
                       f'{level(v_corner, vspan)}{unit}; {what} (drive the command {side} '
                       f'{level(v_corner, vspan)}{unit} to identify it)')
        else:
            out.append(f'the {line} line of the loop barely matters here (it sets the output '
                       f'over less than {100 * BARELY:.0f} % of the command span and moves it '
                       f'by less than {100 * BARELY:.0f} % of its span); {what}')
    return out, names
