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

"""``identify`` against a plain CMA-ES on another simulator's chains (stop 65's review).

An independent reviewer (read only, no package code read) wrote a simulator of
the paper's chain from the paper and the model notes (``bench/cmaes_review/sim.py``),
drew eight chains under the paper's constraints alone (``draw.py``; seven of the
eight loops have their corners out of a proper loop's order) and fitted each with
a plain IPOP CMA-ES over its own gauge-fixed parameters (``fit.py``, 300,000
evaluations). This reruns both on those recordings, in memory: the CMA-ES and
``identify`` with its defaults (one process each), and prints per recording the
RMS residual over the true noise (1.0: the floor) of each, whether the true and
the kept loops are proper, and the seconds. Run from the repository root (about
ten minutes on 2 cores)::

    python bench/cmaes_review.py [--workers 2] [--budget 300000]
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench' / 'cmaes_review'))
sys.path.insert(0, str(ROOT))

import draw  # noqa: E402, I100
import fit  # noqa: E402

from hyst_id.identification import identify, IdentifySettings  # noqa: E402, I100
from hyst_id.io.recording import Recording  # noqa: E402


def one(job: tuple[int, int]) -> dict:
    """CMA-ES and identify on recording ``index``."""
    index, budget = job
    case = draw.draw_all()[index]
    cma = fit.fit(case, budget=budget, seed=0)
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'])
    t0 = time.monotonic()
    ident = identify(rec, settings=IdentifySettings(workers=1))
    rms = ident.er_percent / 100.0 * float(np.sqrt(np.mean(rec.measurement ** 2)))
    return {'name': case['name'], 'channel': case['channel'], 'excitation': case['excitation'],
            'n': rec.n_samples, 'noise': 100 * case['noise_frac'], 'true_proper': case['proper'],
            'cma': cma['ratio'], 'cma_s': cma['seconds'], 'identify': rms / case['sigma'],
            'kept_proper': ident.proper, 'identify_s': time.monotonic() - t0}


def main() -> int:
    """Run the eight recordings and print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--workers', type=int, default=2)
    ap.add_argument('--budget', type=int, default=300000)
    args = ap.parse_args()
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(one, [(i, args.budget) for i in range(len(draw.PLAN))]))
    print('rec  channel   excitation      n     noise %  true loop  CMA-ES  identify  kept loop'
          '  CMA-ES s  identify s')
    for r in rows:
        print(f'{r["name"]:4s} {r["channel"]:9s} {r["excitation"]:14s} {r["n"]:5d}  '
              f'{r["noise"]:7.2f}  {"proper" if r["true_proper"] else "improper":9s}  '
              f'{r["cma"]:6.4f}  {r["identify"]:8.4f}  '
              f'{"proper" if r["kept_proper"] else "improper":9s}  {r["cma_s"]:8.0f}  '
              f'{r["identify_s"]:10.0f}')
    near = sum(r['identify'] <= 1.01 * r['cma'] for r in rows)
    print(f'identify within 1 % of the CMA-ES on {near} of {len(rows)}; within 1.1 x the true '
          f'noise: identify {sum(r["identify"] <= 1.1 for r in rows)}, CMA-ES '
          f'{sum(r["cma"] <= 1.1 for r in rows)}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
