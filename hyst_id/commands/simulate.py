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

"""``hyst-id simulate``: run the rig simulator and write one recording per channel.

Writes ``OUT_<channel>.csv`` (header ``t,command,measurement``; seconds, mA,
the channel's unit), a sidecar ``OUT.json`` with units, the excitation, seed
and the full rig parameters, optionally ``OUT_truth.csv`` (every internal
signal) and, with ``--bag DIR``, one rosbag2 MCAP per channel under ``DIR``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
import sys

import numpy as np
import yaml

from hyst_id.errors import ConfigError
from hyst_id.io.outputs import same_file
from hyst_id.io.recording import CHANNELS
from hyst_id.signals.excitation import EXCITATIONS, make_excitation

__all__ = ['add_arguments', 'run', 'output_paths', 'sample_times']


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the arguments of ``simulate``."""
    parser.add_argument('--params', metavar='YAML', default=None,
                        help='rig params file (default: built-in defaults = '
                        'params/pipeline.yaml)')
    parser.add_argument('--set', metavar='KEY=VALUE', action='append', default=[],
                        help='override a rig parameter by dotted name, e.g. '
                        'supply.regulation=false (repeatable)')
    parser.add_argument('--excitation', choices=tuple(EXCITATIONS), default='eq24',
                        help="command profile (default: eq24, the paper's)")
    parser.add_argument('--excitation-param', metavar='KEY=VALUE', action='append',
                        default=[], help='profile parameter, e.g. amplitude_ma=1.5 or '
                        'levels_ma=[8,10,9] (repeatable)')
    parser.add_argument('--duration', type=float, default=100.0, help='seconds (default 100)')
    parser.add_argument('--dt', type=float, default=0.05, help='sample time, s (default 0.05)')
    parser.add_argument('--jitter', type=float, default=0.0,
                        help='sampling jitter, fraction of dt in [0, 0.5) (default 0)')
    parser.add_argument('--seed', type=int, default=0, help='noise seed (default 0)')
    parser.add_argument('--channels', default=','.join(CHANNELS),
                        help='comma-separated channels to write (default all)')
    parser.add_argument('--out', required=True, metavar='OUT',
                        help='output stem: OUT_<channel>.csv and OUT.json')
    parser.add_argument('--truth', action='store_true',
                        help='also write OUT_truth.csv with every internal signal')
    parser.add_argument('--bag', metavar='DIR', default=None,
                        help='also write one rosbag2 MCAP per channel under DIR/<channel>')


def _number(value: object) -> object:
    """A string that is a number YAML 1.1 leaves a string (``2e-1``) as a float."""
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value
    return value


def _key_values(items: list[str], what: str, numbers: bool = False) -> dict:
    """``KEY=VALUE`` items as a dict; ``numbers``: every value a number or a list of them."""
    out = {}
    for item in items:
        key, sep, text = item.partition('=')
        if not sep or not key.strip():
            raise ConfigError(f'{what} needs KEY=VALUE, got {item!r}')
        try:
            value = yaml.safe_load(text)
            value = [_number(x) for x in value] if isinstance(value, list) else _number(value)
        except yaml.YAMLError:
            raise ConfigError(f'{what} {key}: cannot parse {text!r}') from None
        values = value if isinstance(value, list) else [value]
        if numbers and not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                               and np.isfinite(x) for x in values):
            raise ConfigError(f'{what} {key.strip()}: {text!r} is not a finite number (or a '
                              'list of them)')
        out[key.strip()] = value
    return out


#: Most samples ``simulate`` writes: a bound that refuses a typo (``--dt 1e-9``) rather
#: than being killed by the kernel for memory.
MAX_SAMPLES = 5 * 10 ** 6


def sample_times(duration_s: float, dt_s: float, jitter: float = 0.0,
                 seed: int = 0) -> np.ndarray:
    """Sample times ``0, dt, 2 dt, ... <= duration``, optionally jittered.

    Jitter moves every sample after the first by up to ``jitter * dt`` (uniform),
    drawn from its own stream so it never changes the sensor noise.
    """
    if not (np.isfinite(duration_s) and np.isfinite(dt_s) and dt_s > 0 and duration_s > dt_s):
        raise ConfigError(f'need 0 < --dt < --duration, got dt={dt_s}, duration={duration_s}')
    if not 0.0 <= jitter < 0.5:
        raise ConfigError(f'--jitter must be in [0, 0.5), got {jitter}')
    n = int(np.floor(duration_s / dt_s + 1e-9)) + 1
    if n > MAX_SAMPLES:
        raise ConfigError(f'--duration {duration_s:g} at --dt {dt_s:g} is {n:.3g} samples; at '
                          f'most {MAX_SAMPLES:.0e} (a longer --dt or a shorter run)')
    t = np.arange(n) * dt_s
    if jitter > 0:
        rng = np.random.default_rng([seed, 1])
        t[1:] += rng.uniform(-jitter, jitter, n - 1) * dt_s
    return t


