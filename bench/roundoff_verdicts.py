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

"""How many of the suite's numeric claims change their verdict at round-off level.

Another CPU make sums in another order: every result differs in its last
bits, and a search whose path depends on them can end elsewhere. This script
imitates that: it runs the test suite once as it is and then ``--runs`` more
times with every recording perturbed at ``--size`` relative (default 1e-12,
``HYST_ID_ROUNDOFF_PROBE``, see :func:`hyst_id.io.recording.roundoff_probe`),
and prints

* every test whose outcome (passed / failed / skipped) differs between runs;
* for every figure a test records with pytest's ``record_property`` (the
  value a claim rests on, and its limit), the spread over the runs and the
  smallest margin to the limit.

Run from the repository root (about the suite's time per run)::

    python bench/roundoff_verdicts.py                       # 1 + 3 runs, ROS and lint off
    python bench/roundoff_verdicts.py --runs 2 -k diagnose  # a subset

The answer to aim for is none flipped, and no margin near zero.
"""

from __future__ import annotations

import argparse
from collections import defaultdict
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

ROOT = Path(__file__).resolve().parents[1]


def run_suite(probe: str, xml_path: Path, marker: str, keyword: str | None,
              workers: int = 2) -> int:
    """Run pytest with the probe setting; return its exit code."""
    env = dict(os.environ, HYST_ID_ROUNDOFF_PROBE=probe, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    cmd = [sys.executable, '-m', 'pytest', '-q', '-p', 'no:cacheprovider', '-m', marker,
           f'--junitxml={xml_path}', '-n', str(workers)]
    if keyword:
        cmd += ['-k', keyword]
    print(f'[roundoff] probe {probe or "off"}: {" ".join(cmd[3:])}', flush=True)
    return subprocess.call(cmd, cwd=ROOT, env=env, stdout=subprocess.DEVNULL)


def outcomes(xml_path: Path) -> tuple[dict[str, str], dict[str, dict[str, str]]]:
    """Outcome and recorded properties of every test case in a junit XML file."""
    result, props = {}, {}
    for case in ET.parse(xml_path).getroot().iter('testcase'):
        name = f'{case.get("classname")}::{case.get("name")}'
        state = 'passed'
        for tag in ('failure', 'error', 'skipped'):
            if case.find(tag) is not None:
                state = tag
        result[name] = state
        props[name] = {p.get('name'): p.get('value') for p in case.iter('property')}
    return result, props


def margins(runs: list[dict[str, dict[str, str]]]) -> list[tuple[str, str, list[float], str]]:
    """Recorded figures per test: name, values over the runs, and the limit if recorded."""
    out = []
    names = sorted({n for r in runs for n in r})
    for test in names:
        keys = sorted({k for r in runs for k in r.get(test, {}) if not k.endswith('_limit')})
        for key in keys:
            values = []
            for r in runs:
                try:
                    values.append(float(r.get(test, {}).get(key, 'nan')))
                except ValueError:
                    pass
            limit = next((r[test].get(key + '_limit') for r in runs
                          if r.get(test, {}).get(key + '_limit')), '')
            out.append((test, key, values, limit))
    return out


def main() -> int:
    """Run the suite unperturbed and perturbed; print flips and margins."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--runs', type=int, default=3, help='perturbed runs (seeds 1..runs)')
    ap.add_argument('--size', type=float, default=1e-12, help='relative perturbation size')
    ap.add_argument('-m', dest='marker', default='not ros and not lint',
                    help='pytest marker expression')
    ap.add_argument('-k', dest='keyword', default=None, help='pytest -k expression')
    ap.add_argument('--workers', type=int, default=2, help='pytest-xdist workers per run')
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix='hyst_id_roundoff_'))
    probes = [''] + [f'{k}:{args.size:g}' for k in range(1, args.runs + 1)]
    states: dict[str, list[str]] = defaultdict(list)
    props = []
    for i, probe in enumerate(probes):
        xml_path = tmp / f'run{i}.xml'
        run_suite(probe, xml_path, args.marker, args.keyword, args.workers)
        if not xml_path.exists():
            print(f'[roundoff] run {i} wrote no report', file=sys.stderr)
            return 1
        res, pr = outcomes(xml_path)
        for name in set(states) | set(res):
            states[name].append(res.get(name, 'absent'))
        props.append(pr)
    flipped = {n: s for n, s in states.items() if len(set(s)) > 1}
    failed = {n: s for n, s in states.items() if 'failure' in s or 'error' in s}
    print(f'\n{len(states)} tests, {len(probes)} runs (unperturbed, then probe seeds 1..'
          f'{args.runs} at {args.size:g}): {len(flipped)} changed their verdict, '
          f'{len(failed)} failed in some run')
    for name, s in sorted({**flipped, **failed}.items()):
        print(f'  {name}: {" ".join(s)}')
    rows = margins(props)
    if rows:
        print('\nrecorded figures (value per run; limit; worst relative margin to the limit):')
        for test, key, values, limit in rows:
            text = ' '.join(f'{v:.4g}' for v in values)
            note = ''
            op, _, bound = limit.partition(' ')
            if op in ('<', '<=', '>', '>=') and values:
                b = float(bound)
                below = op in ('<', '<=')
                worst = max(values) if below else min(values)
                margin = (b - worst) if below else (worst - b)
                note = f'; margin {margin / abs(b):+.1%}'
            print(f'  {test} {key}: {text}  (limit {limit or "-"}{note})')
    print(f'\nreports in {tmp}')
    return 1 if flipped else 0


if __name__ == '__main__':
    sys.exit(main())
