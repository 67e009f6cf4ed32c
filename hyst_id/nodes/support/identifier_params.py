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

"""The identifier node's parameter table (:mod:`hyst_id.nodes.identifier`)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable

from rclpy.validate_topic_name import InvalidServiceNameException, validate_topic_name

from hyst_id.diagnosis.mechanisms.registry import get_mechanisms, mechanism_ids
from hyst_id.errors import ConfigError
from hyst_id.identification.config import (
    check_domains_file, make_settings, MAX_GENERATIONS, MAX_HOPS, MAX_POP_SIZE, MAX_SEEDS)
from hyst_id.identification.result import IdentifySettings
from hyst_id.io.recording import CHANNELS
from hyst_id.nodes.support.params import field_params, Param, topic_params
from hyst_id.nodes.support.qos import IDENTIFIED_PARAMS_TOPIC
from hyst_id.nodes.support.sliding import SLIDING_PARAMS, SlidingLink

__all__ = ['PARAMS', 'default_params_out', 'identify_settings', 'validate_identifier_params']


def validate_identifier_params(values: dict[str, Any], changed: set[str]) -> str | None:
    """Why the identifier's parameter ``values`` cannot be taken, or None.

    Checked when set, not when a run has been collected: the domains (and a
    domains file's contents, against the channel's chain of the model's
    family), the diagnosis's mechanism ids, the compensator's node name (its
    service name must be valid), and the sliding re-identification's settings.
    """
    if values['min_samples'] > values['max_samples']:
        return (f'min_samples ({values["min_samples"]}) must not exceed max_samples '
                f'({values["max_samples"]}): the buffer could never hold enough to identify')
    dom = values['domains']
    if {'domains', 'model'} & changed and dom != 'auto' and values['model'] == 'auto':
        return "model 'auto' derives each family's domains from the data: domains must be auto"
    if {'domains', 'model'} & changed and dom == 'paper' and values['model'] != 'tk':
        return f"the 'paper' domains are for model 'tk', not {values['model']!r}"
    if {'domains', 'model'} & changed and dom not in ('auto', 'paper'):
        if not Path(dom).expanduser().is_file():
            return f"domains must be 'auto', 'paper' or an existing YAML file; got {dom!r}"
        try:
            check_domains_file(str(Path(dom).expanduser()), values['channel'], values['model'])
        except ConfigError as exc:
            return str(exc)
    if {'diagnose_mechanisms', 'channel'} & changed and values['diagnose_mechanisms'].strip():
        try:
            get_mechanisms(mechanism_ids(values['diagnose_mechanisms']), values['channel'])
        except ConfigError as exc:
            return f'diagnose_mechanisms: {exc}'
    node = values['compensator_node']
    if 'compensator_node' in changed and node:
        try:
            validate_topic_name(node.rstrip('/') + '/set_parameters_atomically',
                                is_service=True)
        except InvalidServiceNameException as exc:
            return (f'compensator_node {node!r} is not a valid node name: '
                    + str(exc).splitlines()[0])
    if any(n.startswith('sliding.') for n in changed):
        return SlidingLink.validate(values)
    return None


def identify_settings(p: Callable[[str], Any]) -> IdentifySettings:
    """Identify's settings from the node's parameters (``p(name)``), as the CLI builds them.

    Proper loops only (``--proper-loops``): the node's sets go to the compensator,
    which inverts proper loops only.
    """
    bound = p('er_bound_percent')
    return make_settings(
        seeds=p('seeds'), seed_offset=p('seed_offset'), pop_size=p('pop_size'),
        generations=p('generations'), c=p('c'), xi=p('xi'), workers=p('workers'),
        refine=p('refine'), restarts=p('restarts'),
        er_bound_percent=bound if bound > 0 else None, global_evals=p('global_evals'),
        global_runs=p('global_runs'), hops=p('hops'), more_starts=p('more_starts'),
        loose_loops=False)


def default_params_out() -> Path:
    """``$ROS_HOME/hyst_id/compensator.yaml`` (``ROS_HOME`` defaults to ``~/.ros``)."""
    home = os.environ.get('ROS_HOME') or os.path.join(os.path.expanduser('~'), '.ros')
    return Path(home) / 'hyst_id' / 'compensator.yaml'


PARAMS = [
    Param('channel', 'position', 'measured channel to identify', choices=CHANNELS,
          read_only=True),
    *topic_params(), *field_params(),
    Param('topics.stamp_source', 'header', "'header': measurement header stamps; 'log': "
          'source timestamps for everything (replays)', choices=('header', 'log'),
          read_only=True),
    Param('topics.identified_params_topic', IDENTIFIED_PARAMS_TOPIC,
          'latched identified parameters (std_msgs/String, JSON)', read_only=True),
    Param('topics.identified_typed_topic', '~/identified', 'latched identified parameters, '
          "typed (hyst_id_interfaces/msg/IdentifiedParams; '' = JSON only)", read_only=True),
    Param('measurement_reliable', False, 'subscribe to the measurement with reliable QoS '
          '(for replays; live sensors are best effort)', read_only=True),
    Param('collect', True, 'accumulate samples from the topics'),
    Param('min_samples', 50, 'fewest samples an identification starts with', low=20,
          high=100000000),
    Param('max_samples', 2000000, 'samples kept (oldest dropped)', low=100, high=100000000),
    Param('end_of_run_timeout_s', 2.0, 'identify when no measurement arrived for this long '
          '(0 = only on request)', low=0.0, high=86400.0, unit='s'),
    Param('identify_now', False, 'set true to identify the samples collected so far'),
    Param('clear_after_identify', True, 'start a new run after each identification'),
    Param('pop_size', 10, 'GAASS population size N_pop', low=2, high=MAX_POP_SIZE),
    Param('generations', 500, 'GAASS generations', low=1, high=MAX_GENERATIONS),
    Param('c', 0.007, 'GAASS search-space contraction rate (Eq. 15)', low=1e-9, high=100.0),
    Param('xi', 0.02, 'GAASS mutation subspace coefficient (Eq. 22)', low=1e-9, high=1.0),
    Param('seeds', 10, 'number of seeds (one GAASS run each)', low=1, high=MAX_SEEDS),
    Param('seed_offset', 0, 'first seed', low=0, high=2**31 - 1),
    Param('workers', 1, '1: seeds one after the other in a worker thread; 0: one worker '
          'process per core; n > 1: n processes', low=0, high=1024),
    Param('refine', True, 'polish each GAASS result with bounded least squares'),
    Param('restarts', 4, 'extra GAASS runs per seed while %e_r stays above 1.05 x the noise '
          'floor and they still gain (0 = one run per seed)', low=0, high=1000),
    Param('er_bound_percent', 0.0, 'stop a GAASS run once %e_r is below this (0 = never)',
          low=0.0, high=1000.0, unit='%'),
    Param('global_evals', 200000, 'evaluations of each global-phase run while the best fit '
          'stays above 1.1 x the noise floor (0 = no global phase)', low=0, high=100000000),
    Param('global_runs', 14, 'most runs of the global phase (0 = none)', low=0, high=1000),
    Param('hops', 100, 'when the best seed ends between 1.1 and 4 x the noise floor, the most '
          'jumps of basin hopping from it (0 = none)', low=0, high=MAX_HOPS),
    Param('more_starts', False, 'when the chains built from the data stop above the noise '
          'floor, five more ways of sharing the loop width between H and the backlash '
          '(identify --more-starts: finds narrow basins, costs time)'),
    Param('domains', 'auto', "search domains: 'auto' (from the data), 'paper', or a YAML "
          'file of name: [low, high]'),
    Param('model', 'tk', "H's family: 'tk' (the paper's piecewise-linear loop), 'smooth' "
          "(Prandtl-Ishlinskii, curved branches) or 'auto' (fit both on the first 70 % of the "
          'run, keep the lower held-out error)', choices=('tk', 'smooth', 'auto')),
    Param('params_out', '', 'compensator params file written after each identification '
          "('' = $ROS_HOME/hyst_id/compensator.yaml)", read_only=True),
    Param('recover_on_start', True, 'republish the parameter set found in params_out at '
          'start (restart recovery)', read_only=True),
    Param('compensator_node', 'compensator', 'node whose set_parameters_atomically service '
          "receives the parameters ('' = do not push)"),
    Param('gate_max_floor_ratio', 3.0, 'quality gate: hand no set over (params_out, '
          'compensator_node, compensator_params) whose %e_r exceeds this multiple of the '
          'noise floor (0 = no limit)', low=0.0, high=1e6),
    Param('gate_max_uncertainty', 1.0, 'quality gate: hand no set over in which a '
          "parameter's uncertainty (seed spread or standard error) exceeds this fraction of "
          'its scale (0 = no limit)', low=0.0, high=1e6),
    Param('input_timeout_s', 5.0, 'report ERROR when commands arrive but no measurement has '
          'for this long (and the reverse)', low=0.1, high=86400.0, unit='s'),
    Param('push_timeout_s', 5.0, 'how long to wait for the compensator service', low=0.0,
          high=3600.0, unit='s'),
    Param('cancel_now', False, 'set true to cancel the running identification (the last '
          'published parameters stay)'),
    Param('diagnose_now', False, 'set true to diagnose the samples collected so far (else the '
          'last identified run)'),
    Param('diagnose_seeds', 2, 'GAASS seeds of the diagnosis baseline fit', low=1, high=1000),
    Param('diagnose_generations', 200, 'GAASS generations of the diagnosis baseline fit',
          low=1, high=MAX_GENERATIONS),
    Param('diagnose_train_fraction', 0.7, 'share of the run the diagnosis fits on (the rest is '
          'held out)', low=0.1, high=0.95),
    Param('diagnose_hops', 100, "most jumps of basin hopping in the diagnosis baseline's "
          'identifications (20: about 40 % faster when the chain lacks physics)', low=0,
          high=MAX_HOPS),
    Param('diagnose_more_starts', False, "identify's more_starts in the diagnosis baseline's "
          'identifications (diagnose --more-starts; off: a claim that gains little is '
          'challenged by such a search anyway)'),
    Param('diagnose_mechanisms', '', "comma-separated mechanism ids to test ('' = the whole "
          'library)'),
    *SLIDING_PARAMS,
]
