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

"""Clean recordings under coloured noise: whether the diagnosis claims physics that is not there.

A real rig's noise is rarely white: a sensor's own filter, 1/f drift and
mains hum aliased by the sampling all correlate it over samples, and the
noise floor (estimated from sample-to-sample changes) then reads low. This
draws the blind family's recordings (``bench/blind_family.py``) with every
effect left out (the reference chain alone: no physics beyond the paper's), the
same noise standard deviation as the family's but coloured, and diagnoses each:

``white``
    the family's own noise (the control);
``ar1``
    a first-order autoregression, lag-one correlation 0.6-0.95;
``lowpass``
    white noise through a second-order Butterworth filter at 5-30 % of the
    Nyquist frequency;
``pink``
    a 1/f spectrum (random phases);
``hum``
    half the variance white, half a mains sine of 49.8-50.2 Hz sampled at the
    recording's rate (aliased to a slow oscillation at most rates).

It prints, per recording, the verdict, the findings held up by blocked
cross-validation (claims) and those only stated, and the baseline's and final
held-out error over the floor; then the claims per noise kind. A claim on any
of these recordings names physics the recording does not have. Run from the
repository root (about 20 s per diagnosis and worker)::

    python bench/coloured_noise_family.py [--n 12] [--kinds white ar1 lowpass pink hum]
        [--workers 2] [--json rows.json]
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import json
from pathlib import Path
import sys

import numpy as np
from scipy.signal import butter, lfilter

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT))

from blind_family import draw  # noqa: E402, I100

from hyst_id.diagnosis import diagnose, DiagnoseSettings  # noqa: E402, I100
from hyst_id.diagnosis.blocked_cv import confirmed  # noqa: E402
from hyst_id.io.recording import Recording  # noqa: E402

KINDS = ('white', 'ar1', 'lowpass', 'pink', 'hum')


def coloured(kind: str):
    """``noise(rng, n, sigma, dt_s)`` of the kind, for :func:`blind_family.draw`."""
    def noise(rng: np.random.Generator, n: int, sigma: float, dt_s: float) -> np.ndarray:
        w = rng.normal(0.0, 1.0, n)
        if kind == 'white':
            e = w
        elif kind == 'ar1':
            e = lfilter([1.0], [1.0, -rng.uniform(0.6, 0.95)], w)
        elif kind == 'lowpass':
            e = lfilter(*butter(2, rng.uniform(0.05, 0.3)), w)
        elif kind == 'pink':
            f = np.fft.rfftfreq(n)
            amp = np.where(f > 0, 1.0 / np.sqrt(np.maximum(f, 1e-12)), 0.0)
            e = np.fft.irfft(amp * np.exp(2j * np.pi * rng.uniform(0, 1, f.size)), n)
        else:
            t = np.arange(n) * dt_s
            hz = rng.uniform(49.8, 50.2)
            e = np.sqrt(0.5) * w + np.sin(2 * np.pi * hz * t + rng.uniform(0, 2 * np.pi))
        e = e - e.mean()
        return sigma * e / e.std()
    return noise


def one(job: tuple[int, str]) -> dict:
    """Recording ``index`` without its effects, noise of ``kind``: the diagnosis's answer."""
    index, kind = job
    case = draw(index, only=frozenset(), noise=coloured(kind))
    rec = Recording(case['t'], case['command'], case['measurement'], case['channel'],
                    source=f'blind #{index} {kind}')
    d = diagnose(rec, settings=DiagnoseSettings(workers=1))
    j = d.extra['judged_holdout']
    claims = [f.mechanism for f in d.findings if confirmed(f.blocked_cv)]
    return {'index': index, 'kind': kind, 'channel': case['channel'],
            'excitation': case['excitation'], 'dt_s': case['dt_s'], 'verdict': d.verdict,
            'claims': claims,
            'stated': [f.mechanism for f in d.findings if f.mechanism not in claims],
            'baseline': j['baseline_er_percent'] / j['noise_floor_percent'],
            'final': j['final_er_percent'] / j['noise_floor_percent']}


def main(argv: list[str] | None = None) -> int:
    """Diagnose the clean draws under each noise kind and print the claims."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--n', type=int, default=12, help='recordings of the family (0..n-1)')
    ap.add_argument('--kinds', nargs='+', choices=KINDS, default=list(KINDS))
    ap.add_argument('--workers', type=int, default=2)
    ap.add_argument('--json', type=Path, help='write the rows here')
    args = ap.parse_args(argv)
    jobs = [(i, k) for i in range(args.n) for k in args.kinds]
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(one, jobs))
    print('   #  noise    channel   excitation        dt s   verdict               claims / '
          'stated                  baseline  final (x floor)')
    for r in rows:
        said = '+'.join(r['claims']) or '-'
        if r['stated']:
            said += ' / ' + '+'.join(r['stated'])
        print(f'#{r["index"]:3d}  {r["kind"]:7s}  {r["channel"]:8s}  {r["excitation"]:16s} '
              f'{r["dt_s"]:5.2f}  {r["verdict"]:20s}  {said:30s} {r["baseline"]:6.2f}  '
              f'{r["final"]:6.2f}')
    for k in args.kinds:
        mine = [r for r in rows if r['kind'] == k]
        bad = [r for r in mine if r['claims']]
        print(f'{k}: physical claims on {len(bad)} of {len(mine)} clean recordings'
              + (' (' + ', '.join(f'#{r["index"]} {"+".join(r["claims"])}' for r in bad) + ')'
                 if bad else '')
              + f'; verdict none {sum(r["verdict"] == "none" for r in mine)}, unknown '
              f'{sum(r["verdict"] == "unknown" for r in mine)}')
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == '__main__':
    sys.exit(main())
