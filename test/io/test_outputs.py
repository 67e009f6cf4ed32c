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

"""Where outputs go: the figure-or-folder rule the commands and the diagnosis figure share."""

from __future__ import annotations

import pytest

from hyst_id.errors import ConfigError
from hyst_id.io.outputs import make_output_folder, names_folder


@pytest.mark.parametrize('name, folder', [('out', True), ('run.2', True), ('figs.d', True),
                                          ('loops.png', False), ('Loops.PNG', False),
                                          ('fig.svg', False), ('fig.pdf', False)])
def test_a_figure_suffix_names_a_file_anything_else_a_folder(tmp_path, name, folder):
    assert names_folder(tmp_path / name) is folder


def test_an_existing_folder_is_a_folder_whatever_its_name(tmp_path):
    (tmp_path / 'odd.png').mkdir()
    assert names_folder(tmp_path / 'odd.png')


def test_make_output_folder_refuses_a_path_under_a_file(tmp_path):
    (tmp_path / 'f').touch()
    with pytest.raises(ConfigError, match='is a file, not a folder'):
        make_output_folder(tmp_path / 'f' / 'sub', '--plot', 'f/sub')
    make_output_folder(tmp_path / 'a' / 'b', '--plot', 'a/b')
    assert (tmp_path / 'a' / 'b').is_dir()
