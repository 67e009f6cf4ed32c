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

"""Where the test suite's time goes, from a pytest junit XML.

``./run test --junitxml=results/suite.xml`` then
``python bench/suite_time.py [results/suite.xml] [--top 30] [--files 25]``

Prints the number of tests (passed, skipped, failed), the test-seconds summed
over every test (setup, call and teardown: what the two workers share, so the
run's wall time is about half of it plus the install), the seconds per test
module and the slowest tests. CI allows 30 minutes; ``docs/CONVENTIONS.md``
says how the thorough tier keeps the default run inside it.
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path
import sys
import xml.etree.ElementTree as ET

ROOT = Path(__file__).resolve().parents[1]
#: Where ``./run test --junitxml=results/suite.xml`` writes the times (``./run`` works in
#: the repository root).
DEFAULT_XML = ROOT / 'results' / 'suite.xml'


def read_times(path: Path) -> list[tuple[float, str, str, str]]:
    """``(seconds, module, test, status)`` per test case; passed, skipped or failed."""
    rows = []
    for case in ET.parse(path).getroot().iter('testcase'):
        if case.find('failure') is not None or case.find('error') is not None:
            status = 'failed'
        elif case.find('skipped') is not None:
            status = 'skipped'
        else:
            status = 'passed'
        rows.append((float(case.get('time', 0.0)), case.get('classname', ''),
                     case.get('name', ''), status))
    return rows


def main(argv: list[str] | None = None) -> int:
    """Print the suite's test-seconds, per module and the slowest tests."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('xml', type=Path, nargs='?',
                        help='junit XML written by pytest --junitxml (default '
                             'results/suite.xml)')
    parser.add_argument('--top', type=int, default=30, help='slowest tests shown (30)')
    parser.add_argument('--files', type=int, default=25, help='slowest modules shown (25)')
    args = parser.parse_args(argv)
    if args.xml is None:
        if not DEFAULT_XML.is_file():   # as ./run bench runs it: nothing measured yet
            print(f'no {DEFAULT_XML}: ./run test --junitxml=results/suite.xml writes it')
            return 0
        args.xml = DEFAULT_XML
    try:
        rows = read_times(args.xml)
    except (OSError, ET.ParseError) as exc:
        print(f'error: cannot read {args.xml}: {exc}', file=sys.stderr)
        return 2
    counts = Counter(status for *_, status in rows)
    total_s = sum(r[0] for r in rows)
    print(f'{len(rows)} tests: {counts["passed"]} passed, {counts["skipped"]} skipped, '
          f'{counts["failed"]} failed; {total_s:.0f} test-seconds '
          f'(about {total_s / 2 / 60:.1f} min on two workers)')
    per_module = Counter()
    for seconds, module, *_ in rows:
        per_module[module] += seconds
    print('\nseconds  module')
    for module, seconds in per_module.most_common(args.files):
        print(f'{seconds:7.1f}  {module}')
    print('\nseconds  test')
    for seconds, module, name, status in sorted(rows, reverse=True)[:args.top]:
        flag = '' if status == 'passed' else f'  ({status})'
        print(f'{seconds:7.1f}  {module}::{name}{flag}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
