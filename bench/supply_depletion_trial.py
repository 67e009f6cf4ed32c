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


"""A trial block for the unregulated rig: a gain driven by the cumulative opening (issue 17).

The physics column (b) of ``hyst-id experiment`` lacks on pressure is a supply that
empties with the flow the valve draws (docs/RESULTS.md). Before building it into
the library this script tries it as a block outside the package: the gain on the
sensed quantity is ``g = 1 - a t / T - b X(t)``, ``X`` the running integral of the
chain's (sensor-filtered) reading, standardised on the training part, so that
``b`` is the depletion by the opening and ``a`` soaks up the reading's unknown
zero (the integral of a constant is a ramp in time); ``y = g (k s + b0) + b1``
as the library's other gain blocks. It is fitted alone on the rig's Eq. 24
identification run (supply not regulated, noise seed 0), as
``rig_diagnosis_roundoff.py --supply`` fits the library's drift blocks, and
printed beside ``offset_drift``: the training and held-out %e_r and the fitted
``a``, ``b``, and the gain's change over the record.

A block that fits the training part better but the held-out part worse has the
shape and not the size of the drift: the pivot ``b0`` is free, as in
``gain_drift`` and ``supply_decay``, and one run does not pin it.

Usage: ``python bench/supply_depletion_trial.py [--channel pressure]`` (about 40 s).
"""

from __future__ import annotations

import argparse

import numpy as np

from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.mechanisms import registry
from hyst_id.diagnosis.mechanisms.base import Quantity
from hyst_id.diagnosis.mechanisms.time_gain import TimeGain
from hyst_id.rig import as_rig_params, simulate_rig
from hyst_id.signals.excitation import eq24


class OpeningDepletion(TimeGain):
    """The trial block: ``g = 1 - a t / T - b X(t)`` (not in the package's library)."""

    id = 'opening_depletion'  # noqa: A003
    names = ('a_time', 'b_opening')
    units = ('1', '1')
    channels = ('pressure', 'flow')

    def _gain(self, theta, t_s, reading, ctx):
        ref = reading[:min(ctx.n_train, reading.size)]
        d = max(ctx.train_duration_s, 1e-9)
        dt = np.diff(t_s, prepend=t_s[0])
        opening = np.cumsum((reading - ref.mean()) / (ref.std() + 1e-300) * dt) / d
        return np.maximum(1.0 - theta[0] * (t_s - ctx.t_s[0]) / d - theta[1] * opening, 1e-3)

    def bounds(self, ctx):
        """Each term at most 90 % over the training part."""
        return np.array([[-0.9, 0.9], [-0.9, 0.9]])

    def starts(self, ctx):
        """A 3 x 3 grid."""
        return [np.array([a, b]) for a in (-0.2, 0.0, 0.2) for b in (-0.2, 0.0, 0.2)]

    def null(self, ctx):
        """No change."""
        return np.zeros(2)

    def implausible(self, *args, **kwargs):
        """Every fit is judged by its held-out part only."""
        return ''

    def output(self, theta, t_s, columns, ctx):
        """The gain on the signal columns, and the gained offset."""
        g = self._gain(theta, t_s, columns[0], ctx)
        return [c * g for c in columns[:-1]] + [g, columns[-1]]

    def undo(self, *args, **kwargs):
        """Not undone (a trial)."""
        return None

    def describe(self, theta, coef, info, ctx):
        """The two terms."""
        return {'a_time': Quantity(float(theta[0]), '1'),
                'b_opening': Quantity(float(theta[1]), '1')}

    def correction(self, *args, **kwargs):
        """No compensator correction (a trial)."""
        return {}


def main() -> None:
    """Fit the trial block and ``offset_drift`` alone on the rig run; print both."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--channel', default='pressure', choices=('pressure', 'flow'))
    args = ap.parse_args()
    registry.MECHANISMS[OpeningDepletion.id] = OpeningDepletion()
    rig = as_rig_params('params/paper_rig.yaml').with_values({'supply.regulation': False})
    t = np.arange(0.0, 100.0, 0.05)
    run = simulate_rig(rig, t, eq24(t), seed=0)
    excess = run.truth['supply_pressure_pa'] - rig.gas.ambient_pressure_pa
    print(f'the rig: supply excess over ambient falls {100 * (1 - excess[-1] / excess[0]):.1f} '
          '% over the run')
    for mech in (OpeningDepletion.id, 'offset_drift'):
        d = diagnose(run.recording(args.channel),
                     settings=DiagnoseSettings(max_mechanisms=1, mechanisms=(mech,)))
        cand = d.to_dict()['tested'][0]['candidates'][0]
        line = (f'{mech} alone: %e_r train {cand["er_train_percent"]:.3g}, held-out '
                f'{cand["er_judged_percent"]:.3g} ({cand["status"]}; baseline held-out '
                f'{d.baseline.er_holdout_percent:.3g}, floor {d.noise_floor_percent:.3g})')
        if mech == OpeningDepletion.id and d.findings:
            model, p = d.final.model, d.final.p
            theta = model.theta(p, mech)
            ev = model.evaluate(p, d.t_s, (d.command - d.extra['command_scale'][1])
                                / d.extra['command_scale'][0], d.n_train)
            g = ev.columns[ev.labels.index(f'{mech}:0')]
            line += (f'; a {theta[0]:+.3g}, b {theta[1]:+.3g}: gain {g[0]:.3g} -> {g[-1]:.3g} '
                     f'({100 * (g[-1] / g[0] - 1):+.1f} % over the record)')
        print(line)


if __name__ == '__main__':
    main()
