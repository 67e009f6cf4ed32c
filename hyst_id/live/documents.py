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

"""What the identifier node publishes, built without ROS: documents and status rows.

:func:`compensator_set` (the set handed to the compensator),
:func:`result_document` (the latched JSON), :func:`recovered_document`
(after a restart), :func:`diagnosis_statuses` (``/diagnostics`` rows of a
diagnosis) and :func:`warm_up_kernels` (compile before the first sample).
"""

from __future__ import annotations

import datetime
from typing import Any

import numpy as np

from hyst_id.compensation import InverseModel
from hyst_id.compensation.params_file import compensator_names
from hyst_id.diagnosis.blocked_cv import confirmed
from hyst_id.errors import InvalidParametersError
from hyst_id.identification import Identification
from hyst_id.identification.chains import chain_spec
from hyst_id.live.gate import QualityGate

__all__ = ['compensator_set', 'diagnosis_statuses', 'recovered_document', 'result_document',
           'warm_up_kernels']


def compensator_set(ident: Identification) -> tuple[dict | None, float, str]:
    """The parameter set to hand to the compensator, its %e_r, and a note.

    The best run's canonical set with its ``output_sign``. Canonical sets
    of feasible results are always valid compensator models (validation is
    gauge invariant, :func:`hyst_id.models.tk.loop_is_proper`); the
    check is kept as a guard: a set the compensator would refuse gives
    ``(None, nan, reason)`` and nothing is handed over.
    """
    best = dict(ident.params, output_sign=float(getattr(ident, 'output_sign', 1.0)),
                family=ident.family)
    try:
        InverseModel.from_mapping(best)
    except InvalidParametersError as exc:
        if not getattr(ident, 'proper', True):   # callers pass stand-ins without it
            return None, float('nan'), (
                f'the identified loop is not proper ({exc}): the compensator has no exact '
                'inverse of it; nothing is handed to the compensator')
        return None, float('nan'), (
            f'the identified set is not a valid compensator model ({exc}); nothing is handed '
            'to the compensator (please report this: canonical sets should always be valid)')
    return best, float(ident.er_percent), ''


def result_document(ident: Identification, n_samples: int, duration_s: float,
                    notes: tuple[str, ...] | list[str] = (),
                    gate: QualityGate | None = None) -> dict:
    """JSON-ready summary published on the identified-parameters topic.

    ``params`` and ``er_percent`` are the identification's (as ``hyst-id
    identify`` reports them); ``compensator_params`` / ``compensator_er_percent``
    are the set the compensator should use (see :func:`compensator_set`),
    ``null`` when ``gate`` holds it back (``gate.reasons`` says why);
    ``warnings`` and ``poorly_determined`` are the identification's;
    ``notes`` say what was sorted, dropped or missing in the samples.
    """
    comp, comp_er, note = compensator_set(ident)
    gate = gate or QualityGate(max_floor_ratio=0.0, max_uncertainty=0.0)
    reasons = gate.reasons(ident)
    if reasons and comp is not None:
        comp, comp_er = None, float('nan')
        note = 'held back by the quality gate: ' + '; '.join(reasons)
    return {
        'gate': gate.to_dict(reasons),
        'warnings': list(getattr(ident, 'warnings', ()) or ()),
        'poorly_determined': {k: (float(v) if np.isfinite(v) else None) for k, v in
                              (getattr(ident, 'poorly_determined', None) or {}).items()},
        'compensator_params': comp, 'compensator_er_percent': comp_er,
        'compensator_note': note,
        'channel': ident.channel, 'family': ident.family, 'params': ident.params,
        'er_percent': ident.er_percent,
        'output_sign': float(getattr(ident, 'output_sign', 1.0)),
        'params_mean': ident.params_mean,
        'er_mean_params_percent': ident.er_mean_params_percent,
        'noise_floor_percent': ident.noise_floor_percent,
        'er_seeds_percent': [r.er_percent for r in ident.runs],
        'seeds': [r.seed for r in ident.runs], 'n_samples': int(n_samples),
        'duration_s': float(duration_s), 'domain_source': ident.domain_source,
        'settings': ident.to_dict()['settings'], 'source': ident.source,
        'notes': list(notes),
        'identified_at': datetime.datetime.now(datetime.timezone.utc).isoformat(),
    }


