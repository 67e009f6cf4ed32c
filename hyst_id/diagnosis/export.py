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

"""A diagnosis's final model as the compensator's set: H, B and the in-line corrections.

The diagnosis refits the whole chain with every accepted block, so its H and
B hold for the plant *without* what the blocks describe: a gain schedule is
then referred to the record's start (``gain_reference`` 1, offset reference
0 s), not to the average a plain identification absorbs. The chain is
written in the recording's command units and the canonical gauge
(:mod:`hyst_id.identification.gauge`) with the calibration at the record's
start, which is what :class:`hyst_id.compensation.InverseModel` holds.

A static nonlinearity is a cubic of the travel normalised to [-1, 1] over the
record (``z``): H and B are then written with ``z`` as their output, and the
cubic goes into the augmentation as its output map. Each family maps its set
out of the diagnosis's normalised command frame
(:meth:`~hyst_id.models.family.HysteresisFamily.map_input`); a family without
that map, or another quantity-stage block, raises
:class:`~hyst_id.errors.InvalidParametersError` and the caller keeps an
identified set with :func:`hyst_id.compensation.augment.augmentation_from_findings`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hyst_id.compensation.augment import Augmentation, augmentation_from_findings
from hyst_id.compensation.inverse import InverseModel
from hyst_id.diagnosis.result import Diagnosis
from hyst_id.errors import InvalidParametersError
from hyst_id.identification.gauge import canonical_gauge, output_sign

__all__ = ['compensator_set']


def compensator_set(d: Diagnosis) -> tuple[InverseModel, Augmentation, list[tuple[str, str]]]:
    """H and B of the diagnosis's final model with the findings' in-line corrections.

    Returns
    -------
    model : InverseModel
        Canonical set in the recording's command and measurement units.
    augmentation : Augmentation
        The corrections, schedules referred to the record's start.
    applied : list of (mechanism, words)
        What each finding became in the compensator.

    Raises
    ------
    InvalidParametersError
        The final chain cannot be written as a compensator set (see the module docstring).
    """
    fit = d.final
    model = fit.model
    if model is None:
        raise InvalidParametersError('the diagnosis holds no fitted model')
    # a block with terms of its own only (friction) leaves the map of the travel alone
    quantity = [m.id for m in model.mechanisms if m.stage == 'quantity' and m.maps_travel]
    if quantity and quantity != ['static_nonlinearity']:
        raise InvalidParametersError(f'{", ".join(quantity)} cannot be written as an output '
                                     'map of the compensator')
    fam = model.spec.family
    nh = fam.n_params
    x = np.array(fit.p[:nh + 3], dtype=float)     # a copy: the diagnosis keeps its own
    scale = tuple(d.extra.get('command_scale', (1.0, 0.0)))
    if scale != (1.0, 0.0):
        try:
            x[:nh] = fam.map_input(x[:nh], float(scale[0]), float(scale[1]))
        except NotImplementedError:
            raise InvalidParametersError(f'family {fam.id!r} cannot be mapped out of the '
                                         "diagnosis's normalised command") from None
    if quantity:               # H and B output the normalised travel z
        lo, hi = fit.span
        calibration = (2.0 / (hi - lo), -(hi + lo) / (hi - lo))
    else:
        k = float(fit.coef[fit.labels.index('sensor')])
        if not np.isfinite(k) or k == 0.0:
            raise InvalidParametersError('the final model has no calibration gain')
        calibration = (k, float(fit.offset_at_start))
    canon = canonical_gauge(x, calibration, fam)
    inverse = InverseModel.from_vector(canon, output_sign(calibration), fam.id)
    aug, applied = augmentation_from_findings(d.findings, float(d.t_s[-1] - d.t_s[0]),
                                              model_from='diagnosis')
    if quantity and not aug.has_output_map:
        raise InvalidParametersError('the fitted static curve is not monotone over the '
                                     'travel: no inverse')
    return inverse, replace(aug, gain_reference=1.0, offset_reference_s=0.0), applied
