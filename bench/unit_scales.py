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

"""The piezo example identified with its measurement in other units: whether the fit is the same.

``docs/examples/piezo_stage.csv`` (volts -> um) with the measurement multiplied by
10^k for each ``k`` given, identified with the default settings (two worker processes);
prints the best %e_r, the noise floor and the time per scale. With
``--without-scale`` the least-squares polish runs on the raw residuals, as before the
residual scale of ``hyst_id.identification.refine.residual_scale`` (a measurement whose
RMS is below 1e-2 is polished on residuals divided by a power of two): the unit
dependence a review found. About 5 s per scale.

    python bench/unit_scales.py                      # k = 0 -5 -6 -7 -9 -12 3 12
    python bench/unit_scales.py --without-scale -- 0 -6 -7 -12
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
import sys
import time

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from hyst_id.identification import identify, IdentifySettings  # noqa: E402
import hyst_id.identification.refine as refine_module  # noqa: E402
from hyst_id.io.readers import read_recording  # noqa: E402


def main() -> int:
    """Identify the piezo example at each scale and print the figures."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('powers', type=int, nargs='*', default=[0, -5, -6, -7, -9, -12, 3, 12],
                    help='the k of the scales 10^k')
    ap.add_argument('--without-scale', action='store_true',
                    help='polish on the raw residuals (the code before the residual scale)')
    args = ap.parse_args()
    if args.without_scale:
        refine_module.residual_scale = lambda y: 1.0
    rec = read_recording(ROOT / 'docs' / 'examples' / 'piezo_stage.csv', 'position',
                         columns=['t_s', 'command_V', 'position_um'])
    how = 'raw residuals' if args.without_scale else 'residual scale'
    for k in args.powers:
        t0 = time.time()
        res = identify(replace(rec, measurement=rec.measurement * 10.0 ** k),
                       settings=IdentifySettings(workers=2))
        print(f'x 1e{k:+d} ({how}): %e_r {res.er_percent:.4f}, noise floor '
              f'{res.noise_floor_percent:.4f}, {time.time() - t0:.1f} s', flush=True)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
