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

"""Fitted ``dead_time`` in sample intervals for a half-sample and a one-sample shift.

The reference chain (``test/reference_sim``) at its true values, fed the command
averaged with the one before (a half sample) or the one before (one sample),
0.05 s, noise 0.1 % and 0.4 % of the span, 8 noise seeds; the ``dead_time``
block fitted and judged as in a diagnosis round (``trial.try_mechanism``), as
``test/diagnosis/test_dead_time.py`` does. Prints each fit's delay and status,
and the range per case: where the 0.8-interval rule of
``hyst_id/diagnosis/mechanisms/dead_time.py`` lies against them. About 20 s.

Usage (from the repository root)::

    python bench/dead_time_samples.py [--seeds 8]
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))

import numpy as np  # noqa: E402,I100
from test_dead_time import (  # noqa: E402
    chain_spec, ComposedModel, Context, Data, DiagnoseSettings, DT_S, evaluate, get_mechanisms,
    locate, multisine, NAMES, reference_simulate, TRUTH)

from hyst_id.diagnosis.trial import try_mechanism  # noqa: E402


def fitted(shift: str, noise: float, seed: int) -> tuple[float, str]:
    """Fitted delay (sample intervals) and the round's status."""
    t = np.arange(0.0, 2000 * DT_S, DT_S)
    v = multisine(t, amplitude_ma=1.8)
    seen = 0.5 * (v + np.r_[v[0], v[:-1]]) if shift == 'half' else np.r_[v[0], v[:-1]]
    x = reference_simulate('position', dict(zip(NAMES, TRUTH)), t, seen)
    sigma = noise * np.ptp(x)
    y = x + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    n = int(0.7 * t.size)
    ctx = Context('position', t, n)
    data = Data(t_s=t, v=v, y=y, n_train=n, noise_std=sigma)
    current = evaluate(ComposedModel('position', [], ctx, chain_spec('position').bounds),
                       data, TRUTH)
    loc = locate(t, v, y, current.prediction, sigma, n, None)
    m = get_mechanisms(('dead_time',), channel='position')[0]
    comp = try_mechanism(m, current, data, ctx, DiagnoseSettings(fit_budget=300), loc, [])
    return float(comp.fit.model.theta(comp.fit.p, 'dead_time')[0]) / DT_S, comp.status


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, default=8)
    args = ap.parse_args(argv)
    for shift, noise in (('half', 0.001), ('half', 0.004), ('one', 0.004), ('one', 0.001)):
        got = [fitted(shift, noise, seed) for seed in range(args.seeds)]
        samples = [s for s, _ in got]
        print(f'{shift} sample, noise {100 * noise:.1f} % of the span: fitted '
              f'{min(samples):.2f}-{max(samples):.2f} intervals; accepted '
              f'{sum(st == "accepted" for _, st in got)}/{len(got)}')
        for seed, (s, st) in enumerate(got):
            print(f'    seed {seed}: {s:.3f}  {st[:70]}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
