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

"""Turn result objects into what ``json.dumps`` takes: one converter for every document."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ['jsonable']


def jsonable(obj: Any) -> Any:
    """A JSON-ready copy of ``obj``.

    Mappings and sequences are converted item by item, NumPy scalars and
    arrays to Python numbers and lists, non-finite floats to ``None`` (JSON
    has no NaN), and objects with a ``to_dict()`` method through it.
    """
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if hasattr(obj, 'to_dict') and callable(obj.to_dict):
        return jsonable(obj.to_dict())
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, (np.floating, float)):
        x = float(obj)
        return x if np.isfinite(x) else None
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    return obj
