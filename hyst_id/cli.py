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

"""``hyst-id``: the command-line front end (no ROS needed).

Each subcommand lives in :mod:`hyst_id.commands` as a module with
``add_arguments(parser)`` and ``run(args) -> int``. Errors a user can cause
(:class:`hyst_id.errors.HystIdError`) end in one line on stderr and a
non-zero exit; anything else is reported as an internal error in one line
too (set ``HYST_ID_DEBUG=1`` for the traceback).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from hyst_id.errors import HystIdError
from hyst_id.pins import pin_numerics

pin_numerics()   # before any subcommand imports NumPy (docs/reproducibility.md)

__all__ = ['main', 'build_parser', 'COMMANDS']

#: Subcommand name -> (module under hyst_id.commands, one-line help).
COMMANDS = {
    'identify': ('identify', 'identify the chain of one channel from a recording'),
    'diagnose': ('diagnose', 'find, name and model what a recording has that the model lacks'),
    'simulate': ('simulate', 'simulate the pneumatic rig and write a recording'),
    'experiment': ('experiment', "reproduce the paper's section 4 experiment"),
    'fleet': ('fleet', 'identify (and diagnose) many recordings: a table, trends per valve'),
}


def build_parser() -> argparse.ArgumentParser:
    """Build the argument parser with every available subcommand."""
    parser = argparse.ArgumentParser(
        prog='hyst-id', description='Identify and compensate actuator hysteresis (GAASS).')
    sub = parser.add_subparsers(dest='command', metavar='COMMAND', required=True)
    for name, (module, help_text) in COMMANDS.items():
        try:
            mod = importlib.import_module(f'hyst_id.commands.{module}')
        except ModuleNotFoundError as exc:
            if exc.name != f'hyst_id.commands.{module}':
                raise
            continue
        p = sub.add_parser(name, help=help_text, description=help_text)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; return the process exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except HystIdError as exc:
        print(f'hyst-id: error: {exc}', file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print('hyst-id: interrupted', file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 - the CLI must never show a traceback
        if os.environ.get('HYST_ID_DEBUG'):
            raise
        first = str(exc).splitlines()[0] if str(exc) else ''
        print(f'hyst-id: internal error: {type(exc).__name__}: {first} '
              '(set HYST_ID_DEBUG=1 for the traceback)', file=sys.stderr)
        return 3


if __name__ == '__main__':
    sys.exit(main())
