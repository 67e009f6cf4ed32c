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

"""Where the commands' outputs go: one rule for a figure path, folders made with one error."""

from __future__ import annotations

from pathlib import Path

from hyst_id.errors import ConfigError

__all__ = ['IMAGE_SUFFIXES', 'make_output_folder', 'names_folder', 'same_file']

#: Suffixes of a figure file (what matplotlib writes); another suffix is a folder's name.
IMAGE_SUFFIXES = frozenset({'.png', '.svg', '.pdf', '.jpg', '.jpeg', '.eps'})


def same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` are one file (a hard or symbolic link is another name for it)."""
    try:
        return a.is_file() and b.is_file() and a.samefile(b)
    except OSError:
        return False


def names_folder(path: str | Path) -> bool:
    """``--plot FILE|DIR``: True when ``path`` names a folder, not a figure file.

    An existing folder, or a name without a figure's suffix (``out``,
    ``run.2``); ``loops.png`` names a file.
    """
    path = Path(path)
    return path.is_dir() or path.suffix.lower() not in IMAGE_SUFFIXES


def make_output_folder(folder: Path, flag: str, value: str) -> None:
    """Make ``folder`` and its parents for the output ``flag value``.

    Raises
    ------
    ConfigError
        ``folder`` or a parent is a file, or the folder cannot be made.
    """
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise ConfigError(f'{flag} {value}: {folder} is a file, not a folder') from None
    except OSError as exc:
        raise ConfigError(f'{flag} {value}: cannot make the folder {folder}: '
                          f'{exc.strerror}') from None
