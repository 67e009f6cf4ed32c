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

"""Tables (Markdown), JSON and figures (Figs. 2, 4-7) of :mod:`hyst_id.experiment`.

Plots use matplotlib's Agg backend (no display needed).
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np

from hyst_id.experiment.result import CHANNELS, CLEAN_SERIES, ExperimentResult, supply_drop_percent
from hyst_id.experiment.run import to_backlash_gauge
from hyst_id.identification.chains import CHAIN_NAMES, chain_spec
from hyst_id.identification.gauge import canonical_gauge
from hyst_id.io.jsonable import jsonable
from hyst_id.models.tk import simulate_hysteresis

__all__ = ['PAPER', 'FIGURES', 'headline', 'format_markdown', 'write_json',
           'plot_fig2', 'plot_fig4', 'plot_compensation', 'write_outputs']

#: The paper's numbers (section 4, Table 1).
PAPER = {
    'er_percent': {'position': 2.38, 'pressure': 10.56, 'flow': 4.83},
    'eps_c_percent': {'position': 3.80, 'pressure': 13.27, 'flow': 38.87},
    'true_h': {'m_l': 1.01, 'm_r': 1.05, 'm_t': 0.10, 'm_b': 0.15,
               'c_l': -0.25, 'c_r': 0.50, 'c_t': 14.00, 'c_b': 7.00},
    'table1': {
        'position': {'m_bl': 1.09, 'c_bl': 0.48, 'c_br': 1.02, 'm_l': 1.01, 'm_r': 1.08,
                     'm_t': 0.08, 'm_b': 0.12, 'c_l': -0.28, 'c_r': 0.92, 'c_t': 10.71,
                     'c_b': 7.20},
        'pressure': {'tau_s': 1.79, 'm_bl': 1.11, 'c_bl': 0.59, 'c_br': 1.15, 'm_l': 1.08,
                     'm_r': 1.11, 'm_t': 0.10, 'm_b': 0.10, 'c_l': 0.11, 'c_r': 1.07,
                     'c_t': 10.72, 'c_b': 7.34},
        'flow': {'zeta': 0.51, 'omega_n': 0.22, 'm_bl': 1.10, 'c_bl': 0.55, 'c_br': 1.09,
                 'm_l': 1.01, 'm_r': 1.09, 'm_t': 0.10, 'm_b': 0.13, 'c_l': -0.32,
                 'c_r': 1.04, 'c_t': 10.36, 'c_b': 7.26},
    },
}
#: Figure file names.
FIGURES = {'fig2': 'fig2_shubert.png', 'fig4': 'fig4_hysteresis.png',
           'position': 'fig5_position.png', 'pressure': 'fig6_pressure.png',
           'flow': 'fig7_flow.png'}
_MODE_NAME = {'refined': 'GAASS + refinement', 'gaass': 'GAASS only'}
_UNIT = {'position': ('mA-eq', 1.0), 'pressure': ('kPa abs', 1e-3), 'flow': ('g/s', 1.0)}
_TABLE_ORDER = ('tau_s', 'zeta', 'omega_n', 'm_bl', 'c_bl', 'c_br', 'm_l', 'm_r', 'm_t', 'm_b',
                'c_l', 'c_r', 'c_t', 'c_b')


def headline(result: ExperimentResult) -> list[dict]:
    """One row per (scenario, mode, channel): the two metrics next to the paper's.

    ``er`` is %e_r (Eq. 7) in position-equivalent units averaged over the
    seeds; ``eps_c`` is %ε_c (Eq. 26) in position-equivalent units.
    """
    rows = []
    for key, sc in result.scenarios.items():
        for (mode, ch), r in sc.channels.items():
            rows.append({'scenario': key, 'mode': mode, 'channel': ch,
                         'er': r.er['cal_seeds_mean'], 'er_paper': PAPER['er_percent'][ch],
                         'eps_c': r.eps_c_percent, 'eps_c_paper': PAPER['eps_c_percent'][ch],
                         'eps_c_uncompensated': sc.eps_unc_percent[ch]})
    return rows


def _f(x: float, nd: int = 2) -> str:
    return 'nan' if not np.isfinite(x) else f'{x:.{nd}f}'


def _table(head: list[str], rows: list[list[str]]) -> list[str]:
    return ['| ' + ' | '.join(head) + ' |', '|' + '---|' * len(head)] + [
        '| ' + ' | '.join(r) + ' |' for r in rows] + ['']


def _headline_table(result: ExperimentResult, key: str) -> list[str]:
    sc = result.scenarios[key]
    modes = [m for m in result.modes if (m, CHANNELS[0]) in sc.channels or any(
        (m, c) in sc.channels for c in CHANNELS)]
    head = ['sensor', '%e_r paper'] + [f'%e_r {_MODE_NAME[m]}' for m in modes] + [
        '%ε_c paper', '%ε_c uncompensated'] + [f'%ε_c {_MODE_NAME[m]}' for m in modes]
    rows = []
    for ch in CHANNELS:
        if not any((m, ch) in sc.channels for m in modes):
            continue
        er = [sc.channels[(m, ch)].er['cal_seeds_mean'] for m in modes]
        eps = [sc.channels[(m, ch)].eps_c_percent for m in modes]
        pe, pc = PAPER['er_percent'][ch], PAPER['eps_c_percent'][ch]
        rows.append([ch, _f(pe)] + [f'**{_f(e)}** ({pe / e:.1f}x)' for e in er] + [
            _f(pc), _f(sc.eps_unc_percent[ch])] + [f'**{_f(e)}** ({pc / e:.1f}x)' for e in eps])
    return _table(head, rows)


def _er_table(result: ExperimentResult) -> list[str]:
    head = ['supply', 'mode', 'sensor', 'raw: best', 'seeds mean', 'mean params', 'floor',
            'pos.-eq.: best', 'seeds mean', 'mean params', 'floor']
    rows = []
    for key, sc in result.scenarios.items():
        for (mode, ch), r in sc.channels.items():
            e = r.er
            keys = [f'{t}_{k}' for t in ('raw', 'cal')
                    for k in ('best', 'seeds_mean', 'mean_params', 'noise_floor')]
            rows.append([f'reg. {key}', mode, ch] + [_f(e[k], 3) for k in keys])
    return _table(head, rows)


def _output_error(result: ExperimentResult, sc, x: np.ndarray) -> float:
    """Rms of B(H(v)) identified minus true over the identification command, mA-eq."""
    pos = chain_spec('position', calibration=(1.0, 0.0))
    t, v = sc.ident_run.t_s, sc.ident_run.command_ma
    return float(np.sqrt(np.mean((pos.simulate(x[:11], t, v)
                                  - pos.simulate(result.true_x, t, v)) ** 2)))


def _param_table(result: ExperimentResult, key: str, mode: str) -> list[str]:
    """Table 1: true vs identified, position units, in the gauge of the true backlash."""
    sc = result.scenarios[key]
    true = result.true_x
    m_bl, centre = true[8], 0.5 * (true[9] + true[10])
    names = CHAIN_NAMES['flow']
    ours = {}
    for ch in CHANNELS:
        r = sc.channels.get((mode, ch))
        if r is None:
            continue
        x = to_backlash_gauge(r.x_position, m_bl, centre)
        seeds = np.array([to_backlash_gauge(s, m_bl, centre) for s in r.x_position_seeds])
        ours[ch] = (dict(zip(CHAIN_NAMES[ch], x)), dict(zip(CHAIN_NAMES[ch], seeds.std(axis=0))),
                    r.top_line_reached, _output_error(result, sc, r.x_position))
    truth = dict(zip(names, true))
    head = ['param', 'true'] + [f'paper {c[:4]}.' for c in CHANNELS] + [
        f'ours {c[:4]}. (± seed std)' for c in ours]
    rows = []
    for n in _TABLE_ORDER:
        row = [n, _f(truth[n]) if n in truth else '–']
        row += [_f(PAPER['table1'][c][n]) if n in PAPER['table1'][c] else 'N/A' for c in CHANNELS]
        for c, (vals, std, top, _) in ours.items():
            if n not in vals:
                row.append('N/A')
            elif n == 'c_t' and not top:
                row.append(f'({_f(vals[n])}) n.i.')
            else:
                row.append(f'{_f(vals[n])} ± {_f(std[n])}')
        rows.append(row)
    rows.append(['B(H(v)) rms error vs true, Eq. 24 [mA-eq]', '0', '', '', ''] + [
        _f(o[3], 3) for o in ours.values()])
    return _table(head, rows)


def _canonical_table(result: ExperimentResult, key: str, mode: str) -> list[str]:
    sc = result.scenarios[key]
    names = CHAIN_NAMES['position']
    true = canonical_gauge(result.true_x)
    head = ['param', 'true (canonical)'] + [c for c in CHANNELS if (mode, c) in sc.channels]
    chans = [c for c in CHANNELS if (mode, c) in sc.channels]
    rows = [[n, _f(true[i], 3)] + [_f(sc.channels[(mode, c)].x_position[i], 3) for c in chans]
            for i, n in enumerate(names)]
    return _table(head, rows)


def _calibration_table(result: ExperimentResult) -> list[str]:
    head = ['supply', 'sensor', 'k [unit/mA-eq]', 'b [unit]', 'fitted lag', 'rms residual']
    rows = []
    for key, sc in result.scenarios.items():
        for ch, c in sc.calibrations.items():
            dyn = ', '.join(f'{n} {v:.3g}' for n, v in c.dynamics.items()) or '–'
            rows.append([f'reg. {key}', ch, f'{c.k:.4g}', f'{c.b:.4g}', dyn,
                         f'{c.rms_residual:.3g}'])
    return _table(head, rows)


def _compensation_table(result: ExperimentResult) -> list[str]:
    head = ['supply', 'sensor', 'uncompensated', *(_MODE_NAME[m] for m in result.modes),
            'position rms error [mA-eq] unc. / ' + ' / '.join(result.modes)]
    rows = []
    for key, sc in result.scenarios.items():
        for ch in CHANNELS:
            rs = [sc.channels[(m, ch)] for m in result.modes if (m, ch) in sc.channels]
            if not rs:
                continue
            rows.append([f'reg. {key}', ch,
                         f'{_f(sc.eps_unc_percent[ch])} ({_f(sc.eps_unc_raw_percent[ch])})'] + [
                f'{_f(r.eps_c_percent)} ({_f(r.eps_c_raw_percent)})' for r in rs] + [
                ' / '.join(_f(x, 3) for x in [sc.position_rms_error_unc] + [
                    r.position_rms_error for r in rs])])
    return _table(head, rows)


#: Issue 17's targets for %ε_c on the unregulated paper rig.
ADAPTIVE_TARGETS = {'position': 0.4, 'pressure': 1.5, 'flow': 3.0}


def _adaptive_table(result: ExperimentResult) -> list[str]:
    """Issue 17: (a) fixed H⁻¹, (b) augmented by the diagnosis, (c) tracking.

    The *desired value vs reference* column is %ε_c of a reading that is
    exactly the desired value through the calibration's lag: how far the
    desired value itself is from the reference (a floor when the
    calibration's lag describes the channel).
    """
    head = ['supply', 'sensor', 'mode', '(a) fixed', '(b) augmented', '(c) tracking',
            'target', 'desired value vs reference (a) / (b)',
            'diagnosis of the identification run: what (b) does with it']
    rows = []
    for key, sc in result.scenarios.items():
        for (mode, ch), r in sc.channels.items():
            a = r.adaptive
            if a is None:
                continue
            how = '; '.join(f'{m}: {h.split(":")[0]}' for m, h in a.applied) or 'nothing found'
            rows.append([f'reg. {key}', ch, _MODE_NAME[mode], _f(r.eps_c_percent),
                         _f(a.eps_c_augmented_percent), _f(a.eps_c_tracking_percent),
                         f'<= {ADAPTIVE_TARGETS[ch]:g}',
                         f'{_f(a.floor_percent[0])} / {_f(a.floor_percent[1])}',
                         f'{a.verdict} -> {how} (set from the {a.augmented_from})'])
    return _table(head, rows) if rows else []


def _decay_table(result: ExperimentResult) -> list[str]:
    """%ε_c with the supply decay in neither, one or both of identification and compensation."""
    if not {'off', 'on'} <= set(result.scenarios):
        return []
    off, on = result.scenarios['off'], result.scenarios['on']
    head = ['sensor', 'case', 'identified / compensated: off / off', 'off / on', 'on / off',
            'on / on', 'share of (off/off)² explained by the decay, 1 - (on/on ÷ off/off)²']
    rows = []
    for ch in CHANNELS:
        a, b = off.eps_unc_percent.get(ch), on.eps_unc_percent.get(ch)
        if a is not None and b is not None:
            rows.append([ch, 'uncompensated', _f(a), '', '', _f(b),
                         f'{(1 - (b / a) ** 2) * 100:.0f} %'])
        for m in result.modes:
            if (m, ch) not in off.channels or (m, ch) not in on.channels:
                continue
            r_off, r_on = off.channels[(m, ch)], on.channels[(m, ch)]
            a, b = r_off.eps_c_percent, r_on.eps_c_percent
            rows.append([ch, _MODE_NAME[m], _f(a), _f(r_off.eps_c_other_supply_percent),
                         _f(r_on.eps_c_other_supply_percent), _f(b),
                         f'{(1 - (b / a) ** 2) * 100:.0f} %'])
    return _table(head, rows)


def format_markdown(result: ExperimentResult, command: str | None = None) -> str:
    """All tables of the experiment as Markdown (paste-ready for docs/RESULTS.md)."""
    s = result.settings
    lines = ['# Section 4 experiment: results', '']
    if command:
        lines += ['Command: `' + command + '`', '']
    lines += [f'Rig: `{result.params_source}`; GAASS N_pop {s.pop_size}, {s.maxiter} generations, '
              f'c {s.c}, ξ {s.xi}, seeds {list(s.seeds)}; modes: '
              + ', '.join(_MODE_NAME[m] for m in result.modes) + '.', '']
    for key, sc in result.scenarios.items():
        lines += [f'## Headline, supply {sc.name} (position-equivalent units; '
                  '(Nx) = paper / ours)', '']
        lines += _headline_table(result, key)
        lines += [f'Supply pressure drop: {supply_drop_percent(sc, sc.ident_run):.1f} % over the '
                  f'identification run, {supply_drop_percent(sc):.1f} % over each compensation '
                  'run.',
                  '']
    adaptive = _adaptive_table(result)
    if adaptive:
        lines += ['## Compensation with what the diagnosis found (issue 17): %ε_c, '
                  'position-equivalent', ''] + adaptive
    lines += ['## %e_r (Eq. 7): raw units and position-equivalent', '']
    lines += _er_table(result)
    lines += ['## Position calibration of the readings (identification run)', '']
    lines += _calibration_table(result)
    for key in result.scenarios:
        for mode in result.modes:
            lines += [f'## Table 1, supply regulation {key}, {_MODE_NAME[mode]} '
                      '(position units, gauge of the true backlash)', '']
            lines += _param_table(result, key, mode)
            lines += [f'Canonical gauge (B unit slope, centred), position units, '
                      f'regulation {key}, {_MODE_NAME[mode]}:', '']
            lines += _canonical_table(result, key, mode)
    lines += ['## %ε_c (Eq. 26): position-equivalent (raw units in brackets)', '']
    lines += _compensation_table(result)
    decay = _decay_table(result)
    if decay:
        lines += ['## What the supply decay explains', ''] + decay
    lines += ['## Run time [s]', '']
    lines += _table(['step', 'seconds'], [[k, f'{v:.1f}'] for k, v in result.timings_s.items()])
    return '\n'.join(lines)


def write_json(result: ExperimentResult, path: str | Path, command: str | None = None) -> Path:
    """Write :meth:`ExperimentResult.to_dict` plus the paper's numbers as JSON."""
    data = result.to_dict()
    data['paper'] = PAPER
    data['command'] = command
    data['headline'] = headline(result)
    Path(path).write_text(json.dumps(jsonable(data), indent=1) + '\n')
    return Path(path)


def _plt():
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    return plt


def plot_fig2(path: str | Path) -> Path | None:
    """Fig. 2 via ``bench/fig2_shubert.py`` (source checkouts only; else ``None``)."""
    script = Path(__file__).resolve().parents[1] / 'bench' / 'fig2_shubert.py'
    if not script.is_file():
        return None
    spec = importlib.util.spec_from_file_location('_fig2_shubert', script)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    gaass, sga = mod.run()
    mod.plot(gaass, sga, str(path))
    return Path(path)


def _loop_command(sc) -> tuple[np.ndarray, int]:
    """Triangle over the commanded range of the identification run, and where to start plotting.

    Low, high, low, high: the first rise only brings the initial state onto the
    loop, so plots start at the first fall (one closed cycle).
    """
    lo, hi = float(sc.ident_run.command_ma.min()), float(sc.ident_run.command_ma.max())
    n = int((hi - lo) / 0.005) + 1
    up, down = np.linspace(lo, hi, n), np.linspace(hi, lo, n)
    return np.concatenate([up, down[1:], up[1:]]), n - 1


def plot_fig4(result: ExperimentResult, path: str | Path, key: str = 'off') -> Path:
    """Identified H from each sensor vs the true one, position units (paper's Fig. 4).

    Left: H alone, in the gauge of the true backlash (slope and centre), so the
    true curve is the paper's H. Right: the actuator output B(H(v)), which no
    gauge choice changes. Input: a triangle low-high-low-high over the range
    the Eq. 24 run commanded (outer loop of what was excited).
    """
    plt = _plt()
    sc = result.scenarios[key]
    v, i0 = _loop_command(sc)
    t = np.arange(v.size, dtype=float)
    cut = slice(i0, None)
    true = result.true_x
    m_bl, centre = true[8], 0.5 * (true[9] + true[10])
    pos = chain_spec('position', calibration=(1.0, 0.0))
    modes = [m for m in result.modes if any((m, c) in sc.channels for c in CHANNELS)]
    fig, axes = plt.subplots(len(modes), 2, figsize=(11, 4.6 * len(modes)), squeeze=False)
    for row, mode in zip(axes, modes):
        row[0].plot(v[cut], simulate_hysteresis(true[:8], v)[cut], 'k-', lw=2.2,
                    label='true (paper)')
        row[1].plot(v[cut], pos.simulate(true[:11], t, v)[cut], 'k-', lw=2.2, label='true')
        for i, ch in enumerate(CHANNELS):
            r = sc.channels.get((mode, ch))
            if r is None:
                continue
            x = to_backlash_gauge(r.x_position, m_bl, centre)
            style = {'lw': 1.0, 'color': f'C{i}', 'ls': ('-', '--', ':')[i]}
            row[0].plot(v[cut], simulate_hysteresis(x[:8], v)[cut], label=f'from {ch}', **style)
            row[1].plot(v[cut], pos.simulate(x[:11], t, v)[cut], label=f'from {ch}', **style)
        row[0].set_title(f'H, {_MODE_NAME[mode]}, {sc.name}')
        row[1].set_title('actuator output B(H(v))')
        row[0].set_ylabel('H output [mA-eq]')
        row[1].set_ylabel('position [mA-eq]')
        for ax in row:
            ax.set_xlabel('command v [mA]')
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8)
    return _save(fig, path)


