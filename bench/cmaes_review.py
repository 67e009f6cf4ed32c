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

``--seeds S1 S2 ...`` draws eight recordings per seed the same way (6565, the
default, is the reviewer's draw) and prints one table; ``--no-cma`` skips the
CMA-ES (its column then reads ``nan``); ``--diagnose`` also runs ``diagnose``
with its defaults on each (every recording is the bare chain, so any mechanism
claimed is a false claim) and prints the verdict, the final held-out %e_r over
the diagnosis's own floor, its baseline's training %e_r over the training floor
and the seconds (docs/reliability.md section 15); ``--indices`` runs only those
recordings of each draw::

    python bench/cmaes_review.py --seeds 1 2 3 4 --no-cma --diagnose --workers 1
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

from hyst_id.diagnosis import diagnose  # noqa: E402, I100
from hyst_id.identification import identify, IdentifySettings  # noqa: E402
from hyst_id.io.recording import Recording  # noqa: E402


def one(job: tuple[int, int, int, bool, bool]) -> dict:
    """CMA-ES, identify and (optionally) diagnose on recording ``index`` of draw ``seed``."""
    seed, index, budget, with_cma, with_diagnose = job
    case = draw.draw_all(seed)[index]
    cma = {'ratio': np.nan, 'seconds': np.nan}
    if with_cma:
        cma = fit.fit(case, budget=budget, seed=0)
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'])
    t0 = time.monotonic()
    ident = identify(rec, settings=IdentifySettings(workers=1))
    rms = ident.er_percent / 100.0 * float(np.sqrt(np.mean(rec.measurement ** 2)))
    row = {'name': f'{seed % 10000}:{case["name"]}', 'channel': case['channel'],
           'excitation': case['excitation'], 'n': rec.n_samples,
           'noise': 100 * case['noise_frac'], 'true_proper': case['proper'],
           'cma': cma['ratio'], 'cma_s': cma['seconds'], 'identify': rms / case['sigma'],
           'kept_proper': ident.proper, 'identify_s': time.monotonic() - t0}
    if with_diagnose:
        t0 = time.monotonic()
        d = diagnose(rec)
        row.update(verdict=d.verdict, findings=[f.mechanism for f in d.findings],
                   final=d.final.er_holdout_percent / d.noise_floor_percent,
                   base_train=d.baseline.er_train_percent / d.noise_floor_train_percent,
                   diagnose_s=time.monotonic() - t0)
    return row


def main() -> int:
    """Run the eight recordings and print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--workers', type=int, default=2)
    ap.add_argument('--budget', type=int, default=300000)
    ap.add_argument('--seeds', type=int, nargs='+', default=[6565], metavar='S')
    ap.add_argument('--no-cma', action='store_true', help='identify only')
    ap.add_argument('--diagnose', action='store_true', help='also run diagnose')
    ap.add_argument('--indices', type=int, nargs='+', metavar='I',
                    help='only these recordings of each draw (0: r1 ... 7: r8)')
    args = ap.parse_args()
    jobs = [(seed, i, args.budget, not args.no_cma, args.diagnose)
            for seed in args.seeds for i in (args.indices or range(len(draw.PLAN)))]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(one, jobs))
    print('rec      channel   excitation      n     noise %  true loop  CMA-ES  identify  '
          'kept loop  CMA-ES s  identify s'
          + ('  verdict (findings)  final x floor  baseline train x floor  diagnose s'
             if args.diagnose else ''))
    for r in rows:
        line = (f'{r["name"]:8s} {r["channel"]:9s} {r["excitation"]:14s} {r["n"]:5d}  '
                f'{r["noise"]:7.2f}  {"proper" if r["true_proper"] else "improper":9s}  '
                f'{r["cma"]:6.4f}  {r["identify"]:8.4f}  '
                f'{"proper" if r["kept_proper"] else "improper":9s}  {r["cma_s"]:8.0f}  '
                f'{r["identify_s"]:10.0f}')
        if args.diagnose:
            line += (f'  {r["verdict"]} ({", ".join(r["findings"]) or "-"})  '
                     f'{r["final"]:6.3f}  {r["base_train"]:6.3f}  {r["diagnose_s"]:6.0f}')
        print(line)
    ratios = np.array([r['identify'] for r in rows])
    if not args.no_cma:
        near = sum(r['identify'] <= 1.01 * r['cma'] for r in rows)
        print(f'identify within 1 % of the CMA-ES on {near} of {len(rows)}; CMA-ES within 1.1 x '
              f'the true noise on {sum(r["cma"] <= 1.1 for r in rows)}')
    print(f'identify within 1.1 x the true noise on {int(np.sum(ratios <= 1.1))} of {len(rows)} '
          f'(median {np.median(ratios):.4f}, worst {ratios.max():.4f}); seconds median '
          f'{np.median([r["identify_s"] for r in rows]):.0f}, '
          f'max {max(r["identify_s"] for r in rows):.0f}')
    if args.diagnose:
        claims = [r for r in rows if r['verdict'] not in ('none', 'unknown')]
        print(f'diagnose: {len(claims)} of {len(rows)} bare chains given a mechanism '
              f'({", ".join(r["name"] + " " + r["verdict"] for r in claims) or "none"}); '
              f'{sum(r["verdict"] == "unknown" for r in rows)} unknown; final held-out median '
              f'{np.median([r["final"] for r in rows]):.3f} x floor')
    return 0


if __name__ == '__main__':
    sys.exit(main())
