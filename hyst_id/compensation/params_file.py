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

"""ROS 2 params files holding an identified compensator parameter set (any H family).

:func:`write_compensator_params` writes what ``--ros-args --params-file``
accepts for the compensator node, in any namespace (``/**``, so that
``-r __ns:=/valve1`` keeps the set)::

    /**:
      ros__parameters:
        channel: position
        family: tk
        m_l: 1.01
        ...
        c_br: 0.27
        output_sign: 1.0
        er_percent: 2.38
        augment:              # optional: in-line corrections from a diagnosis
          dead_time_s: 0.5
          ...

``family`` names H's family (:mod:`hyst_id.models.registry`; a file
without it holds the paper's ``tk`` loop) and the names that follow are
that family's. ``output_sign`` is the canonical calibration sign (-1 for a sensor that
falls as the actuator output rises); a file without it means +1. ``augment``
holds the in-line corrections of :class:`hyst_id.compensation.augment.Augmentation`
(``hyst-id diagnose --params-out``); ROS reads them as ``augment.<field>``.

Every number is written as a YAML float (``1.0``, never ``1``; ``.nan`` for
a missing value) because ROS refuses an integer for a double parameter. The
file is written to a temporary name and renamed, so a reader (the
identifier recovering after a restart) never sees half a file.
:func:`read_compensator_params` reads it back.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
import tempfile
from typing import Any, Mapping

import yaml

from hyst_id.compensation.augment import AUGMENT_PREFIX, Augmentation
from hyst_id.errors import ConfigError, InvalidParametersError
from hyst_id.io.params_file import read_yaml
from hyst_id.models.backlash import BACKLASH_NAMES
from hyst_id.models.registry import DEFAULT_FAMILY, FAMILIES, get_family

__all__ = ['COMPENSATOR_NAMES', 'ALL_MODEL_NAMES', 'NODE_COMMAND_LIMITS', 'command_limits_for',
           'compensator_names', 'compensator_values', 'read_compensator_params',
           'read_set_document', 'write_compensator_params']

#: The compensator node's default ``min_command`` / ``max_command`` (the paper's 4-20 mA).
NODE_COMMAND_LIMITS = (4.0, 20.0)


#: The node's bounds on any command parameter.
_NODE_COMMAND_BOUND = 1e6


def command_limits_for(command: Any) -> tuple[float, float, float] | None:
    """Command limits for a params file: the recording's range when it leaves the node's defaults.

    None when every command of the recording lies within
    :data:`NODE_COMMAND_LIMITS` (the defaults fit, nothing is written);
    else ``(lowest, highest, first)`` command of the recording, the range the
    set was identified on and where it started (an actuator driven in volts or
    mm, not mA, would otherwise have its commands clamped to 4-20 and start
    at 9), within the node's bounds of +-1e6.
    """
    import numpy as np
    arr = np.clip(np.asarray(command, dtype=float), -_NODE_COMMAND_BOUND, _NODE_COMMAND_BOUND)
    lo, hi = float(np.min(arr)), float(np.max(arr))
    if NODE_COMMAND_LIMITS[0] <= lo and hi <= NODE_COMMAND_LIMITS[1]:
        return None
    return lo, hi, float(arr[0])


def compensator_names(family: str | None = None) -> tuple[str, ...]:
    """Model parameters of a compensator set: H's (per family), then the backlash's."""
    return tuple(get_family(family).names) + BACKLASH_NAMES


#: Model parameters of the paper's ``tk`` set (hysteresis 8, backlash 3), in order.
COMPENSATOR_NAMES = compensator_names(DEFAULT_FAMILY)
#: Every model parameter of every registered family (what the compensator node declares).
ALL_MODEL_NAMES = tuple(dict.fromkeys(n for f in FAMILIES for n in compensator_names(f)))


def _float(value: Any, name: str) -> float:
    if isinstance(value, bool):
        raise ConfigError(f'{name} must be a number, got {value!r}')
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ConfigError(f'{name} must be a number, got {value!r}') from None


def compensator_values(identification_or_dict: Any) -> dict[str, Any]:
    """Return ``{channel, family, H's names, m_bl ... c_br, output_sign, er_percent}``.

    Parameters
    ----------
    identification_or_dict : Identification or mapping
        An :class:`~hyst_id.identification.Identification` (its best canonical
        parameters are used), or a mapping with ``channel``, ``er_percent``
        and the parameters either flat or under ``params`` (the layout of
        ``Identification.to_dict()`` and of the identifier's JSON message).

    Raises
    ------
    ConfigError
        A parameter is missing or not a number.
    """
    obj = identification_or_dict
    if hasattr(obj, 'params') and hasattr(obj, 'channel') and not isinstance(obj, Mapping):
        params, channel = obj.params, obj.channel
        er = getattr(obj, 'er_percent', math.nan)
        sign = getattr(obj, 'output_sign', 1.0)
        family = getattr(obj, 'family', DEFAULT_FAMILY)
    elif isinstance(obj, Mapping):
        params = obj.get('params', obj)
        if not isinstance(params, Mapping):
            raise ConfigError('params must be a mapping of parameter names to numbers')
        channel = obj.get('channel', params.get('channel', 'position'))
        er = obj.get('er_percent', params.get('er_percent', math.nan))
        sign = obj.get('output_sign', params.get('output_sign', 1.0))
        family = obj.get('family', params.get('family', DEFAULT_FAMILY))
    else:
        raise ConfigError(f'cannot take compensator parameters from {type(obj).__name__}')
    names = compensator_names(str(family))
    missing = [n for n in names if n not in params]
    if missing:
        raise ConfigError(f'missing compensator parameters: {", ".join(missing)} (family '
                          f'{family})')
    out: dict[str, Any] = {'channel': str(channel), 'family': str(family)}
    for name in names:
        out[name] = _float(params[name], name)
    out['output_sign'] = _float(sign, 'output_sign')
    if out['output_sign'] not in (1.0, -1.0):
        raise ConfigError(f'output_sign must be 1.0 or -1.0, got {sign!r}')
    out['er_percent'] = math.nan if er is None else _float(er, 'er_percent')
    aug = _augment_values(obj, params)
    if aug:
        out.update(aug)
    return out


def _augment_values(*sources: Any) -> dict[str, Any]:
    """``augment.*`` values from nested ``augment:`` mappings or dotted keys, validated."""
    flat: dict[str, Any] = {}
    for src in sources:
        if not isinstance(src, Mapping):
            aug = getattr(src, 'augmentation', None)
            flat.update(aug.as_mapping() if isinstance(aug, Augmentation) else {})
            continue
        nested = src.get('augment')
        if isinstance(nested, Mapping):
            flat.update({AUGMENT_PREFIX + str(k): v for k, v in nested.items()})
        elif isinstance(nested, Augmentation):
            flat.update(nested.as_mapping())
        flat.update({k: v for k, v in src.items() if str(k).startswith(AUGMENT_PREFIX)})
    if not flat:
        return {}
    known = set(Augmentation().as_mapping())
    unknown = sorted(set(flat) - known)
    if unknown:
        raise ConfigError(f'unknown in-line corrections: {", ".join(unknown)} (known: '
                          f'{", ".join(sorted(k[len(AUGMENT_PREFIX):] for k in known))})')
    try:
        return Augmentation.from_mapping(flat).as_mapping()
    except InvalidParametersError as exc:
        raise ConfigError(str(exc)) from None


def write_compensator_params(identification_or_dict: Any, path: str | Path,
                             node_name: str = '/**',
                             command_limits: tuple[float, ...] | None = None) -> Path:
    """Write a ROS 2 params file for the compensator node.

    Parameters
    ----------
    identification_or_dict : Identification or mapping
        See :func:`compensator_values`.
    path : str or pathlib.Path
        File to write (parent directories are created).
    node_name : str
        Node name the section is keyed by: ``/**`` (default) for any node in
        any namespace, ``/**/compensator`` for nodes of that name only.
    command_limits : (float, float) or (float, float, float), optional
        Written as the node's ``min_command``, ``max_command`` and, when given,
        ``initial_command`` (:func:`command_limits_for`); None: the node's
        defaults hold.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ConfigError
        Bad values, or the file cannot be written.
    """
    values = compensator_values(identification_or_dict)
    if not node_name or not isinstance(node_name, str):
        raise ConfigError('node_name must be a non-empty string')
    path = Path(path)
    lines = [f'# Compensator parameters identified by hyst_id (channel {values["channel"]}).',
             '# Use: ros2 run hyst_id compensator --ros-args --params-file THIS_FILE',
             f'{node_name}:', '  ros__parameters:',
             f'    channel: {yaml.safe_dump(values["channel"]).splitlines()[0]}',
             f'    family: {values["family"]}']
    for name in compensator_names(values['family']) + ('output_sign', 'er_percent'):
        lines.append(f'    {name}: {_yaml_float(values[name])}')
    if command_limits is not None:
        values_in = [float(x) for x in command_limits]
        if len(values_in) not in (2, 3):
            raise ConfigError('command limits are (min, max) or (min, max, first command), '
                              f'got {len(values_in)} values')
        lo, hi, *first = values_in
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi
                and all(lo <= v <= hi for v in first)):
            raise ConfigError('command limits need finite min < max (and a first command '
                              f'between), got {command_limits}')
        lines += ["    # the recording's command range (the node's default is 4-20)",
                  f'    min_command: {_yaml_float(lo)}', f'    max_command: {_yaml_float(hi)}']
        lines += [f'    initial_command: {_yaml_float(v)}' for v in first]
    aug = {k[len(AUGMENT_PREFIX):]: v for k, v in values.items() if k.startswith(AUGMENT_PREFIX)}
    if aug:
        lines.append('    augment:')
        for name, v in aug.items():
            # a stop at infinity is written .nan: the node reads .nan as no stop
            text = v if isinstance(v, str) else _yaml_float(
                math.nan if math.isinf(v) and name.endswith('_command') else v)
            lines.append(f'      {name}: {text}')
    text = '\n'.join(lines) + '\n'
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f'.{path.name}.', dir=str(path.parent))
        with os.fdopen(fd, 'w', encoding='utf-8') as fh:
            fh.write(text)
        os.replace(tmp, path)
    except OSError as exc:
        raise ConfigError(f'cannot write {path}: {exc.strerror or exc}') from None
    return path


def _yaml_float(value: float) -> str:
    if math.isnan(value):
        return '.nan'
    if math.isinf(value):
        return '.inf' if value > 0 else '-.inf'
    return repr(float(value))


def read_compensator_params(path: str | Path, node_name: str | None = None) -> dict[str, Any]:
    """Read ``{channel, family, H's names, m_bl ... c_br, output_sign, er_percent}`` from a file.

    Parameters
    ----------
    path : str or pathlib.Path
        A file written by :func:`write_compensator_params` (or by hand).
    node_name : str, optional
        Section to read; default ``compensator``, else ``/**``, else the
        only section of the file.

    Raises
    ------
    ConfigError
        Missing or unreadable file, invalid YAML, missing or non-numeric
        parameters.
    """
    path = Path(path)
    doc = read_yaml(path)
    if not isinstance(doc, dict):
        raise ConfigError(f'{path}: expected "<node>: ros__parameters:" sections')
    sections = {str(k).strip('/') or '/': v for k, v in doc.items()
                if isinstance(v, dict) and 'ros__parameters' in v}
    keys = [node_name.strip('/')] if node_name else ['compensator', '**']
    section = next((sections[k] for k in keys if k in sections), None)
    if section is None and node_name is None and len(sections) == 1:
        section = next(iter(sections.values()))
    if section is None:
        raise ConfigError(f'{path}: no ros__parameters section for '
                          f'{node_name or "compensator"}; sections: {sorted(sections)}')
    params = section['ros__parameters'] or {}
    if not isinstance(params, dict):
        raise ConfigError(f'{path}: ros__parameters must be a mapping')
    try:
        return compensator_values(params)
    except ConfigError as exc:
        raise ConfigError(f'{path}: {exc}') from None


def read_set_document(doc: Any, sensor_names: tuple[str, ...] = ()
                      ) -> tuple[str, dict[str, Any], float]:
    """The channel, the compensator's values and the %e_r of an identified-parameters document.

    The document is :func:`hyst_id.live.documents.result_document`'s
    (``compensator_params``), a bare set or one under ``params``; ``sensor_names``
    found in ``params`` come as ``tracking.<name>``.

    Raises
    ------
    ValueError
        What is wrong, in words: not an object, an unknown family, the names missing,
        a value that is not a number. An independent reviewer's malformed documents had
        been refused with a bare ``KeyError('m_l')``.
    """
    if not isinstance(doc, dict):
        raise ValueError(f'a JSON object was expected, got {type(doc).__name__}')
    params = doc.get('compensator_params') or doc.get('params', doc)
    if not isinstance(params, dict):
        raise ValueError(f'its parameters must be an object, got {type(params).__name__}')
    family = str(params.get('family', doc.get('family', DEFAULT_FAMILY)))
    if family not in FAMILIES:
        raise ValueError(f'unknown family {family!r} (known: {", ".join(FAMILIES)})')
    names = compensator_names(family)
    missing = [n for n in names if n not in params]
    if missing:
        raise ValueError(f'{", ".join(missing)} missing: a {family} set has '
                         f'{", ".join(names)}')

    def number(key: str, value: Any) -> float:
        try:
            return float(value)
        except (TypeError, ValueError):
            raise ValueError(f'{key} is {value!r}, not a number') from None
    values: dict[str, Any] = {n: number(n, params[n]) for n in names}
    values['family'] = family
    values['output_sign'] = number('output_sign', doc.get('output_sign',
                                                          params.get('output_sign', 1.0)))
    full = doc.get('params') if isinstance(doc.get('params'), dict) else {}
    values.update({f'tracking.{k}': number(k, full[k]) for k in sensor_names if k in full})
    er = number('er_percent', doc.get('compensator_er_percent', doc.get('er_percent', math.nan)))
    return str(doc.get('channel', params.get('channel', ''))), values, er
