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

"""The exchange step's figures (``hyst_id/diagnosis/exchange.py``, docs/diagnosis.md section 4).

Prints every rival the step tries in a finding's place, judged against the final
model (training BIC, held-out z, share of what is left above the floor, relative
gain, its own trial's status, better or not) and the exchanges made, on:

* the reference chain with a static curve and a 0.3 s sensor lag or a six-sample
  dead time, the wrong and then the right lag block forced into the final model
  (``test/lag_cases.py: forced``);
* blind #24 (``bench/blind_family.py``: a sensor lag of 1.9 samples and a static
  curve) and its mirror (a two-sample dead time in place of the lag,
  ``test/lag_cases.py: mirror_of_24``), diagnosed with the defaults: the findings and
  the final held-out %e_r over the floor.

The round-off probe is read from ``HYST_ID_ROUNDOFF_PROBE`` as everywhere (set it
before the command to see another CPU's path). Usage: ``python
bench/exchange_trial.py`` (about two minutes on 2 cores).
"""

from __future__ import annotations

from pathlib import Path
import sys

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.exchange import exchanges
from hyst_id.io.recording import Recording

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))
from lag_cases import forced, mirror_of_24  # noqa: E402, I100
import blind_family  # noqa: E402, I100


def _said(text: str) -> None:
    if text.startswith('exchange:'):
        print('   ', text, flush=True)


def main() -> None:
    """Print the forced cases, then the two diagnoses."""
    for lag in ('sensor_lag', 'dead_time'):
        for chosen in ({'sensor_lag': 'dead_time', 'dead_time': 'sensor_lag'}[lag], lag):
            print(f'reference chain, static curve + {lag}; {chosen} forced in:', flush=True)
            made = exchanges(**forced(lag, chosen), say=_said)
            print(f'    exchanges made: {[(x.replaced, x.comparison.mechanism) for x in made]}')
    case = blind_family.draw(24)
    records = [('blind #24', Recording(case['t'], case['command'], case['measurement'],
                                       'position', source='blind #24')),
               ('its mirror (dead time)', mirror_of_24())]
    for name, rec in records:
        print(f'{name}:', flush=True)
        d = diagnose(rec, settings=DiagnoseSettings(), progress=_said)
        print(f'    findings {[f.mechanism for f in d.findings]}, final held-out '
              f'{d.final.er_holdout_percent / d.noise_floor_percent:.2f} x the floor; the '
              'first: ' + ', '.join(f'{k} {q.value:.4g} {q.unit}'
                                    for k, q in d.findings[0].params.items()), flush=True)


if __name__ == '__main__':
    main()
