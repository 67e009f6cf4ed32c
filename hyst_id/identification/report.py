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

"""Reports of an identification: Table 1 style text, JSON, figures.

Plots use matplotlib's Agg backend (no display needed).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from hyst_id.identification import Identification
from hyst_id.identification.chains import er_percent, param_units
from hyst_id.identification.quality import floor_says_nothing
from hyst_id.io.jsonable import jsonable
from hyst_id.io.recording import Recording

__all__ = ['MEAN_NOT_A_MODEL', 'format_table', 'write_json', 'plot_identification', 'er_of']

#: The mean of the runs' parameters is called no model when its %e_r exceeds this
#: multiple of the runs' median %e_r (the runs sit on different, equally good sets).
MEAN_NOT_A_MODEL = 2.0


def format_table(ident: Identification, truth: dict | None = None) -> str:
    """Table 1 of the paper for one channel: mean over seeds, best run, spread.

    Parameters
    ----------
    ident : Identification
        The result.
    truth : dict, optional
        Known true (canonical) parameters, shown in an extra column.
    """
    xs = np.array([r.x for r in ident.runs])
    spread = xs.std(axis=0)
    head = f'{"param":8s} {"unit":8s} {"mean":>11s} {"best":>11s} {"std":>9s}'
    if truth:
        head += f' {"true":>11s}'
    convention = f'initial state: {ident.initial}'
    if ident.channel != 'position':
        convention += f', sensor input held {ident.hold} its sample'
    units = param_units(ident.family)
    n_seeds = sum(r.seed >= 0 for r in ident.runs)     # the others: hopping, global phase
    runs = f'seeds: {n_seeds}' + (f' (+{len(ident.runs) - n_seeds} later run(s))'
                                  if len(ident.runs) > n_seeds else '')
    lines = [f'channel: {ident.channel}   H family: {ident.family}   {runs}   '
             f'domains: {ident.domain_source}   {convention}', head, '-' * len(head)]
    for i, name in enumerate(ident.names):
        mean, best = ident.params_mean[name], ident.params[name]
        std = spread[i] if spread[i] > 1e-9 * max(abs(mean), abs(best)) else 0.0  # round-off
        row = f'{name:8s} {units[name]:8s} {_num(mean, 11)} {_num(best, 11)} {_num(std, 9)}'
        if truth:
            row += f' {_num(truth.get(name, float("nan")), 11)}'
        lines.append(row)
    er = np.array([r.er_percent for r in ident.runs])
    floor = ident.noise_floor_percent
    lines += [
        '-' * len(head),
        f'%e_r best run        {_num(ident.er_percent, 8, 3)}   ' + _floor_ratio(
            ident.er_percent, floor),
        f'%e_r mean params     {_num(ident.er_mean_params_percent, 8, 3)}' + (
            '   (not a model: the runs found different parameter sets that fit alike, and '
            'their mean fits none; use the best run)'
            if ident.er_mean_params_percent > MEAN_NOT_A_MODEL * np.median(er) else '')
        if np.isfinite(ident.er_mean_params_percent) else
        '%e_r mean params          n/a  (the mean of the runs is not a valid loop)',
        f'%e_r over runs       median {_num(np.median(er), 0, 3)}  worst '
        f'{_num(er.max(), 0, 3)}',
        f'noise floor %e_r     {_num(floor, 8, 3)}',
    ]
    lines += [f'warning: {w}' for w in ident.warnings]
    return '\n'.join(lines)


def _num(value: float, width: int, decimals: int = 4) -> str:
    """``value`` in ``decimals`` fixed decimals, or in significant figures when that hides it.

    Fixed decimals print a value in micrometres or pascals as ``0.0000`` or
    as a long string of digits; those get ``decimals + 1`` significant figures.
    """
    v = float(value)
    fixed = f'{v:{width}.{decimals}f}'
    if not np.isfinite(v) or v == 0.0 or 10.0 ** -(decimals - 1) <= abs(v) < 1e5:
        return fixed
    return f'{v:{width}.{decimals + 1}g}'


def _floor_ratio(er_percent: float, floor_percent: float) -> str:
    """The fit's ratio to its noise floor in words, or why there is none."""
    if floor_says_nothing(er_percent, floor_percent):
        return ('(noise floor about 0: the record is noise-free or smoothed, so a ratio to it '
                'says nothing)')
    return f'({er_percent / floor_percent:.2f} x noise floor)'


def write_json(ident: Identification, path: str | Path, extra: dict | None = None) -> None:
    """Write the identification (and any extra fields) as JSON."""
    data = ident.to_dict()
    if extra:
        data.update(extra)
    Path(path).write_text(json.dumps(jsonable(data), indent=2) + '\n')


def plot_identification(ident: Identification, rec: Recording, out_dir: str | Path,
                        stem: str = 'identify') -> list[Path]:
    """Write loop, time-series/residual and convergence figures; return their paths."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    y_fit = ident.spec().simulate(ident.x, rec.t_s, rec.command)
    unit_c = f' [{rec.command_unit}]' if rec.command_unit else ''
    unit_y = f' [{rec.measurement_unit}]' if rec.measurement_unit else ''
    paths = []

    fig, ax = plt.subplots(figsize=(6, 5))
    ax.plot(rec.command, rec.measurement, '.', ms=2, alpha=0.5, label='measured')
    ax.plot(rec.command, y_fit, '-', lw=1, label='identified chain')
    ax.set_xlabel(f'{rec.command_name or "command"}{unit_c}')
    ax.set_ylabel(f'{rec.quantity}{unit_y}')
    ax.set_title(f'Hysteresis loop, {rec.quantity}: %e_r {ident.er_percent:.2f}')
    ax.legend()
    paths.append(_save(fig, out / f'{stem}_loop.png'))

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    a1.plot(rec.t_s, rec.measurement, lw=0.8, label='measured')
    a1.plot(rec.t_s, y_fit, lw=0.8, label='identified')
    a1.set_ylabel(f'{rec.quantity}{unit_y}')
    a1.legend()
    a2.plot(rec.t_s, rec.measurement - y_fit, lw=0.6, color='C3')
    a2.set_ylabel('residual')
    a2.set_xlabel('time [s]')
    paths.append(_save(fig, out / f'{stem}_residual.png'))

    fig, ax = plt.subplots(figsize=(7, 4.5))
    ss = float(np.sum(rec.measurement ** 2))
    for run in ident.runs:
        ax.semilogy(np.sqrt(np.asarray(run.best_history) / ss) * 100.0, lw=0.8,
                    label=f'seed {run.seed}')
    ax.axhline(ident.noise_floor_percent, color='k', ls='--', lw=0.8, label='noise floor')
    ax.set_xlabel('generation')
    ax.set_ylabel('best %e_r (GAASS)')
    ax.set_title('GAASS convergence')
    ax.legend(fontsize=6, ncol=2)
    paths.append(_save(fig, out / f'{stem}_convergence.png'))
    return paths


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    import matplotlib.pyplot as plt
    plt.close(fig)
    return path


def er_of(ident: Identification, rec: Recording) -> float:
    """%e_r of the identification's best parameters on another recording."""
    y = ident.spec().simulate(ident.x, rec.t_s, rec.command)
    return float(er_percent(np.sum((rec.measurement - y) ** 2), rec.measurement))
