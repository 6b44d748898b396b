# Copyright 2026 The ttb_sim Authors
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

"""
A package face whose names are imported from their modules on first use (PEP 562).

``ttb_sim.config`` and ``ttb_sim.io`` export names from heavy modules (the
model records, the bag writer); a verb that refuses its input before it needs
them should not pay for their imports. Each package binds the module-level
``__getattr__`` and ``__dir__`` that :func:`lazy_face` returns.
"""

from __future__ import annotations

import importlib
import sys
from typing import Any, Callable, Mapping, Sequence

__all__ = ['lazy_face']


def lazy_face(package: str, face: Mapping[str, Sequence[str]]
              ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """
    Return (``__getattr__``, ``__dir__``) for the package ``package``.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    face : mapping of str to sequence of str
        Module name -> the names the package exports from it.

    """
    home = {name: module for module, names in face.items() for name in names}
    namespace = sys.modules[package].__dict__

    def getattr_(name: str) -> Any:
        if name not in home:
            raise AttributeError(f'module {package!r} has no attribute {name!r}')
        value = getattr(importlib.import_module(home[name]), name)
        namespace[name] = value
        return value

    def dir_() -> list[str]:
        return sorted(set(namespace) | set(home))

    getattr_.__doc__ = 'Import a name of the package face from its module on first use.'
    dir_.__doc__ = "List the module's names with the face's lazily imported ones."
    return getattr_, dir_