def recovered_document(values: dict, path: Any) -> dict:
    """The result document of a params file (``read_compensator_params`` values).

    What the identifier republishes after a restart: the set of its last
    result, as both ``params`` and ``compensator_params``.
    """
    family = str(values.get('family', 'tk'))
    params: dict[str, Any] = {n: float(values[n])
                              for n in compensator_names(family) + ('output_sign',)}
    params['family'] = family
    return {'channel': values['channel'], 'family': family, 'params': params,
            'compensator_params': params,
            'output_sign': params['output_sign'], 'er_percent': values['er_percent'],
            'compensator_er_percent': values['er_percent'], 'compensator_note': '',
            'notes': [], 'source': f'recovered from {path}'}


def warm_up_kernels(channel: str) -> None:
    """Compile (or load from cache) the numba kernels of ``channel``'s chain."""
    spec = chain_spec(channel)
    t = np.arange(8) * 0.1
    v = np.array([1.0, 2.0, 3.0, 2.0, 1.0, 2.0, 3.0, 2.0])
    x = np.array([[1.01, 1.05, 0.1, 0.15, -0.25, 0.5, 14.0, 7.0, 1.0, -0.2, 0.2, 1.0, 1.0,
                   1.0][:spec.n_params]])
    spec.cost_function(t, v, v)(x)
    spec.signal(x[0], t, v)


def diagnosis_statuses(doc: dict) -> list[tuple[int, str, str, dict[str, Any]]]:
    """One ``(level, name, message, values)`` per finding of a diagnosis document.

    ``doc`` is :meth:`hyst_id.diagnosis.Diagnosis.to_dict`. A finding gives
    level 1 (WARN: the model lacks a mechanism) named after its mechanism,
    its explanation as message and, as values, the mechanism, its place in
    the chain, the held-out and training %e_r before and after adding it,
    its parameters (``name: value unit``) and how the block is compensated
    (``compensation``: kind, ``compensation_how``: words) and the blocks that
    explain it nearly as well (``judgement_call``), its blocked cross-validation
    (``blocked_cv``; ``confirmed: false`` and the message says so when it does
    not hold the block up). No finding gives one level 0
    status with the verdict, the held-out %e_r and the noise floor.
    """
    out = []
    for f in doc.get('findings') or []:
        values: dict[str, Any] = {'mechanism': f.get('mechanism', '?'),
                                  'title': f.get('title', ''),
                                  'placement': f.get('placement', '')}
        for key in ('er_holdout_before_percent', 'er_holdout_after_percent',
                    'er_train_before_percent', 'er_train_after_percent', 'delta_bic'):
            if f.get(key) is not None:
                values[key] = float(f[key])
        for name, q in (f.get('params') or {}).items():
            if isinstance(q, dict):
                value = q.get('value')
                text = 'nan' if value is None else f'{float(value):.6g}'
                values[f'param.{name}'] = (text + f' {q.get("unit", "")}').strip()
            else:
                values[f'param.{name}'] = str(q)
        comp = f.get('compensation') or {}
        if comp:
            values['compensation'] = str(comp.get('kind', ''))
            values['compensation_how'] = str(comp.get('how', ''))
        close = [a['mechanism'] for a in f.get('alternatives') or ()
                 if isinstance(a, dict)
                 and a.get('kind') in ('close', 'signature', 'hold', 'split')]
        if close:       # the data barely prefer this block
            values['judgement_call'] = ', '.join(close)
        message = str(f.get('explanation') or f.get('title') or f.get('mechanism', ''))
        cv = f.get('blocked_cv') or {}
        if cv:          # blocked cross-validation: time blocks better / worse with the block
            values['blocked_cv'] = (f"better in {cv.get('better')}, worse in "
                                    f"{cv.get('worse')} of {cv.get('blocks')} time blocks")
            if not confirmed(cv):
                values['confirmed'] = 'false'
                message = 'not confirmed across time blocks (stated, not claimed): ' + message
        out.append((1, str(f.get('mechanism', '?')), message, values))
    if not out:
        base = doc.get('baseline') or {}
        er = base.get('er_holdout_percent')
        floor = doc.get('noise_floor_percent')
        values = {'verdict': doc.get('verdict', 'none')}
        if er is not None:
            values['er_holdout_percent'] = float(er)
        if floor is not None:
            values['noise_floor_percent'] = float(floor)
        out.append((0, 'none', f'no missing mechanism found (verdict {values["verdict"]}'
                    + (f', held-out %e_r {er:.4g}' if er is not None else '')
                    + (f', noise floor {floor:.4g}' if floor is not None else '') + ')',
                    values))
    return out
