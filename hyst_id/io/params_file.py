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

"""Read a YAML file (a ROS 2 params file, a domains file, rig params) with one-line errors."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from hyst_id.errors import ConfigError

__all__ = ['read_yaml']


class _UniqueKeyLoader(yaml.SafeLoader):
    """PyYAML's safe loader refusing a key given twice in one mapping (it kept the last)."""

    def construct_mapping(self, node: Any, deep: bool = False) -> Any:
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if isinstance(key, (str, int, float, bool)) and key in seen:
                raise yaml.constructor.ConstructorError(
                    None, None, f'the key {key!r} is given twice (the first would be '
                    'ignored)', key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


def read_yaml(path: str | Path, what: str = '') -> Any:
    """Parsed YAML document of a file, or a one-line ConfigError.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.
    what : str
        What the file holds, for the message (``'rig params'``).
    """
    path = Path(path)
    name = f'{what} {path}' if what else str(path)
    try:
        return yaml.load(path.read_text(encoding='utf-8'), Loader=_UniqueKeyLoader)  # noqa: S506
    except FileNotFoundError:
        raise ConfigError(f'cannot read {name}: no such file') from None
    except OSError as exc:
        raise ConfigError(f'cannot read {name}: {exc.strerror or exc}') from None
    except yaml.YAMLError as exc:
        raise ConfigError(f'{name} is not valid YAML: {" ".join(str(exc).split())}') from None
