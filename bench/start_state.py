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

"""Recordings whose actuator starts inside its play: identify with and without the start.

A play operator written apart from the package (``test/play_reference.py``:
``y = 2 play(u, 0.8) + 1``, noise 0.01), the command resting at 0 for
``rest`` seconds (the output mid-play, or on the rising edge), then 40 s of
a sine of varying amplitude at 100 Hz. For each
case and noise seed: the whole record's fit over the noise floor (from the
warning, when the start was left out) and the fit that identify reports.
See ``hyst_id/identification/start_state.py``. About two minutes.

With ``--diagnose``: ``diagnose`` instead (``hyst_id/diagnosis/start_cut.py``),
its verdict, findings, and the whole record's baseline and the probe from the
first reversal over their floors; about 7 minutes for the nine records. With
``--whole-record`` too, the diagnosis without the cut (what it was before).

With ``--mild``: a new-user trial's milder case (``play_reference.mild_start``: a sine
from the middle of a play behind a 0.15 s sensor), the whole record's fit and the
reported one over the floor with the fitted lag; about a minute.

Usage: ``python bench/start_state.py [--seeds 0 1 2] [--diagnose [--whole-record] | --mild]``
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
import re
import sys

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT))

from hyst_id.diagnosis import diagnose, DiagnoseSettings  # noqa: E402
from hyst_id.identification import identify, IdentifySettings  # noqa: E402

from play_reference import mild_start, rest_then_sine  # noqa: E402, I100


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--seeds', type=int, nargs='+', default=[0, 1, 2])
    ap.add_argument('--diagnose', action='store_true', help='diagnose instead of identify')
    ap.add_argument('--whole-record', action='store_true',
                    help='with --diagnose: no start cut (DiagnoseSettings.start_state off)')
    ap.add_argument('--mild', action='store_true',
                    help="a new-user trial's mild start (play_reference.mild_start) instead")
    args = ap.parse_args()
    settings = IdentifySettings(seeds=(0, 1, 2), workers=1)
    if args.mild:
        _mild(args.seeds)
        return
    for rest, inside in ((20.0, True), (0.0, True), (20.0, False)):
        for seed in args.seeds:
            if args.diagnose:
                _diagnose(rest, inside, seed, not args.whole_record)
                continue
            ident = identify(rest_then_sine(seed, rest, inside, sine_s=40.0), settings=settings)
            ratio = ident.er_percent / ident.noise_floor_percent
            left = next((w for w in ident.warnings if 'left out of the fit' in w), '')
            whole = re.search(r'with them the fit was ([0-9.]+) x', left)
            print(f'rest {rest:g} s, {"inside the play" if inside else "on its edge"}, '
                  f'noise seed {seed}: whole record '
                  f'{whole.group(1) if whole else f"{ratio:.2f}"} x the floor, reported '
                  f'{ratio:.3f} x' + (f' (the first {left.split(" s (")[0][10:]} s left out)'
                                      if left else ' (fitted whole)'), flush=True)


def _mild(seeds: list[int]) -> None:
    """The whole record's fit and the reported one, with the sensor lag (true 0.15 s)."""
    fast = IdentifySettings(seeds=(0, 1, 2), workers=1, global_runs=0, hops=0)
    for seed in seeds:
        for retry in (False, True):
            ident = identify(mild_start(seed), settings=replace(fast, start_state=retry))
            left = any('left out of the fit' in w for w in ident.warnings)
            print(f'mild start, noise seed {seed}, {"retry" if retry else "whole record"}: '
                  f'{ident.er_percent / ident.noise_floor_percent:.3f} x the floor, tau_s '
                  f'{ident.params["tau_s"]:.4f} s{" (start left out)" if left else ""}',
                  flush=True)


def _diagnose(rest: float, inside: bool, seed: int, cut: bool) -> None:
    d = diagnose(rest_then_sine(seed, rest, inside, sine_s=40.0),
                 settings=DiagnoseSettings(workers=1, start_state=cut))
    left = next((n for n in d.notes if 'left out of the diagnosis' in n), '')
    ratios = re.search(r'with them the fit was ([0-9.]+) x .* without them ([0-9.]+) x', left)
    print(f'rest {rest:g} s, {"inside the play" if inside else "on its edge"}, noise seed '
          f'{seed}: verdict {d.verdict} {[f.mechanism for f in d.findings]}, '
          + (f'cut at {d.t_s[0]:.2f} s: whole-record baseline {ratios.group(1)} x, probe '
             f'{ratios.group(2)} x the floor' if ratios else 'diagnosed whole'), flush=True)


if __name__ == '__main__':
    main()
