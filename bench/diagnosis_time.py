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

"""Where a diagnosis spends its time: each candidate block's trial, the swap's search.

Diagnoses blind-family recordings (``bench/blind_family.py``'s draw, the same
recordings as its ``--indices``) in one process and prints, per recording, the
total seconds, the seconds of each mechanism's trials summed over the rounds,
friction's data-built starts, identify's data-built starts and conventions
(its incumbent, :mod:`hyst_id.identification.incumbent`, in every
identification of the diagnosis), and how many of the family swap's quick searches
(:func:`hyst_id.diagnosis.baseline.quick_starts`) ran and what they cost. A
search made once and reused in later rounds shows as one search in a
diagnosis of several rounds. Times are wall seconds on this machine, with
nothing else running; they are not asserted anywhere.

Run from the repository root (a minute or two per recording)::

    python bench/diagnosis_time.py [--indices 1 160]
"""

from __future__ import annotations

import argparse
import collections
from pathlib import Path
import sys
import time

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT))

from blind_family import draw  # noqa: E402

from hyst_id.diagnosis import baseline, driver, refit, trial  # noqa: E402
from hyst_id.diagnosis.driver import diagnose  # noqa: E402
from hyst_id.diagnosis.mechanisms.friction import Friction  # noqa: E402
from hyst_id.diagnosis.result import DiagnoseSettings  # noqa: E402
from hyst_id.identification import driver as identify_driver  # noqa: E402
from hyst_id.io.recording import Recording  # noqa: E402


#: The identify searches of a diagnosis, by kind (counted as well as timed).
SEARCHES = ('baseline search', 'swap quick search', 're-identification search')


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--indices', type=int, nargs='+', default=[1, 160])
    args = ap.parse_args()
    spent: dict = collections.defaultdict(float)
    counts: collections.Counter = collections.Counter()

    def timed(inner, key_of):
        """``inner`` with its wall time added under ``key_of(*args, **kwargs)``."""
        def wrapper(*a, **k):
            key, t0 = key_of(*a, **k), time.perf_counter()
            try:
                return inner(*a, **k)
            finally:
                spent[key] += time.perf_counter() - t0
                counts[key] += key in SEARCHES
        return wrapper

    trial.try_mechanism = timed(trial.try_mechanism, lambda m, *a, **k: f'trial {m.id}')
    searches = timed(baseline.baseline_starts, lambda *a, thorough=True, global_phase=None: (
        SEARCHES[0] if thorough else SEARCHES[1] if global_phase is None else SEARCHES[2]))
    for module in (baseline, driver, refit):        # each holds its own name for it
        module.baseline_starts = searches
    incumbent_key = 'identify data-built starts (in the searches)'
    for name in ('data_incumbent', 'rank_conventions'):     # identify's own name for each
        setattr(identify_driver, name, timed(getattr(identify_driver, name),
                                             lambda *a, **k: incumbent_key))
    Friction.data_starts = timed(Friction.data_starts,
                                 lambda *a, **k: 'friction data starts (in trial friction)')
    for i in args.indices:
        case = draw(i)
        spent.clear()
        counts.clear()
        baseline.forget_quick()
        t0 = time.perf_counter()
        rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                        source=f'blind #{i}')
        d = diagnose(rec, settings=DiagnoseSettings(workers=1))
        total = time.perf_counter() - t0
        found = ', '.join(f.mechanism for f in d.findings) or 'none'
        effects = '+'.join(case['effects']) or 'clean'
        print(f'#{i} ({effects}) -> {found}: {total:.1f} s in all, '
              f'{len(d.rounds)} rounds')
        print('   ' + ', '.join(f'{k} x{n} {spent[k]:.1f} s' for k, n in sorted(counts.items())
                                if n))
        rows = sorted(((k, v) for k, v in spent.items() if k not in SEARCHES),
                      key=lambda kv: -kv[1])
        if rows:
            print('   ' + ', '.join(f'{k} {v:.1f} s' for k, v in rows))


if __name__ == '__main__':
    main()
