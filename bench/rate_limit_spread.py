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
"""``rate_limit`` over seeds and over drawn recordings: the spreads the tests' bounds rest on.

Part 1 (``--seeds``): the recordings of ``test/diagnosis/test_rate_limit.py``
(steps between held levels into the reference chain, followed at 0.8 mA/s),
diagnosed with the tests' settings, and the same recordings without the
limit. Part 2 (``--drawn``): recordings drawn as the blind family draws its
chains (``bench/generalisation.py``: random loop, backlash, excitation,
units), position and pressure, each with a slew at a top rate that crosses
the command's range in 2-20 s, diagnosed with the default settings. Prints
the verdict, the fitted rate over the true one and the final held-out error
over the noise floor.

Run from the repository root (about 10 minutes on 2 cores)::

    python bench/rate_limit_spread.py [--seeds 6] [--drawn 6]
    python bench/rate_limit_spread.py --seeds 2 --drawn 0 --without   # the library before it
    python bench/rate_limit_spread.py --seeds 4 --drawn 0 --probes 1 2  # other CPU makes
"""

from __future__ import annotations

import argparse
from dataclasses import replace
import os
from pathlib import Path
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))
sys.path.insert(0, str(ROOT))

from blind_family import draw_excitation  # noqa: E402, I100
from generalisation import _draw_params  # noqa: E402, I100
from reference_sim import first_order_sensor  # noqa: E402, I100
from reference_sim import simulate as reference_simulate  # noqa: E402, I100
from test_rate_limit import _recording, RATE_MA_S, reference_slew, SETTINGS  # noqa: E402

from hyst_id.diagnosis import diagnose, DiagnoseSettings  # noqa: E402, I100
from hyst_id.diagnosis.mechanisms import get_mechanisms  # noqa: E402
from hyst_id.io.recording import Recording, ROUNDOFF_PROBE_ENV  # noqa: E402


def drawn(index: int) -> tuple[Recording, float]:
    """Recording ``index`` of part 2 and its true top rate (command units per second)."""
    rng = np.random.default_rng([index, 77])
    channel = ('position', 'pressure')[index % 2]
    dt = float(rng.choice([0.02, 0.05, 0.1]))
    t = np.arange(2000) * dt
    kind, v = draw_excitation(rng, t)
    p = _draw_params(channel, v, rng, t[-1])
    rate = float(np.ptp(v)) / float(np.exp(rng.uniform(np.log(2.0), np.log(20.0))))
    x = reference_simulate('position', p, t, reference_slew(t, v, rate))
    y = first_order_sensor(t, x, p['tau_s']) if channel == 'pressure' else x
    y = y + rng.normal(0.0, rng.uniform(0.002, 0.01) * np.ptp(y), y.size)
    a, b = float(np.exp(rng.uniform(np.log(0.5), np.log(5.0)))), float(rng.uniform(-5, 5))
    return Recording(t, a * v + b, 40.0 * y - 3.0, channel, source=f'{kind} #{index}'), a * rate


def _line(label: str, d, rate: float | None, seconds: float) -> str:
    found = '+'.join(f.mechanism for f in d.findings) or d.verdict
    fitted = [f.params['max_rate'].value for f in d.findings if f.mechanism == 'rate_limit']
    ratio = f'rate {fitted[0] / rate:.4f} x true' if fitted and rate else '-'
    calls = [a['mechanism'] for f in d.findings for a in f.alternatives
             if 'mechanism' in a]
    final = d.final.er_holdout_percent / d.noise_floor_percent
    j = d.extra['judged_holdout']
    judged = j['final_er_percent'] / j['noise_floor_percent']
    return (f'{label:34s} {found:34s} {ratio:20s} final {final:5.2f} x floor (judged '
            f'{judged:5.2f} x on {j["n_samples"]}/{j["n_holdout"]})  '
            f'calls {",".join(calls) or "-"}  ({seconds:.0f} s)')


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, default=6)
    ap.add_argument('--drawn', type=int, default=6)
    ap.add_argument('--probes', type=int, nargs='*', default=[], metavar='SEED',
                    help='part 1 under these round-off probes instead (another CPU make)')
    ap.add_argument('--without', action='store_true',
                    help='offer every block but rate_limit: what the library said before it')
    args = ap.parse_args()

    def offered(settings: DiagnoseSettings, channel: str) -> DiagnoseSettings:
        if not args.without:
            return settings
        return replace(settings, mechanisms=tuple(
            m.id for m in get_mechanisms(channel=channel) if m.id != 'rate_limit'))

    tests = offered(SETTINGS, 'position')
    for probe in args.probes or [None]:
        if probe is not None:
            os.environ[ROUNDOFF_PROBE_ENV] = str(probe)
        for seed in range(args.seeds):
            for rate in (RATE_MA_S, None):
                t0 = time.perf_counter()
                d = diagnose(_recording(seed, rate), settings=tests)
                label = (f'test seed {seed}, ' + ('limited' if rate else 'no limit')
                         + (f', probe {probe}' if probe is not None else ''))
                print(_line(label, d, rate, time.perf_counter() - t0), flush=True)
    os.environ.pop(ROUNDOFF_PROBE_ENV, None)
    for index in range(args.drawn):
        rec, rate = drawn(index)
        t0 = time.perf_counter()
        d = diagnose(rec, settings=offered(DiagnoseSettings(), rec.channel))
        print(_line(f'drawn {index} {rec.channel} {rec.source}', d, rate,
                    time.perf_counter() - t0), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
