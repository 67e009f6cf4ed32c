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

Usage: ``python bench/measured_loops.py [--data ../shared/data]``
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys


ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'bench'))
sys.path.insert(0, str(ROOT))

from real_recordings import load_all  # noqa: E402, I100

from hyst_id.diagnosis.measured_loop import measured_loop  # noqa: E402, I100
from hyst_id.identification.loop import loop_orientation  # noqa: E402


def main() -> int:
    """Print each recording's loop."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--data', default=str(ROOT.parent / 'shared' / 'data'))
    args = ap.parse_args()
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