def plot_compensation(result: ExperimentResult, channel: str, path: str | Path) -> Path:
    """Desired vs uncompensated vs compensated output of one sensor (Figs. 5-7)."""
    plt = _plt()
    unit, scale = _UNIT[channel]
    keys = list(result.scenarios)
    fig, axes = plt.subplots(len(keys), 2, figsize=(12, 4.2 * len(keys)), squeeze=False,
                             gridspec_kw={'width_ratios': [2.2, 1]})
    for row, key in zip(axes, keys):
        sc = result.scenarios[key]
        t = sc.reference.t_s
        clean = CLEAN_SERIES[channel]
        ax, axc = row
        ax.plot(t, sc.reference.truth[clean] * scale, 'k-', lw=2, label='desired w_ud')
        ax.plot(t, sc.uncompensated.measurement(channel) * scale, 'C3-', lw=1,
                label=f'uncompensated ({_f(sc.eps_unc_percent[channel])} %)')
        axc.plot(t, sc.uncompensated.command_ma, 'k-', lw=1.5, label='u_d (uncompensated)')
        for i, mode in enumerate(result.modes):
            r = sc.channels.get((mode, channel))
            if r is None:
                continue
            style = {'color': ('C0', 'C2')[i], 'ls': ('-', '--')[i], 'lw': 1.1}
            ax.plot(t, r.run.measurement(channel) * scale,
                    label=f'compensated, {_MODE_NAME[mode]} ({_f(r.eps_c_percent)} %)', **style)
            axc.plot(t, r.command_ma, label=f'compensated, {_MODE_NAME[mode]}', **style)
        ax.set_title(f'{channel} control, {sc.name} (%ε_c position-equivalent)')
        ax.set_ylabel(f'{channel} [{unit}]')
        axc.set_title('command')
        axc.set_ylabel('command [mA]')
        for a in row:
            a.set_xlabel('time [s]')
            a.grid(True, alpha=0.3)
            a.legend(fontsize=7)
    return _save(fig, path)


def _save(fig, path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    _plt().close(fig)
    return Path(path)


def write_outputs(result: ExperimentResult, out_dir: str | Path, command: str | None = None,
                  fig2: bool = True) -> dict:
    """Write ``results.json``, ``results.md`` and the figures into ``out_dir``.

    Returns
    -------
    dict
        Name -> path of everything written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {'json': write_json(result, out / 'results.json', command)}
    md = out / 'results.md'
    md.write_text(format_markdown(result, command) + '\n')
    paths['markdown'] = md
    if fig2:
        p = plot_fig2(out / FIGURES['fig2'])
        if p is not None:
            paths['fig2'] = p
    first = next(iter(result.scenarios))
    paths['fig4'] = plot_fig4(result, out / FIGURES['fig4'], key=first)
    channels = {ch for sc in result.scenarios.values() for (_, ch) in sc.channels}
    for ch in CHANNELS:
        if ch in channels:
            paths[ch] = plot_compensation(result, ch, out / FIGURES[ch])
    return paths
