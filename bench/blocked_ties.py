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

"""Does blocked cross-validation decide between tied blocks? (issue 14 item 3, docs).

For each blind-family recording given, diagnoses it and, in every round with
an accepted winner, refits the winner and each block tied with it (or a close
call) per time block (:func:`hyst_id.diagnosis.blocked_cv.block_predictions`)
and prints the runner-up against the winner: the time blocks where it predicts
better and worse, and the %e_r of each per block. The diagnosis itself is
unchanged (the round's choice is observed, not altered).

A round that accepts nothing is shown too: every candidate against the
current model per time block (``--no-winner``: would the time blocks accept a
block the split refused? Measured on #3 and #138, docs/diagnosis.md).

Run from the repository root (about a minute per recording on 2 cores)::

    python bench/blocked_ties.py 106 61 18 93
    python bench/blocked_ties.py 3 138 --no-winner
    python bench/blocked_ties.py --short-splits 150     # which splits are short
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT))

import blind_family  # noqa: E402, I100

from hyst_id.diagnosis import diagnose, DiagnoseSettings  # noqa: E402
from hyst_id.diagnosis.blocked_cv import (  # noqa: E402
    block_predictions, compare_blocked, SPLIT_MINORITY)
import hyst_id.diagnosis.driver as driver  # noqa: E402, I100
from hyst_id.diagnosis.ties import choose, close_calls  # noqa: E402
from hyst_id.io.recording import Recording  # noqa: E402
from hyst_id.signals.split import inside_rows, split_index  # noqa: E402


_CURRENT: dict = {}
_try_all = driver.try_all


def _observed_try_all(cands, current, data, *args, **kwargs):
    """:func:`try_all`, keeping the model the round starts from."""
    _CURRENT['fit'] = current
    return _try_all(cands, current, data, *args, **kwargs)


def _no_winner(comps, data) -> None:
    """Every candidate of a round that accepted none against the current model, per block."""
    current = _CURRENT['fit']
    print(f'  round without a winner (current: {"+".join(current.ids) or "baseline"})',
          flush=True)
    pc = block_predictions(current, data)
    for c in comps:
        cv = compare_blocked(pc, block_predictions(c.fit, data), data)
        print(f'    {c.mechanism} ({c.status}): better than the current model in '
              f'{cv.better}, worse in {cv.worse} of {cv.n_blocks} blocks; %e_r per block '
              f'current {[round(x, 3) for x in cv.er_a_percent]}, {c.mechanism} '
              f'{[round(x, 3) for x in cv.er_b_percent]}; noise floor '
              f'{[round(x, 3) for x in cv.floor_percent]}', flush=True)


def short_splits(n: int) -> list[int]:
    """The family's recordings whose split judges under ``SPLIT_MINORITY`` of its held-out part."""
    out = []
    for i in range(n):
        case = blind_family.draw(i)
        n_train = split_index(case['t'], DiagnoseSettings().train_fraction)
        judged = inside_rows(case['command'], n_train).size
        if judged < SPLIT_MINORITY * (case['t'].size - n_train):
            out.append(i)
            print(f'#{i} {case["channel"]}, {case["excitation"]}: '
                  f'{"+".join(case["effects"]) or "clean"}; judged {judged} of '
                  f'{case["t"].size - n_train} held-out samples', flush=True)
    return out


def _observed_choose(comps, data, criteria):
    """:func:`choose`, printing the blocked cross-validation of its ties."""
    winner, tied = choose(comps, data, criteria)
    if winner is None:
        if _CURRENT.get('no_winner'):
            _no_winner(comps, data)
        return winner, tied
    close = [c for c in close_calls(comps, winner, tied, data, criteria) if c not in tied]
    print(f'  round winner {winner.mechanism} (judged held-out '
          f'{data.judged_er_percent(winner.fit):.4g} %)', flush=True)
    pw = block_predictions(winner.fit, data)
    for kind, group in (('tied', tied), ('close', close)):
        for c in group:
            cv = compare_blocked(pw, block_predictions(c.fit, data), data)
            print(f'    {kind} {c.mechanism}: better than the winner in {cv.better}, worse '
                  f'in {cv.worse} of {cv.n_blocks} blocks; %e_r per block winner '
                  f'{[round(x, 3) for x in cv.er_a_percent]}, '
                  f'{c.mechanism} {[round(x, 3) for x in cv.er_b_percent]}', flush=True)
    return winner, tied


def main() -> int:
    """Diagnose the recordings given, printing each round's ties per time block."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('indices', type=int, nargs='*', help='blind-family recordings')
    ap.add_argument('--short-splits', type=int, metavar='N',
                    help='only list the first N recordings whose split judges under half of '
                         'its held-out part (no diagnosis)')
    ap.add_argument('--workers', type=int, default=2)
    ap.add_argument('--no-winner', action='store_true',
                    help='also show the rounds that accept no block')
    args = ap.parse_args()
    if args.short_splits:
        print(' '.join(map(str, short_splits(args.short_splits))))
        return 0
    driver.choose = _observed_choose
    driver.try_all = _observed_try_all
    _CURRENT['no_winner'] = args.no_winner
    for i in args.indices:
        case = blind_family.draw(i)
        print(f'#{i} {case["channel"]}: {"+".join(case["effects"]) or "clean"}', flush=True)
        rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                        source=f'blind #{i}')
        d = diagnose(rec, settings=DiagnoseSettings(workers=args.workers))
        print(f'  -> {d.verdict}: {[f.mechanism for f in d.findings]}', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
