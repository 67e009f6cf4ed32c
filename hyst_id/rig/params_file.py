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

"""Rig parameters in YAML files: ROS 2 params files or plain groups.

:func:`load_rig_params` reads ``params/pipeline.yaml`` (a ROS params file,
``node: ros__parameters: groups``) or a plain document of groups, dotted keys
allowed; :func:`save_rig_params` writes the ROS layout back;
:func:`as_rig_params` takes whatever a caller has (parameters, a mapping, a
path or nothing).
"""

from __future__ import annotations

import difflib
import functools
from pathlib import Path
from typing import Any, Mapping

import yaml

from hyst_id.errors import ConfigError
from hyst_id.io.params_file import read_yaml
from hyst_id.rig.params import (
    _merge,
    _unflatten,
    RIG_GROUPS,
    rig_params_from_dict,
    rig_params_to_dict,
    RigParams,
)

__all__ = ['DEFAULT_NODE', 'as_rig_params', 'load_rig_params', 'NODE_SCALARS', 'save_rig_params']

#: Node section written by :func:`save_rig_params`.
DEFAULT_NODE = 'pipeline_sim'

#: Groups of node parameters a ROS params file may hold beside the rig's.
NODE_GROUPS = ('topics', 'qos_overrides')

#: The pipeline_sim node's own parameters, which its params section may hold beside the rig's
#: groups (``test_nodes_unit.py`` checks the list against the node's), and ROS's.
NODE_SCALARS = frozenset({
    'plant', 'rig_params_file', 'tau_s', 'zeta', 'omega_n', 'pressure_offset_pa',
    'pressure_gain_pa', 'flow_offset_g_s', 'flow_gain_g_s', 'position_noise_std',
    'pressure_noise_pa', 'flow_noise_g_s', 'seed', 'publish_position', 'time_scale', 'step_s',
    'joint_name', 'm_l', 'm_r', 'm_t', 'm_b', 'c_l', 'c_r', 'c_t', 'c_b', 'm_bl', 'c_bl',
    'c_br', 'use_sim_time'})


def load_rig_params(yaml_path: str | Path, *, node: str | None = None) -> RigParams:
    """Read rig parameters from a YAML file (ROS params file or plain groups).

    Parameters
    ----------
    yaml_path : str or pathlib.Path
        The file.
    node : str, optional
        In a ROS params file, the node section to read (default every
        section with ``ros__parameters``, ``/**`` first, later ones winning).

    Raises
    ------
    ConfigError
        Unreadable file, invalid YAML, unknown or invalid parameter.
    """
    path = Path(yaml_path)
    doc = read_yaml(path, 'rig params')
    return _with_path(lambda: _from_document(doc, node), path)


