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

"""Wall time of ``identify`` on 2,000-sample recordings, with default settings.

Recordings ``--start`` .. ``--start + --n`` of the reference family
(``bench/generalisation.py``, drawn by ``test/reference_sim``), each cut to
2,000 samples. ``identify`` runs as ``hyst-id identify`` does: default
settings (10 seeds, workers = cores). Printed per recording: wall time,
evaluations and the best %e_r over the **true** noise floor; then the median
and worst wall time and the share that ended within 1.1 x the floor.
Run it on an otherwise idle machine: it measures time.

Usage (from the repository root)::

    python bench/identify_speed.py --n 10
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT))

from generalisation import draw_case, recording, true_floor  # noqa: E402, I100

__all__ = ['main']


def main(argv: list[str] | None = None) -> int:
    """Time identify on the family's recordings, cut to ``--samples`` samples."""
    from hyst_id.identification import identify
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--n', type=int, default=10, help='recordings')
    ap.add_argument('--start', type=int, default=0, help='first recording index')
    ap.add_argument('--samples', type=int, default=2000, help='samples per recording')
    args = ap.parse_args(argv)
    identify(recording(draw_case(0, n_samples=200)))      # compile the kernels first
    walls, ratios = [], []
    for index in range(args.start, args.start + args.n):
        case = draw_case(index, n_samples=args.samples)
        t0 = time.perf_counter()
        ident = identify(recording(case))
        wall = time.perf_counter() - t0
        ratio = ident.er_percent / true_floor(case)
        walls.append(wall)
        ratios.append(ratio)
        print(f'#{index:3d} {case.channel:8s} {case.excitation:13s} {wall:5.1f} s  '
              f'{ident.nfev:7d} evaluations  {ratio:.3f} x the true floor',
              flush=True)
    walls, ratios = np.array(walls), np.array(ratios)
    print()
    print(f'{args.n} recordings of {args.samples} samples: wall time median '
          f'{np.median(walls):.1f} s, worst {walls.max():.1f} s; within 1.1 x the true floor '
          f'{np.mean(ratios <= 1.1):.0%}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
