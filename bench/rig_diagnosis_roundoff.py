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

"""How the diagnosis of the paper rig's identification run moves with round-off (issue 17).

The unregulated paper rig's Eq. 24 identification run (what ``hyst-id
experiment`` column (b) diagnoses) is diagnosed once per round-off probe
(``HYST_ID_ROUNDOFF_PROBE``: 0 = none, 1-3 perturb the recording's last
bits as another CPU's sums would); each line prints the verdict, the
findings, the final held-out %e_r, each finding's alternatives (tied or
close calls) and the first round's drift blocks with their judged held-out
%e_r; then the final held-out error over the noise floor and, per later
round, how ``static_nonlinearity`` fitted there. A verdict that changes
between probes is a tie the data do not decide, or a fit that lands in a
different optimum.

With ``--augmented`` each probe runs ``hyst-id experiment``'s column (b)
instead (:func:`hyst_id.experiment.run.run_experiment` on the one channel,
two GAASS seeds: (b) depends on the diagnosis only) and prints the verdict,
the findings and what they became in the compensator, (a)'s and (b)'s %ε_c
and the desired values' distance from the reference: how far (b)'s figure
moves with the verdict; and column (c), (b)'s compensator with tracking.
More lines say where (b) and (c) miss: their mean error against the
reference per fifth of the reference level, the share of (b)'s
commands at the upper command limit (a level the plant cannot give), and, with an output
map (``static_nonlinearity``), the share of the run's model targets past the
travel the map was fitted on (``|z| > 1``, where it continues straight).

With ``--supply`` each probe instead sets the drift blocks against the rig
itself: how much of the supply's excess over ambient (``p_s - p_amb``, the
rig's noise-free internal signal) is lost over the run, and what each drift
block (``offset_drift``, ``gain_drift``, ``supply_decay``), fitted alone,
makes of it: its training and held-out %e_r and its fitted change over the
run. A block whose training fit is as good as another's but whose held-out
part is far worse has fitted the drift's shape, not its size.

Usage: ``python bench/rig_diagnosis_roundoff.py [--channel pressure] [--probes 0 1 2 3]
[--augmented | --supply]`` (about a minute per probe; two with ``--supply``).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

ONE = """
import numpy as np
from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.rig import as_rig_params, simulate_rig
from hyst_id.signals.excitation import eq24
rig = as_rig_params('params/paper_rig.yaml').with_values({'supply.regulation': False})
t = np.arange(0.0, 100.0, 0.05)
run = simulate_rig(rig, t, eq24(t), seed=0)
d = diagnose(run.recording(%r), settings=DiagnoseSettings(max_mechanisms=3))
first = {c['mechanism']: round(c['er_judged_percent'], 4)
         for c in d.to_dict()['tested'][0]['candidates']
         if c['mechanism'] in ('offset_drift', 'gain_drift', 'supply_decay')}
print(d.verdict, [f.mechanism for f in d.findings], round(d.final.er_holdout_percent, 4),
      [[f"{a['mechanism']} ({a.get('kind', 'tied')})" for a in f.alternatives]
       for f in d.findings], 'round 1 drift blocks (judged held-out %%e_r):', first)
print('    final held-out %%.2f x the noise floor' %% (
      d.final.er_holdout_percent / d.noise_floor_percent))
for k, rnd in enumerate(d.to_dict()['tested'][1:], start=2):
    for c in rnd['candidates']:
        if c['mechanism'] == 'static_nonlinearity':
            print(f"    round {k} static_nonlinearity: held-out %%e_r "
                  f"{c['er_judged_percent']:.4g}, training {c['er_train_percent']:.4g}, "
                  f"dBIC {c['delta_bic']:.0f}, {c['status']}")
"""

AUGMENTED = """
import numpy as np
import hyst_id.experiment.columns as columns
from hyst_id.diagnosis.export import compensator_set
from hyst_id.experiment.run import run_experiment
seen = {}
plain = columns.adaptive_columns
loop = columns.closed_loop_tracking
def tracked(*a, **kw):
    out = loop(*a, **kw)
    seen['tracker'] = out[1].tracker
    return out
columns.closed_loop_tracking = tracked
def kept(diagnosis, result, rig, t_s, *rest, desired_augmented=None, **kw):
    seen.update(diagnosis=diagnosis, t_s=t_s, desired=desired_augmented)
    return plain(diagnosis, result, rig, t_s, *rest, desired_augmented=desired_augmented, **kw)
columns.adaptive_columns = kept
res = run_experiment('params/paper_rig.yaml', seeds=2, modes=('gaass',), channels=(%r,),
                     adaptive=True)