def _from_document(doc: Any, node: str | None = None) -> RigParams:
    """Parameters from a parsed YAML document (ROS params layout or plain groups)."""
    if doc is None:
        doc = {}
    if not isinstance(doc, Mapping):
        raise ConfigError('rig params must be a mapping')
    keys = [k for k in sorted(doc, key=lambda k: k != '/**')
            if isinstance(doc[k], Mapping) and 'ros__parameters' in doc[k]]
    if not keys:
        return rig_params_from_dict(doc)
    if node is not None:
        keys = [k for k in keys if str(k).lstrip('/') == node.lstrip('/')]
        if not keys:
            raise ConfigError(f'no section {node}: ros__parameters')
    merged: dict = {}
    for section in (doc[k]['ros__parameters'] for k in keys):
        if not isinstance(section, Mapping):
            raise ConfigError('ros__parameters must be a mapping')
        _merge(merged, _unflatten(section))
    # a node's own parameters may share the section, but a group that is neither a rig
    # group nor a node's is a typo (``suply``) or another node's file: it was ignored
    strays = sorted(k for k, v in merged.items() if isinstance(v, Mapping)
                    and k not in RIG_GROUPS and k not in NODE_GROUPS)
    if strays:
        hints = [f'{k} (did you mean {close[0]}?)' if close else k for k, close in
                 ((k, difflib.get_close_matches(k, RIG_GROUPS, 1)) for k in strays)]
        raise ConfigError(f'unknown parameter group(s) {", ".join(hints)}; rig groups: '
                          f'{", ".join(RIG_GROUPS)}')
    # the rig's values are all in groups; a scalar beside them is the pipeline_sim node's
    # parameter or a typo (a review's foo: 1 and group-less actuator keys were ignored)
    scalars = sorted(str(k) for k, v in merged.items()
                     if not isinstance(v, Mapping) and k not in NODE_SCALARS)
    # the simple plant's values that a rig group also has (m_l, tau_s, zeta, ...): a rig
    # file's actuator.m_l without its group, unless the section says it is the simple plant's
    if merged.get('plant') != 'simple':
        shared = sorted(str(k) for k, v in merged.items() if not isinstance(v, Mapping)
                        and k in NODE_SCALARS and _group_hints([str(k)]))
        if shared:
            raise ConfigError(f'{", ".join(shared)}: the pipeline_sim node\'s simple plant reads '
                              f'{"these" if len(shared) > 1 else "it"} (plant: simple), the rig '
                              'does not' + _group_hints(shared))
    if scalars:
        raise ConfigError(f'{", ".join(scalars)}: neither rig parameters (a rig file holds them '
                          'in groups: ' + ', '.join(RIG_GROUPS) + ') nor the pipeline_sim '
                          "node's" + _group_hints(scalars))
    return rig_params_from_dict(merged, allow_unknown=True)


@functools.cache
def _rig_fields() -> frozenset[str]:
    """Every rig value as ``group.name``."""
    return frozenset(f'{g}.{k}' for g, values in rig_params_to_dict(RigParams()).items()
                     for k in values)


def _group_hints(keys: list[str]) -> str:
    """'; did you mean actuator.c_t?' for keys that are a field of some rig group."""
    hints = [m for k in keys for m in sorted(f for f in _rig_fields() if f.endswith(f'.{k}'))]
    return f'; did you mean {", ".join(hints[:4])}?' if hints else ''


def as_rig_params(params: Any = None) -> RigParams:
    """Coerce ``params`` to :class:`RigParams`.

    Parameters
    ----------
    params : RigParams, mapping, str, pathlib.Path or None
        ``None``: the defaults; a mapping: a parsed params document (ROS
        layout or plain groups, dotted keys allowed); a path: a YAML file.
    """
    if params is None:
        return RigParams()
    if isinstance(params, RigParams):
        return params
    if isinstance(params, (str, Path)):
        return load_rig_params(params)
    if isinstance(params, Mapping):
        return _from_document(params)
    raise ConfigError(f'rig params must be RigParams, a mapping or a path, got '
                      f'{type(params).__name__}')


def _with_path(build: Any, path: Path) -> RigParams:
    try:
        return build()
    except ConfigError as exc:
        raise ConfigError(f'{path}: {exc}') from None


def save_rig_params(params: RigParams, yaml_path: str | Path, *,
                    node: str = DEFAULT_NODE) -> Path:
    """Write ``params`` as a ROS 2 params file (``node: ros__parameters: groups``).

    Returns
    -------
    pathlib.Path
        The file written; :func:`load_rig_params` reads it back unchanged.
    """
    path = Path(yaml_path)
    body = {node: {'ros__parameters': rig_params_to_dict(params)}}
    text = ('# hyst_id rig simulator parameters (see docs/rig.md for units and sources).\n'
            + yaml.safe_dump(body, sort_keys=False, default_flow_style=False))
    try:
        path.write_text(text, encoding='utf-8')
    except OSError as exc:
        raise ConfigError(f'cannot write rig params {path}: {exc.strerror}') from None
    return path
