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

"""Make the concealed recordings in ``bags/`` for the blind diagnosis test.

Each bag is a rosbag2 MCAP directory written with
:func:`hyst_id.io.bag.write_recording_bag` from a run of the pipeline rig
simulator (:func:`hyst_id.rig.simulate_rig`) with at most one effect
switched on. The bag names (``case_a`` ...) do not say which: the answer
key is :data:`CASES` below, read by ``test/diagnosis/test_concealed_bags.py``, and
``bags/README.md`` lists only the channel of each bag.

Run from the repository root::

    python bench/make_concealed_bags.py            # writes bags/case_*/
    python bench/make_concealed_bags.py case_h     # writes one of them
"""

from __future__ import annotations

from pathlib import Path
import shutil
import sys

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from hyst_id.io.bag import write_recording_bag  # noqa: E402
from hyst_id.rig import RigParams, simulate_rig  # noqa: E402
from hyst_id.signals.excitation import eq25, multisine  # noqa: E402

#: Sampling and length of every bag.
DT_S = 0.05
DURATION_S = 120.0

#: A realistic industrial pressure transmitter: 0.1 % of a 1 MPa span of noise.
PRESSURE_NOISE = {'pressure_sensor.noise_std_pa': 1000.0}

#: An actuator whose hysteron reaches its own top line (slope 0.3) inside the commanded
#: range, above 9.6 mA.
TOP_LINE_ACTUATOR = {'actuator.m_t': 0.3, 'actuator.c_t': 6.675, 'actuator.c_b': 5.0}

#: name -> (channel, excitation, seed, rig settings, expected verdict). The answer key.
#: The clean-supply pressure runs (case_d) use a smaller command amplitude (1 mA), where
#: the pneumatics' own
#: nonlinear pressure map is weakest. It still shows in some clean pressure runs
#: (docs/diagnosis.md: the sweep names it in clean pressure runs), so the clean
#: recordings here are position recordings, where the rig with no effect is exactly
#: the paper's chain plus sensor noise. The valve-characteristic case (case_h) has the full
#: 1.8 mA multisine and rangeability 50: at 1 mA and 20 the effect cost only 1.25 x the
#: noise floor and the verdict changed with round-off (docs/diagnosis.md). The end-stop
#: case uses :data:`TOP_LINE_ACTUATOR`: with the default actuator the hysteron's top and
#: bottom lines lie beyond the commanded range and a fitted hysteron reproduces any stop
#: with them, so a stop is only distinguishable once the hysteron's own top line shows.
CASES = {
    'case_a': ('position', 'multisine', 11,
               {'effects.rate_hysteresis.enabled': True,
                'effects.rate_hysteresis.width_per_rate_s': 0.3,
                'effects.rate_hysteresis.filter_tau_s': 1.0}, 'rate_dependence'),
    'case_b': ('position', 'sine', 12, {}, 'none'),
    'case_c': ('position', 'multisine', 13,
               {'effects.dead_time.enabled': True, 'effects.dead_time.delay_s': 0.15},
               'dead_time'),
    'case_d': ('pressure', 'small sine', 14, {**PRESSURE_NOISE, 'supply.regulation': False},
               'supply_decay'),
    'case_e': ('position', 'sine', 15,
               {'effects.sensor_lag.enabled': True, 'effects.sensor_lag.position_tau_s': 0.3},
               'sensor_lag'),
    'case_f': ('position', 'multisine', 16,
               {**TOP_LINE_ACTUATOR, 'effects.end_stops.enabled': True,
                'effects.end_stops.min_position': 0.0,
                'effects.end_stops.max_position': 9.55}, 'saturation'),
    'case_g': ('position', 'sine', 17,
               {'effects.offset_drift.enabled': True,
                'effects.offset_drift.position_per_s': 0.002}, 'offset_drift'),
    'case_h': ('pressure', 'multisine', 18,
               {**PRESSURE_NOISE, 'effects.valve_characteristic.enabled': True,
                'effects.valve_characteristic.kind': 'equal_percentage',
                'effects.valve_characteristic.rangeability': 50.0}, 'static_nonlinearity'),
    'case_i': ('position', 'multisine', 19, {}, 'none'),
    'case_j': ('position', 'multisine', 20,
               {'effects.stick_slip.enabled': True, 'effects.stick_slip.static_band': 0.15,
                'effects.stick_slip.dynamic_band': 0.05}, 'stiction'),
}


def excitation(kind: str, t_s: np.ndarray) -> np.ndarray:
    """Command profile of a bag (mA): 1.8 mA amplitude, 1 mA for the 'small' ones."""
    amplitude = 1.0 if kind.startswith('small') else 1.8
    if kind.endswith('sine') and not kind.endswith('multisine'):
        return eq25(t_s, amplitude_ma=amplitude, period_s=10.0)
    return multisine(t_s, amplitude_ma=amplitude)


def make(name: str, out_dir: Path = ROOT / 'bags') -> Path:
    """Simulate one case and write its bag directory."""
    channel, kind, seed, values, _ = CASES[name]
    t = np.arange(0.0, DURATION_S, DT_S)
    run = simulate_rig(RigParams().with_values(values), t, excitation(kind, t), seed=seed)
    rec = run.recording(channel)
    path = out_dir / name
    if path.exists():
        shutil.rmtree(path)
    return write_recording_bag(path, rec)


def main(names: list[str]) -> int:
    """Write the named bags (every bag when none is named)."""
    for name in names or CASES:
        path = make(name)
        size = sum(f.stat().st_size for f in path.rglob('*') if f.is_file())
        print(f'{path.relative_to(ROOT)}: {CASES[name][0]}, {size / 1e3:.0f} kB')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