sc = res.scenarios['off']
r = sc.channels[('gaass', %r)]
a = r.adaptive
print(a.verdict, [m for m, _ in a.applied], '(a) %%.3g (b) %%.3g (c) %%.3g' %% (
      r.eps_c_percent, a.eps_c_augmented_percent, a.eps_c_tracking_percent),
      'desired value vs reference (a) / (b) %%.3g / %%.3g' %% a.floor_percent, a.augmentation)
ref = sc.reference.truth[{'position': 'position_clean', 'pressure': 'pressure_clean_pa',
                          'flow': 'flow_clean_g_s'}[%r]]
err = a.w_augmented - ref
fifth = np.minimum((5 * np.argsort(np.argsort(ref))) // ref.size, 4)
print('    (b) minus reference by fifth of the reference level, low to high (mean):',
      ' '.join(f'{err[fifth == k].mean():.3g}' for k in range(5)))
top = a.command_augmented_ma >= res.config.command_limits_ma[1] - 1e-9
err_c = a.w_tracking - ref
print('    (c) minus reference by fifth of the reference level, low to high (mean):',
      ' '.join(f'{err_c[fifth == k].mean():.3g}' for k in range(5)),
      f'(tracked gain at the end {a.tracking_gain:.4g})')
for e in seen['tracker'].events:
    if e.reason.startswith('correction'):
        print(f'    (c) at {e.t_s:.1f} s: {e.reason} (gain {e.gain:.3g}, offset {e.offset:.4g})')
print('    (b) commands at the upper limit, per fifth of the level:',
      ' '.join(f'{np.mean(top[fifth == k]):.0%%}' for k in range(5)))
_, aug, _ = compensator_set(seen['diagnosis'])
if aug.has_output_map:
    t = seen['t_s']
    z = np.array([aug.model_target(float(d), float(s - t[0]))
                  for d, s in zip(seen['desired'], t)])
    print(f'    output map: targets past the fitted travel |z| > 1: {np.mean(abs(z) > 1):.0%%}, '
          f'z {z.min():.3g} .. {z.max():.3g}')
"""

SUPPLY = """
import numpy as np
from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.rig import as_rig_params, simulate_rig
from hyst_id.signals.excitation import eq24
rig = as_rig_params('params/paper_rig.yaml').with_values({'supply.regulation': False})
t = np.arange(0.0, 100.0, 0.05)
run = simulate_rig(rig, t, eq24(t), seed=0)
print('drift blocks fitted alone')
excess = run.truth['supply_pressure_pa'] - rig.gas.ambient_pressure_pa
print(f'    the rig: supply excess over ambient {excess[0]:.4g} -> {excess[-1]:.4g} Pa, '
      f'{100 * (1 - excess[-1] / excess[0]):.1f} %% lost over the run')
for m in ('offset_drift', 'gain_drift', 'supply_decay'):
    d = diagnose(run.recording(%r), settings=DiagnoseSettings(max_mechanisms=1, mechanisms=(m,)))
    c = d.to_dict()['tested'][0]['candidates'][0]
    f = ({k: v['value'] for k, v in d.to_dict()['findings'][0]['params'].items()}
         if d.findings else {})
    size = {'offset_drift': f"offset {f.get('drift_over_record', np.nan):.4g} Pa",
            'gain_drift': f"gain +{f.get('gain_growth_percent', np.nan):.3g} %%",
            'supply_decay': f"gain -{f.get('gain_loss_percent', np.nan):.3g} %%, "
                            f"time constant {f.get('time_constant_s', np.nan):.3g} s"}[m]
    print(f'    {m} alone: %%e_r train {c["er_train_percent"]:.3g}, held-out '
          f'{c["er_holdout_percent"]:.3g} ({c["status"]}); over the run: {size}')
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--channel', default='pressure', choices=('position', 'pressure', 'flow'))
    ap.add_argument('--probes', type=int, nargs='+', default=[0, 1, 2, 3])
    how = ap.add_mutually_exclusive_group()
    how.add_argument('--augmented', action='store_true',
                     help='column (b) of hyst-id experiment per probe, not the diagnosis alone')
    how.add_argument('--supply', action='store_true',
                     help="the drift blocks fitted alone against the rig's supply loss")
    args = ap.parse_args()
    code = (AUGMENTED % ((args.channel,) * 3) if args.augmented
            else SUPPLY % args.channel if args.supply else ONE % args.channel)
    for probe in args.probes:
        env = dict(os.environ, HYST_ID_ROUNDOFF_PROBE=str(probe))
        if probe == 0:
            env.pop('HYST_ID_ROUNDOFF_PROBE')
        out = subprocess.run([sys.executable, '-c', code], env=env,
                             capture_output=True, text=True, check=False)
        lines = out.stdout.strip().splitlines()
        first = [j for j, line in enumerate(lines) if not line.startswith('    ')]
        text = '\n'.join(lines[first[-1]:]) if first else out.stderr[-300:]
        print(f'probe {probe}: {text}', flush=True)


if __name__ == '__main__':
    main()
