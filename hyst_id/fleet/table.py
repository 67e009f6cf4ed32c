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

"""The fleet's table: one row per recording, CSV and Parquet, and loop trends per valve.

A row holds the recording, its valve (the parent directory's name unless a
``valve_of`` function says otherwise), status and error, the start of the
recording (seconds since the epoch, when its stamps say), %e_r, the noise
floor and their ratio, every identified parameter (``p.<name>``), the loop
width in command units (:func:`hyst_id.fleet.width.loop_width_command`: the
whole chain's quasi-static loop, however H and the backlash share it), the
parameter differences ``h_width`` (tk family: ``c_r - c_l``) and
``backlash_width`` (``c_br - c_bl``), warnings, poorly determined parameters,
and the diagnosis verdict. Trends are fitted to the loop width: the share
between H and the backlash moves from fit to fit (a new-user trial's widening
play was missed on ``c_r - c_l`` and ``c_br - c_bl``), the whole loop does not.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
import re
from typing import Any, Callable, Iterable

import numpy as np

__all__ = ['TREND_MIN_CHANGE', 'fleet_rows', 'loop_trends', 'write_table']

#: A trend is flagged when the fitted change over a valve's recordings exceeds this
#: share of the metric's median and three times the scatter around the fitted line.
TREND_MIN_CHANGE = 0.10
_EPOCH = re.compile(r'stamp ([0-9]+(?:\.[0-9]*)?) s since the epoch')


def fleet_rows(docs: Iterable[dict],
               valve_of: Callable[[str], str] | None = None) -> list[dict[str, Any]]:
    """One flat row per fleet document (see the module docstring)."""
    rows = []
    for doc in docs:
        path = str(doc.get('recording', ''))
        row: dict[str, Any] = {
            'recording': path,
            'valve': valve_of(path) if valve_of else Path(path).parent.name,
            'status': doc.get('status', 'error'), 'error': doc.get('error', ''),
            'source': doc.get('source', ''), 'n_samples': doc.get('n_samples'),
            'duration_s': doc.get('duration_s'), 'elapsed_s': doc.get('elapsed_s'),
            'start_epoch_s': _start_epoch(doc.get('notes') or []),
        }
        ident = doc.get('identification') or {}
        if ident:
            er, floor = ident.get('er_percent'), ident.get('noise_floor_percent')
            params = ident.get('params') or {}
            row.update({
                'channel': ident.get('channel'), 'family': ident.get('family'),
                'er_percent': er, 'noise_floor_percent': floor,
                'er_over_floor': er / floor if er is not None and floor else None,
                'loop_width': doc.get('loop_width_command'),
                'h_width': _diff(params, 'c_r', 'c_l'),
                'backlash_width': _diff(params, 'c_br', 'c_bl'),
                'warnings': ' | '.join(ident.get('warnings') or []),
                'poorly_determined': ' '.join(sorted(ident.get('poorly_determined') or {})),
                **{f'p.{k}': v for k, v in params.items()}})
        diag = doc.get('diagnosis') or {}
        if diag:
            row['verdict'] = diag.get('verdict')
            row['findings'] = ' '.join(f.get('mechanism', '?')
                                       for f in diag.get('findings') or [])
        rows.append(row)
    return rows


def _diff(params: dict, a: str, b: str) -> float | None:
    if a in params and b in params:
        return float(params[a]) - float(params[b])
    return None


def _start_epoch(notes: list[str]) -> float | None:
    for note in notes:
        m = _EPOCH.search(str(note))
        if m:
            return float(m.group(1))
    return None


def write_table(rows: list[dict[str, Any]], out_dir: str | Path) -> list[Path]:
    """Write ``fleet.csv`` (and ``fleet.parquet`` when pyarrow is installed); the paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    columns = list(dict.fromkeys(k for row in rows for k in row))
    path = out_dir / 'fleet.csv'
    with open(path, 'w', newline='') as fh:
        writer = csv.DictWriter(fh, columns)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: ('' if row.get(k) is None else row.get(k)) for k in columns})
    written = [path]
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return written
    table = pa.table({k: [row.get(k) for row in rows] for k in columns})
    pq.write_table(table, out_dir / 'fleet.parquet')
    return written + [out_dir / 'fleet.parquet']


def loop_trends(rows: list[dict[str, Any]],
                metrics: tuple[str, ...] = ('loop_width',)) -> list[dict]:
    """Valves whose loop width (or another of ``metrics``) drifts over their recordings.

    Per valve (at least three good recordings, ordered by start time, else by
    name) a straight line is fitted to each metric against the recording's
    order; a change from the first to the last recording larger than
    :data:`TREND_MIN_CHANGE` of the median and than three times the scatter
    around the line is flagged.
    """
    out = []
    valves = sorted({r['valve'] for r in rows})
    for valve in valves:
        mine = [r for r in rows if r['valve'] == valve and r['status'] == 'ok']
        mine.sort(key=lambda r: (r.get('start_epoch_s') is None, r.get('start_epoch_s') or 0.0,
                                 r['recording']))
        for metric in metrics:
            pts = [(k, r[metric]) for k, r in enumerate(mine)
                   if r.get(metric) is not None and math.isfinite(r[metric])]
            if len(pts) < 3:
                continue
            x, y = np.array(pts, dtype=float).T
            slope, icpt = np.polyfit(x, y, 1)
            fit = slope * x + icpt
            change = float(fit[-1] - fit[0])
            scatter = float(np.std(y - fit, ddof=2)) if len(y) > 2 else 0.0
            scale = float(np.median(np.abs(y))) or 1.0
            flagged = abs(change) > TREND_MIN_CHANGE * scale and abs(change) > 3 * scatter
            out.append({'valve': valve, 'metric': metric, 'n': len(y), 'first': float(y[0]),
                        'last': float(y[-1]), 'change': change,
                        'change_percent': 100 * change / scale, 'scatter': scatter,
                        'flagged': bool(flagged)})
    return out
