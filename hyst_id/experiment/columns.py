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

"""Issue 17's columns: (b) the augmented model and (c) adaptive tracking on the rig.

Column (a) is the paper's procedure (:mod:`hyst_id.experiment.run`): the
H⁻¹ identified at the start, fixed. Here, per channel, from the same
identification run and with no simulator truth:

(b) **augmented**: :func:`hyst_id.diagnosis.diagnose` on the identification
    run's recording of the channel; the compensator gets the diagnosis's final
    model and the accepted blocks' in-line corrections
    (:func:`hyst_id.diagnosis.export.compensator_set`), or, where that
    model cannot be exported, the identified set with the corrections
    referred to the record's average (:func:`augmentation_from_findings`).
    The compensation run starts with the supply as the identification run
    did, so a schedule fitted from its start applies; where the diagnosis
    found a gain changing in time, the desired value comes from a position
    calibration fitted with that gain and referred to the run's start
    (:func:`~hyst_id.experiment.run.calibration_by_bic` with ``gain_law``; a
    static curve of degree 1-3 where the run shows one): the supply level the
    regulated reference holds.
(c) **tracking**: (b)'s augmented compensator and desired value in an
    :class:`~hyst_id.compensation.tracking.AdaptiveCompensator` (what the
    schedules leave of the plant's gain and offset, by recursive least
    squares, forgetting ``forget_time_s``; the prediction is the augmented
    model's), closed sample by sample around the rig simulator, as the node
    runs it. The sensor of the prediction is the identified chain's.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hyst_id.compensation import CommandLimits, Compensator, InverseModel
from hyst_id.compensation.augment import augmentation_from_findings, AugmentedCompensator
from hyst_id.compensation.tracking import (AdaptiveCompensator, GainOffsetTracker,
                                           SensorPredictor)
from hyst_id.diagnosis import diagnose, DiagnoseSettings
from hyst_id.diagnosis.export import compensator_set
from hyst_id.errors import InvalidParametersError
from hyst_id.experiment.result import eps_c_percent
from hyst_id.identification.chains import chain_spec
from hyst_id.rig import RigParams, simulate_rig
from hyst_id.rig.simulator import RigSimulator

__all__ = ['AdaptiveColumns', 'adaptive_columns', 'closed_loop_tracking', 'diagnose_channel']

#: Reading of each channel in a :class:`RigSimulator` step.
_READING = {'position': 'position', 'pressure': 'pressure_pa', 'flow': 'flow_g_s'}


@dataclass
class AdaptiveColumns:
    """Columns (b) and (c) of one channel (``eps_c`` as Eq. 26, position-equivalent)."""

    eps_c_augmented_percent: float
    eps_c_tracking_percent: float
    augmented_from: str                 # 'diagnosis' (final model) or 'identification'
    verdict: str
    applied: list = field(default_factory=list)     # [(mechanism, what it became)]
    augmentation: str = 'none'
    tracking_gain: float = float('nan')
    calibration: Any = None             # the calibration of (b)'s desired value
    #: %ε_c of a perfect compensator with (a)'s and (b)'s desired values: their own
    #: distance from the reference
    floor_percent: tuple = (float('nan'), float('nan'))
    command_augmented_ma: np.ndarray | None = field(default=None, repr=False)
    w_augmented: np.ndarray | None = field(default=None, repr=False)
    w_tracking: np.ndarray | None = field(default=None, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {'eps_c_augmented_percent': self.eps_c_augmented_percent,
                'eps_c_tracking_percent': self.eps_c_tracking_percent,
                'augmented_from': self.augmented_from, 'verdict': self.verdict,
                'applied': [{'mechanism': m, 'how': h} for m, h in self.applied],
                'augmentation': self.augmentation, 'tracking_gain': self.tracking_gain,
                'floor_percent': {'a': self.floor_percent[0], 'b': self.floor_percent[1]},
                'calibration': None if self.calibration is None else {
                    'k': self.calibration.k, 'b': self.calibration.b,
                    **self.calibration.dynamics,
                    'rms_residual': self.calibration.rms_residual,
                    'curve': None if not self.calibration.curve else {
                        'centre': self.calibration.curve[0],
                        'scale': self.calibration.curve[1],
                        'coefficients': list(self.calibration.curve[2])}}}


def diagnose_channel(recording: Any, settings: DiagnoseSettings) -> Any:
    """The diagnosis of one identification recording (what (b) compensates with)."""
    return diagnose(recording, settings=settings)


def closed_loop_tracking(rig: RigParams, t_s: np.ndarray, desired: np.ndarray,
                         x: np.ndarray, sign: float, channel: str, seed: int | None,
                         forget_time_s: float | None, limits: CommandLimits,
                         compensator: Compensator | AugmentedCompensator | None = None
                         ) -> tuple[np.ndarray, AdaptiveCompensator | None]:
    """Readings of the rig compensated sample by sample, with tracking when ``forget_time_s``.

    ``x`` is the identified canonical chain (its sensor parameters feed the
    tracker's prediction); the compensator is its H⁻¹ unless ``compensator``
    is given (column (c): (b)'s augmented one). Returns the readings and the
    adaptive compensator (``None`` without tracking).
    """
    comp = compensator if compensator is not None else Compensator(
        InverseModel.from_vector(x, sign), limits, v0=limits.min_command)
    adaptive = None
    if forget_time_s is not None:
        sensor = tuple(np.asarray(x)[chain_spec(channel).sensor_slice])
        adaptive = AdaptiveCompensator(comp, GainOffsetTracker(forget_time_s=forget_time_s),
                                       SensorPredictor.for_channel(channel, sensor))
    sim = RigSimulator(rig, seed=seed, t0_s=float(t_s[0]))
    out = np.empty(t_s.size)
    for k in range(t_s.size):
        dt = 0.0 if k == 0 else float(t_s[k] - t_s[k - 1])
        v = comp.step(float(desired[k])) if adaptive is None else \
            adaptive.step(float(desired[k]), float(t_s[k]))
        out[k] = getattr(sim.step(v, dt), _READING[channel])
        if adaptive is not None:
            adaptive.observe(out[k], float(t_s[k]), dt)
    return out, adaptive


def adaptive_columns(diagnosis: Any, result: Any, rig: RigParams, t_s: np.ndarray,
                     w_ud: np.ndarray, offset: float, limits: CommandLimits,
                     noise_seed: int | None, forget_time_s: float = 20.0,
                     desired_augmented: np.ndarray | None = None) -> AdaptiveColumns:
    """Columns (b) and (c) for one channel's :class:`~hyst_id.experiment.result.ChannelResult`.

    Parameters
    ----------
    diagnosis : Diagnosis
        Of the identification run's recording of the channel.
    result : ChannelResult
        Column (a): its identified set and desired value.
    rig : RigParams
        The rig of the scenario.
    t_s, w_ud : numpy.ndarray
        Compensation run times and the reference readings (Eq. 26).
    offset : float
        The calibration's ``b`` (%ε_c is measured from it).
    limits : CommandLimits
        Command limits of the compensator.
    noise_seed : int or None
        The rig's sensor-noise seed of the compensation run.
    forget_time_s : float
        Tracking's forgetting time.
    desired_augmented : numpy.ndarray, optional
        (b)'s desired value (default column (a)'s).
    """
    ch = result.channel
    try:
        model, aug, applied = compensator_set(diagnosis)
        source = 'diagnosis'
    except InvalidParametersError:
        model = InverseModel.from_vector(result.x_used, result.ident.output_sign,
                                         result.ident.family)
        aug, applied = augmentation_from_findings(
            diagnosis.findings, float(diagnosis.t_s[-1] - diagnosis.t_s[0]))
        source = 'identification'
    desired = result.desired if desired_augmented is None else desired_augmented
    command = AugmentedCompensator(model, aug, limits, v0=limits.min_command).run(desired, t_s)
    w_b = simulate_rig(rig, t_s, command, seed=noise_seed).measurement(ch)
    w_c, adaptive = closed_loop_tracking(
        rig, t_s, desired, result.x_used, result.ident.output_sign, ch, noise_seed,
        forget_time_s, limits,
        compensator=AugmentedCompensator(model, aug, limits, v0=limits.min_command))
    return AdaptiveColumns(
        eps_c_augmented_percent=eps_c_percent(w_b, w_ud, offset),
        eps_c_tracking_percent=eps_c_percent(w_c, w_ud, offset), augmented_from=source,
        verdict=diagnosis.verdict, applied=list(applied), augmentation=aug.describe(),
        tracking_gain=float(adaptive.tracker.gain), command_augmented_ma=command,
        w_augmented=w_b, w_tracking=w_c)
