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

"""The ament linters (flake8, pep257, copyright) over the whole package."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TARGETS = [str(ROOT / p) for p in ('hyst_id', 'test', 'bench', 'setup.py')
           if (ROOT / p).exists()]
LICENSE_MARKERS = ('Copyright', 'Licensed under the Apache License, Version 2.0')


@pytest.mark.lint
def test_flake8():
    """ament_flake8 with the repository's own configuration (setup.cfg)."""
    ament_flake8 = pytest.importorskip('ament_flake8.main')
    rc, errors = ament_flake8.main_with_errors(
        argv=['--config', str(ROOT / 'setup.cfg'), *TARGETS])
    assert rc == 0, f'{len(errors)} flake8 errors:\n' + '\n'.join(map(str, errors[:40]))


@pytest.mark.lint
def test_pep257():
    """ament_pep257 with the numpy docstring convention."""
    ament_pep257 = pytest.importorskip('ament_pep257.main')
    rc = ament_pep257.main(argv=[*TARGETS, '--convention', 'numpy', '--add-ignore',
                                 'D100', 'D101', 'D102', 'D103', 'D104', 'D105', 'D106',
                                 'D107', 'D401'])
    assert rc == 0, 'pep257 docstring errors (see output above)'


@pytest.mark.lint
def test_copyright():
    """Every Python source carries the Apache-2.0 copyright header.

    Uses ament_copyright where installed (it is not on PyPI), else the same
    check on the header text.
    """
    try:
        from ament_copyright.main import main as copyright_main
    except ImportError:
        copyright_main = None
    if copyright_main is not None:
        assert copyright_main(argv=['--exclude', str(ROOT / '.venv'), *TARGETS]) == 0
        return
    missing = []
    for target in map(Path, TARGETS):
        files = [target] if target.is_file() else sorted(target.rglob('*.py'))
        for path in files:
            head = '\n'.join(path.read_text(encoding='utf-8').splitlines()[:15])
            if not all(marker in head for marker in LICENSE_MARKERS):
                missing.append(str(path.relative_to(ROOT)))
    assert not missing, 'files without the license header: ' + ', '.join(missing)
