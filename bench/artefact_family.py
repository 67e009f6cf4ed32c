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

"""Measurement artefacts on random families of the reference chain: what is named, what missed.

The draws of ``test/signals/test_artefacts.py`` (the reference chain of
``test/reference_sim`` over three channels, five excitations, 0.005-0.05 s and
0.1-1 % noise), each read by :func:`hyst_id.signals.artefacts.find_artefacts`:
clean, noise-free (the same commands, no noise), with a dropout of 1-8 % of the
record, and with single-sample spikes of 12-40 noise stds (at least 5 % of the
span). The test checks the first fifteen draws; its thresholds come from the
figures this prints. A few seconds for 300 draws.

Usage (from the repository root)::

    python bench/artefact_family.py [--draws 300] [--probe K]

``--probe K`` multiplies every command and reading by ``1 + 1e-12 z`` (``z``
standard normal, seeded by ``K``) before reading it: another CPU's last bits.
The figures should not move.
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path
import sys

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'test' / 'signals'))

from reference_sim import simulate  # noqa: E402,I100
from test_artefacts import _draw, TRUTH, with_dropout, with_spikes  # noqa: E402

from hyst_id.io.recording import Recording  # noqa: E402
from hyst_id.signals.artefacts import find_artefacts  # noqa: E402


#: Seed of the round-off probe (``--probe``); None: the values as drawn.
PROBE: list[int | None] = [None]


def _find(t: np.ndarray, v: np.ndarray, y: np.ndarray) -> list:
    """:func:`find_artefacts`, on values moved in their last bits under ``--probe``."""
    if PROBE[0] is not None:
        rng = np.random.default_rng([PROBE[0], v.size])
        v = v * (1.0 + 1e-12 * rng.standard_normal(v.size))
        y = y * (1.0 + 1e-12 * rng.standard_normal(y.size))
    return find_artefacts(t, v, y)


def dropout(index: int) -> str | None:
    """Outcome of draw ``index`` with a dropout; None when the command rests over it."""
    rec, y, first, length = with_dropout(index)
    if np.ptp(rec.command[first - 1:first + length]) <= 0.02 * np.ptp(rec.command):
        return None
    found = _find(rec.t_s, rec.command, y)
    kinds = [a.kind for a in found]
    exact = any(a.samples == ((first - 1, length + 1),) for a in found)
    if kinds == ['frozen'] and exact:
        return 'frozen, exact samples'
    if kinds == ['clipped'] and exact:
        return "clipped (the held value is the record's extreme), exact samples"
    if not kinds:
        return 'missed'
    return 'named with more: ' + '+'.join(kinds)


def spikes(index: int) -> tuple[int, int, int]:
    """Spikes written, spikes found, other samples named, for draw ``index``."""
    rec, y, at = with_spikes(index)
    named = {i for a in _find(rec.t_s, rec.command, y) for i, _ in a.samples}
    return at.size, len(named & set(at.tolist())), len(named - set(at.tolist()))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--draws', type=int, default=300)
    ap.add_argument('--probe', type=int, default=None, metavar='K',
                    help='move every value in its last bits (seed K) before reading it')
    args = ap.parse_args(argv)
    PROBE[0] = args.probe
    clean, noise_free, drops = Counter(), Counter(), Counter()
    written = found = others = 0
    shares = []
    for index in range(args.draws):
        rec, _ = _draw(index)
        clean[tuple(a.kind for a in _find(rec.t_s, rec.command, rec.measurement))] += 1
        for ch in ('position', 'pressure', 'flow'):
            x = simulate(ch, TRUTH, rec.t_s, rec.command)
            noise_free[tuple(a.kind for a in _find(
                rec.t_s, rec.command, Recording(rec.t_s, rec.command, x, ch).measurement))] += 1
        outcome = dropout(index)
        if outcome is not None:
            drops[outcome] += 1
        w, f, o = spikes(index)
        written, found, others = written + w, found + f, others + o
        shares.append(f / w)
    probe = '' if args.probe is None else f', round-off probe {args.probe}'
    print(f'{args.draws} draws{probe}')
    print('clean, kinds named:', {k or 'none': v for k, v in clean.items()})
    print('noise-free twins (3 channels each), kinds named:',
          {k or 'none': v for k, v in noise_free.items()})
    print(f'dropouts while the command moves: {sum(drops.values())}')
    for outcome, count in drops.most_common():
        print(f'  {count:4d}  {outcome}')
    s = np.array(shares)
    print(f'spikes: {found}/{written} found ({100.0 * found / written:.0f} %), other samples '
          f'named {others}; per draw: 5th percentile {100.0 * np.quantile(s, 0.05):.0f} %, '
          f'median {100.0 * np.median(s):.0f} %, draws with none found {int(np.sum(s == 0))}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
