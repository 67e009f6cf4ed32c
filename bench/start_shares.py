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

"""The start's share of the other boundary's gain, over records started on either boundary.

The diagnosis's baseline (:func:`hyst_id.diagnosis.challenge.chain_fit`) keeps a
chain on the other boundary than its own (rising) only where the training BIC
drops by ``criteria.bic_drop``, at least ``challenge.START_SHARE`` of the gain lies
before the command has first swept half its training range, and the own chain
meets that start better started on the other boundary
(:func:`hyst_id.diagnosis.challenge.start_evidence`). This draws the blind
family's recordings (``bench/blind_family.py``, effects and all) with the
reference chain started on the rising and on the falling boundary, runs the
baseline only (``max_mechanisms=0``) and prints, wherever the BIC test passed,
the share and the own chain's check, then the smallest share of a falling start
and the largest of a rising one: the gap ``START_SHARE`` sits in. Run from the
repository root (about 10 s per diagnosis and worker; 2 x ``--n`` diagnoses)::

    python bench/start_shares.py [--n 40] [--indices 18 100] [--workers 2]

``--synthetic``: instead, the package's own synthetic supply decay of
``test/diagnosis/test_diagnose.py`` (a rising start, noise seeds 0 and 1, that
test's settings), whose missing drift the falling boundary fits better::

    python bench/start_shares.py --synthetic
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import math
from pathlib import Path
import sys

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT))

from blind_family import draw  # noqa: E402, I100

from hyst_id.diagnosis import challenge, diagnose, DiagnoseSettings  # noqa: E402, I100
from hyst_id.io.recording import Recording  # noqa: E402

SEEN: list[tuple[float, float, bool]] = []


def _recorded(*args, _inner=challenge.start_evidence):
    """:func:`start_evidence`, remembering what it weighed."""
    got = _inner(*args)
    SEEN.append(got)
    return got


def one(job: tuple[int, str]) -> tuple[int, str, str, str, str, tuple | None]:
    """Recording ``index`` started on ``initial``: channel, effects, the boundary run, evidence."""
    index, initial = job
    case = draw(index, initial=initial)
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'])
    SEEN.clear()
    challenge.start_evidence = _recorded
    d = diagnose(rec, settings=DiagnoseSettings(workers=1, max_mechanisms=0))
    return (index, initial, case['channel'], '+'.join(case['effects']) or 'clean',
            str(d.extra.get('initial', '')), SEEN[0] if SEEN else None)


def synthetic(seed: int) -> tuple[int, str, tuple | None]:
    """The synthetic supply decay with noise ``seed``: the boundary run, the evidence."""
    from dataclasses import replace
    sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))
    from test_diagnose import FAST, synthetic as synthetic_record
    SEEN.clear()
    challenge.start_evidence = _recorded
    d = diagnose(synthetic_record('supply_decay', seed=seed),
                 settings=replace(FAST, max_mechanisms=0))
    return seed, str(d.extra.get('initial', '')), SEEN[0] if SEEN else None


def main(argv: list[str] | None = None) -> int:
    """Print each record's evidence and the gap between the two boundaries' shares."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--n', type=int, default=40)
    ap.add_argument('--indices', type=int, nargs='*', default=[],
                    help='recordings of the family to add to the first --n')
    ap.add_argument('--workers', type=int, default=2)
    ap.add_argument('--synthetic', action='store_true',
                    help="the package's synthetic supply decay instead (seeds 0, 1)")
    args = ap.parse_args(argv)
    if args.synthetic:
        for seed, ran, ev in map(synthetic, (0, 1)):
            said = 'not weighed' if ev is None else (
                f'BIC gain {ev[0]:.1f}, share {ev[1]:.2f}, {"meets" if ev[2] else "no"}')
            print(f'synthetic supply_decay seed {seed}: ran on {ran}; {said}')
        return 0
    jobs = [(i, side) for i in sorted(set(range(args.n)) | set(args.indices))
            for side in ('rising', 'falling')]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(one, jobs))
    print(f'START_SHARE {challenge.START_SHARE}; a share is printed where the other boundary '
          'was weighed (it fitted the training part best)')
    print('  #  started  channel   effects                              ran on   '
          'BIC gain  share  own chain')
    shares: dict[str, list[float]] = {'rising': [], 'falling': []}
    for index, initial, channel, effects, ran, ev in rows:
        text = '' if ev is None else f'{ev[0]:8.1f}  {ev[1]:5.2f}  {"meets" if ev[2] else "no"}'
        print(f'#{index:3d}  {initial:7s}  {channel:8s}  {effects:36s} {ran:8s} {text}')
        if ev is not None and ev[0] > DiagnoseSettings().criteria.bic_drop \
                and not math.isnan(ev[1]):
            shares[initial].append(ev[1])
    for side in ('falling', 'rising'):
        ran = [r for r in rows if r[1] == side]
        right = sum(r[4] == side for r in ran)
        got = sorted(shares[side])
        print(f'started {side}: {len(ran)} records, run on {side}: {right}; past the BIC test '
              f'{len(got)}, shares ' + (', '.join(f'{s:.2f}' for s in got) or 'none'))
    lo = min(shares['falling'], default=math.nan)
    hi = max(shares['rising'], default=math.nan)
    print(f'smallest share of a falling start {lo:.2f}; largest of a rising start {hi:.2f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
