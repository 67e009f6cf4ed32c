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

"""Reproduce the paper's Fig. 2: GAASS vs a simple GA on F1 (2-D Shubert).

N_pop 6, 100 generations, seeds 0-9, rates of Eq. 17 and 20 for GAASS
(``c = 0.007``, ``xi = 0.02``, the paper's defaults), ``p_c = 0.9`` and
``p_m = 0.01`` for the SGA (roulette, no elitism).  F1 as printed (Eq. 23) is
minimised and ``-F1`` is reported, whose optimum is the paper's 186.7309.
Prints a per-seed table and saves ``fig2_shubert.png`` in ``--out``.

Usage: ``python bench/fig2_shubert.py [--out DIR]``
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))

from hyst_id.solvers import simple_ga as bm  # noqa: E402
from hyst_id.solvers.gaass import GaassResult, minimize  # noqa: E402
from hyst_id.solvers.simple_ga import shubert_2d, simple_ga  # noqa: E402

__all__ = ['run', 'main']

POP_SIZE = 6
GENERATIONS = 100
SEEDS = tuple(range(10))
REL_TOL = 1e-4  # 0.01 %


def _hit_generation(res: GaassResult) -> int | None:
    """First generation whose best-so-far ``-F1`` is within 0.01 % of the optimum."""
    hit = np.flatnonzero(-res.history.best_fun >= bm.F1_OPTIMUM * (1.0 - REL_TOL))
    return int(hit[0]) + 1 if hit.size else None


def run() -> tuple[list[GaassResult], list[GaassResult]]:
    """Run GAASS and the SGA for every seed.

    Returns
    -------
    tuple of list of GaassResult
        GAASS results and SGA results, in seed order.
    """
    gaass = [minimize(shubert_2d, bm.SHUBERT_2D_BOUNDS, pop_size=POP_SIZE, maxiter=GENERATIONS,
                      c=0.007, xi=0.02, p_c=(0.5, 0.9), p_m=(0.01, 0.3), rng=seed)
             for seed in SEEDS]
    sga = [simple_ga(shubert_2d, bm.SHUBERT_2D_BOUNDS, pop_size=POP_SIZE, maxiter=GENERATIONS,
                     p_c=0.9, p_m=0.01, selection='roulette', elitism=False, rng=seed)
           for seed in SEEDS]
    return gaass, sga


def _fmt_gen(gen: int | None) -> str:
    return '-' if gen is None else str(gen)


def print_table(gaass: list[GaassResult], sga: list[GaassResult]) -> None:
    """Print the per-seed table, means and success counts."""
    print(f'F1 (Eq. 23, reported as -F1), optimum {bm.F1_OPTIMUM:.4f}; N_pop {POP_SIZE}, '
          f'{GENERATIONS} generations; "gen" = first generation within 0.01 % of optimum')
    print(f'{"seed":>4} | {"GAASS best":>10} {"gen":>4} | {"SGA best":>10} {"gen":>4}')
    print('-' * 42)
    for seed, rg, rs in zip(SEEDS, gaass, sga, strict=True):
        print(f'{seed:>4} | {-rg.fun:>10.4f} {_fmt_gen(_hit_generation(rg)):>4} | '
              f'{-rs.fun:>10.4f} {_fmt_gen(_hit_generation(rs)):>4}')
    print('-' * 42)
    for name, results in (('GAASS', gaass), ('SGA', sga)):
        best = np.array([-r.fun for r in results])
        gens = [g for g in (_hit_generation(r) for r in results) if g is not None]
        mean_gen = f'{np.mean(gens):.1f}' if gens else '-'
        print(f'{name:>5}: mean best {best.mean():.4f}, median {np.median(best):.4f}, '
              f'min {best.min():.4f}; within 1 %: {np.sum(best >= 0.99 * bm.F1_OPTIMUM)}/'
              f'{len(best)}; within 0.01 %: {len(gens)}/{len(best)} '
              f'(mean generation {mean_gen}); nfev/run {results[0].nfev}')


def plot(gaass: list[GaassResult], sga: list[GaassResult], path: str) -> None:
    """Save best-so-far convergence curves: all GAASS seeds and the best SGA seed."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, (ax, ax_gap) = plt.subplots(1, 2, figsize=(11.0, 4.5))
    gens = np.arange(1, GENERATIONS + 1)
    best_sga = int(np.argmin([r.fun for r in sga]))
    curves = [(f'GAASS (seeds {SEEDS[0]}-{SEEDS[-1]})' if i == 0 else None, 'tab:blue', 1.0,
               -res.history.best_fun) for i, res in enumerate(gaass)]
    curves.append((f'SGA, best of {len(sga)} (seed {SEEDS[best_sga]})', 'tab:red', 2.0,
                   -sga[best_sga].history.best_fun))
    for label, color, lw, value in curves:
        ax.plot(gens, value, color=color, lw=lw, alpha=0.8, label=label)
        gap = np.maximum(bm.F1_OPTIMUM - value, 1e-6)
        ax_gap.semilogy(gens, gap, color=color, lw=lw, alpha=0.8, label=label)
    ax.axhline(bm.F1_OPTIMUM, color='k', ls='--', lw=0.8, label=f'optimum {bm.F1_OPTIMUM:.4f}')
    ax_gap.axhline(bm.F1_OPTIMUM * REL_TOL, color='k', ls=':', lw=0.8, label='0.01 % of optimum')
    ax.set_ylabel('best-so-far -F1')
    ax.set_title('F1 convergence, N_pop = 6 (paper Fig. 2)')
    ax.set_ylim(bottom=min(0.0, float(np.min(curves[-1][3]))))
    ax_gap.set_ylabel('optimum - best-so-far (clipped at 1e-6)')
    ax_gap.set_title('distance to the optimum')
    for axis in (ax, ax_gap):
        axis.set_xlabel('generation')
        axis.set_xlim(1, GENERATIONS)
        axis.grid(True, alpha=0.3)
        axis.legend(loc='lower right' if axis is ax else 'upper right', fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Entry point: run, print the table, save the figure."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--out', default=os.path.join('docs', 'figures'),
                        help='output directory for fig2_shubert.png (default docs/figures)')
    args = parser.parse_args(argv)
    gaass, sga = run()
    print_table(gaass, sga)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, 'fig2_shubert.png')
    plot(gaass, sga, path)
    print(f'saved {path}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
