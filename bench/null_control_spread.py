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

"""Spread of the null control's figures over noise seeds and round-off probes.

``test/diagnosis/test_null_control.py`` asserts on one noise seed; this prints
the same figures for ``--seeds`` seeds, each unperturbed and under the
round-off probes (the measurement perturbed by 1e-12 relative, as
``HYST_ID_ROUNDOFF_PROBE`` does to a recording: another CPU's last bits), so
that the test's bounds sit outside what the computation gives elsewhere:
for a clean recording with an under-converged baseline, whether the block is
accepted against the baseline, the refit's training SSE over the baseline's,
its held-out %e_r over the floor and whether the block is withdrawn; for a
recording with a real offset drift, whether the block survives; and for the
equivalent-chain rule (a current model as good on training, its held-out
prediction moved by 0, 0.2 and 3 noise std), the gain the shift costs, how
often the refit is chosen, its held-out %e_r over the floor and its training BIC
against the current one.

Run from the repository root (a few minutes)::

    python bench/null_control_spread.py [--seeds 8] [--probes 3]
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))
sys.path.insert(0, str(ROOT))

import test_null_control as case  # noqa: E402, I100

from hyst_id.diagnosis.control import null_control, recheck  # noqa: E402, I100
from hyst_id.diagnosis.select import compare, Criteria, evaluate, fit_model  # noqa: E402


def one(drift: float, seed: int, probe: int | None) -> tuple[bool, float, float, bool]:
    """Accepted against the baseline, SSE ratio, refit / floor, withdrawn."""
    data, base, m, model = case.make_case(drift, seed)
    if probe is not None:
        rng = np.random.default_rng([probe, seed])
        data.y = data.y * (1.0 + 1e-12 * rng.standard_normal(data.y.size))
    start = case.OFF if drift == 0.0 else case.TRUTH
    current = evaluate(base, data, start)
    fit = fit_model(model, data, model.pack(start, {}), m, budget=600)
    comp = compare(current, fit, data, m.id, Criteria())
    accepted = comp.accepted
    null = null_control(comp, current, data, max_nfev=1200)
    if null is None:
        return accepted, float('nan'), float('nan'), False
    lost = recheck([comp], null, data, Criteria())
    return (accepted, null.sse_train / current.sse_train,
            null.er_holdout_percent / data.floor_holdout_percent, lost == 1)


def main() -> int:
    """Print the figures per drift over seeds and probes."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, default=8)
    ap.add_argument('--probes', type=int, default=3)
    args = ap.parse_args()
    for drift in (0.0, 0.05):
        rows = []
        for probe in [None, *range(1, args.probes + 1)]:
            rows += [one(drift, s, probe) for s in range(args.seeds)]
        acc, ratio, er, gone = (np.array(c, dtype=float) for c in zip(*rows))
        print(f'drift {drift:g}: {len(rows)} runs; accepted against the baseline '
              f'{int(acc.sum())}/{len(rows)}; withdrawn {int(gone.sum())}/{len(rows)}; '
              f'refit SSE / baseline SSE {np.nanmin(ratio):.3f}-{np.nanmax(ratio):.3f}; '
              f'refit held-out / floor {np.nanmin(er):.2f}-{np.nanmax(er):.2f}')
    for shift in (0.0, 0.2, 3.0):
        rows = [case.equivalent_case(shift, s, probe) for probe in
                [None, *range(1, args.probes + 1)] for s in range(args.seeds)]
        chosen = [(d, cur, o) for d, cur, _, o in rows if o is not None]
        gains = np.array([g for _, _, g, _ in rows])
        line = (f'equivalent chain, held-out off by {shift:g} std: {len(rows)} runs; shift '
                f'costs {100 * gains.min():.1f}-{100 * gains.max():.1f} % held-out gain; '
                f'chosen {len(chosen)}/{len(rows)}')
        if chosen:
            er = [o.er_holdout_percent / d.floor_holdout_percent for d, _, o in chosen]
            dbic = [o.bic(d.n_train) - cur.bic(d.n_train) for d, cur, o in chosen]
            line += (f'; refit held-out / floor {min(er):.2f}-{max(er):.2f}, training BIC '
                     f'{min(dbic):+.1f} to {max(dbic):+.1f}')
        print(line, flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