def output_paths(out: str, channels: list[str]) -> dict[str, Path]:
    """Files written for stem ``out``: one CSV per channel, ``json``, ``truth``."""
    stem = out[:-4] if out.endswith('.csv') else out
    paths = {ch: Path(f'{stem}_{ch}.csv') for ch in channels}
    paths['json'] = Path(f'{stem}.json')
    paths['truth'] = Path(f'{stem}_truth.csv')
    return paths


def _write_csv(path: Path, header: list[str], columns: list[np.ndarray]) -> None:
    data = np.column_stack(columns)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savetxt(path, data, delimiter=',', header=','.join(header), comments='',
                   fmt='%.10g')
    except OSError as exc:
        raise ConfigError(f'cannot write {path}: {exc.strerror}') from None


def run(args: argparse.Namespace) -> int:
    """Simulate and write the files."""
    from hyst_id.rig import load_rig_params, RigParams, simulate_rig
    from hyst_id.rig.params import rig_params_to_dict

    channels = [c.strip() for c in args.channels.split(',') if c.strip()]
    bad = [c for c in channels if c not in CHANNELS]
    if bad or not channels:
        raise ConfigError(f'--channels must name some of {CHANNELS}, got {args.channels!r}')
    params = load_rig_params(args.params) if args.params else RigParams()
    if args.set:
        params = params.with_values(_key_values(args.set, '--set'))
    kw = _key_values(args.excitation_param, '--excitation-param', numbers=True)
    paths = output_paths(args.out, channels)
    if args.params and Path(args.params).is_file():     # OUT.json over a params file named so
        src = Path(args.params)
        for out in paths.values():
            if same_file(out, src):
                raise ConfigError(f'--out {args.out} would write {out}, the --params file; '
                                  'give another stem')
    if Path(args.out).is_dir():
        raise ConfigError(f'--out {args.out} is a folder; --out is a stem (OUT_<channel>.csv, '
                          f'OUT.json): give e.g. {Path(args.out) / "run"}')
    taken = [Path(args.bag) / ch for ch in channels if args.bag and (Path(args.bag) / ch).exists()]
    if taken:                       # refused before any file is written
        raise ConfigError(f'bag directory {taken[0]} already exists')
    t = sample_times(args.duration, args.dt, args.jitter, args.seed)
    command = np.asarray(make_excitation(args.excitation, t, **kw), dtype=float)
    if not np.all(np.isfinite(command)):
        raise ConfigError(f'--excitation {args.excitation} with {kw} gives non-finite commands')
    result = simulate_rig(params, t, command, seed=args.seed)
    units = {'t': 's', 'command': 'mA'}
    for ch in channels:
        _write_csv(paths[ch], ['t', 'command', 'measurement'],
                   [t, command, result.measurement(ch)])
        units[ch] = result.unit(ch)
        print(f'wrote {paths[ch]}', file=sys.stderr)
    if args.truth:
        from hyst_id.rig.simulator import TRUTH_FIELDS
        names = list(TRUTH_FIELDS)
        _write_csv(paths['truth'], ['t', 'command', *names],
                   [t, command, *(result.truth[k] for k in names)])
        print(f'wrote {paths["truth"]}', file=sys.stderr)
    sidecar = {
        'columns': ['t', 'command', 'measurement'],
        'units': units,
        'files': {ch: paths[ch].name for ch in channels},
        'truth_file': paths['truth'].name if args.truth else None,
        'truth_units': _truth_units() if args.truth else None,
        'excitation': {'name': args.excitation, 'params': kw},
        'duration_s': float(args.duration), 'dt_s': float(args.dt), 'jitter': args.jitter,
        'seed': args.seed, 'params_file': args.params, 'overrides': list(args.set),
        'effects_enabled': list(params.effects.enabled),
        'solver_failures': result.solver_failures,
        'rig_params': rig_params_to_dict(params),
    }
    try:
        paths['json'].write_text(json.dumps(sidecar, indent=2) + '\n', encoding='utf-8')
    except OSError as exc:
        raise ConfigError(f'cannot write {paths["json"]}: {exc.strerror}') from None
    print(f'wrote {paths["json"]}', file=sys.stderr)
    if args.bag:
        _write_bags(Path(args.bag), result, channels)
    return 0


def _truth_units() -> dict:
    from hyst_id.rig.simulator import TRUTH_FIELDS
    return {'t': 's', 'command': 'mA', **TRUTH_FIELDS}


def _write_bags(root: Path, result, channels: list[str]) -> None:
    try:
        from hyst_id.io.bag import write_recording_bag
    except ImportError as exc:
        raise ConfigError(f'--bag is unavailable: {exc}') from None
    for ch in channels:
        target = root / ch
        if target.exists():
            raise ConfigError(f'bag directory {target} already exists')
        target.parent.mkdir(parents=True, exist_ok=True)
        write_recording_bag(target, result.recording(ch))
        print(f'wrote {target}', file=sys.stderr)
