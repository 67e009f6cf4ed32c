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

"""The measured loop of every real recording in ``../shared/data``, from the data alone.

Prints, per recording, the signed-area orientation index
(:func:`hyst_id.identification.loop.loop_orientation`, in the frame where the
measurement rises with the command: negative counter-clockwise) next to
:func:`hyst_id.diagnosis.measured_loop.measured_loop`'s level-by-level
direction, half-width and slow/fast sweeps, and its words. Where the two
disagree, loops that do not close (the B(H) records' loops of growing
amplitude) have spoiled the signed area. A second or so in all.

With ``--spreads`` it prints instead the ranges over seeds 0-29 that
``test/diagnosis/test_measured_loop.py``'s bounds come from: the half-width
of a Dahl friction force over its size, and of the paper's loop (reference
simulator) as a share of the span, under a multisine and under a staircase of
held steps; a band, a play and a single-valued curve under a command with
noise of 0.5-5 % of its span; a play with a negative gain whose swing barely
exceeds its dead band (the documented limit); and how much the half-width
moves when the inputs' last bits do. Half a minute.

Usage: ``python bench/measured_loops.py [--data ../shared/data] [--spreads]``
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys


ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT / 'test'))
sys.path.insert(0, str(ROOT / 'test' / 'diagnosis'))
sys.path.insert(0, str(ROOT))

from real_recordings import load_all  # noqa: E402, I100

from hyst_id.diagnosis.measured_loop import measured_loop  # noqa: E402, I100
from hyst_id.identification.loop import loop_orientation  # noqa: E402


def spreads(seeds: range = range(30)) -> None:
    """Print the ranges the test's bounds come from (the test's own cases)."""
    import numpy as np
    from play_reference import play
    from test_measured_loop import dahl_case, last_bits_moved, noisy_sine_case, papers_loop_case
    from test_measured_loop import staircase_case

    friction, paper, steps = [], [], []
    for seed in seeds:
        t, v, y, force = dahl_case(seed)
        loop = measured_loop(t, v, y)
        friction.append((loop.direction, loop.half_width / force))
        loop = measured_loop(*papers_loop_case(seed)[:3])
        paper.append((loop.direction, loop.half_width_share))
        loop = measured_loop(*staircase_case(seed)[:3])
        steps.append((loop.direction, loop.half_width_share))
    for share in (0.005, 0.01, 0.02, 0.05):
        bands, curves, dirs = [], [], set()
        for seed in range(10):
            t, v, clean, e = noisy_sine_case(seed, share)
            band = measured_loop(t, v, clean + 0.3 * np.sign(np.gradient(clean, t)) + e)
            lag = measured_loop(t, v, play(clean, 0.3, clean[0]) + e)
            curve = measured_loop(t, v, clean + e)
            bands.append(band.half_width)
            curves.append(curve.half_width_share)
            dirs |= {f'band {band.direction}', f'play {lag.direction}',
                     f'curve {curve.direction}'}
        print(f'command noise {100 * share:g} % of the span, seeds 0-9: {", ".join(sorted(dirs))};'
              f' band of 0.3 read {min(bands):.3g}-{max(bands):.3g}; curve up to '
              f'{100 * max(curves):.2f} % of the span')
    t, _, clean, _ = noisy_sine_case(0, 0.0)
    for dead_band in (0.8, 0.9, 0.95):
        loop = measured_loop(t, clean, -play(clean, dead_band, clean[0]))
        print(f'a play of half-width {dead_band} on a swing of +-1, negative gain: '
              f'{loop.direction} (swing {2.0 / (2 * dead_band):.2f} x the dead band)')
    worst, runs = 0.0, 0
    for case in (dahl_case, papers_loop_case, staircase_case):
        for seed in seeds:
            t, v, y, _ = case(seed)
            a = measured_loop(t, v, y)
            for k in range(5):
                rng = np.random.default_rng(k)
                b = measured_loop(*(last_bits_moved(x, rng) for x in (t, v, y)))
                worst = max(worst, abs(b.half_width - a.half_width) / abs(a.half_width))
                runs += 1
                if (a.direction, a.rises_with_command) != (b.direction, b.rises_with_command):
                    print(f'  {case.__name__}({seed}): the direction moved with the last bits')
    print(f'last bits moved (up to 4 ulps a sample), {runs} runs: largest relative change of '
          f'the half-width {worst:.1e}')
    for name, rows, what in (('Dahl friction (multisine)', friction, 'of the force'),
                             ("the paper's loop (multisine)", paper, 'of the span'),
                             ("the paper's loop (staircase)", steps, 'of the span')):
        dirs = sorted({d for d, _ in rows})
        vals = [x for _, x in rows]
        print(f'{name}, seeds {seeds.start}-{seeds.stop - 1}: direction {", ".join(dirs)}; '
              f'half-width {min(vals):.3g}-{max(vals):.3g} {what}')


def main() -> int:
    """Print each recording's loop."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--data', default=str(ROOT.parent / 'shared' / 'data'))
    ap.add_argument('--spreads', action='store_true',
                    help="print the seeds' ranges the test's bounds come from")
    args = ap.parse_args()
    if args.spreads:
        spreads()
        return 0
    for rec in load_all(Path(args.data)):
        loop = measured_loop(rec.t_s, rec.command, rec.measurement)
        y = rec.measurement if loop.rises_with_command else -rec.measurement
        area = loop_orientation(rec.command, y)
        print(f'{rec.source}: signed-area index {area:+.3f}; level by level '
              f'{loop.direction}, half-width {loop.half_width:.3g} {rec.measurement_unit} '
              f'({100 * loop.half_width_share:.1f} % of the span); slow sweeps '
              f'{loop.half_width_slow:.3g} at {loop.rate_slow:.3g}/s over '
              f'{loop.span_slow:.3g}, fast {loop.half_width_fast:.3g} at '
              f'{loop.rate_fast:.3g}/s over {loop.span_fast:.3g}; rate signature '
              f'{"not compared" if loop.grows_with_rate is None else loop.grows_with_rate}')
        print(f'  {loop.words("measurement", rec.measurement_unit)}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
