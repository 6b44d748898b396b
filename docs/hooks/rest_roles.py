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
Griffe extension for the API pages: Sphinx roles in docstrings shown as code.

The docstrings name objects with Sphinx roles (``:class:`Frame```,
``:func:`~ttb_sim.fe.compiled.jit```). mkdocstrings renders docstrings as
Markdown, where the role would stay as text; this extension turns each role
into inline code (the last name only where the target starts with ``~``, as
Sphinx shows it). The docstrings in the package are not changed.
"""

import re

from griffe import Extension

_ROLE = re.compile(r':(?:py:)?(?:mod|func|class|meth|attr|data|const|exc|obj):`(~?)([^`]+)`')


def _code(match):
    tilde, target = match.groups()
    return f'`{target.rsplit(".", 1)[-1] if tilde else target}`'


class RestRoles(Extension):
    """Replace Sphinx roles by inline code in every docstring griffe loads."""

    def on_instance(self, *, obj, **kwargs):
        """Rewrite the docstring of one object."""
        if obj.docstring is not None:
            obj.docstring.value = _ROLE.sub(_code, obj.docstring.value)
