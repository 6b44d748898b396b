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
The ament style rules, enforced with PyPI tools where ament is not installed.

flake8 with the ament_flake8 plugin set (setup.cfg holds the configuration),
pydocstyle with the ament convention, and the Apache-2.0 copyright header.
"""

from pathlib import Path
import subprocess
import sys

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCES = sorted(p for d in ('ttb_sim', 'test', 'launch') for p in (ROOT / d).rglob('*.py'))
SOURCES.append(ROOT / 'setup.py')


def _tool(module: str) -> None:
    pytest.importorskip(module, reason=f'{module} is not installed (pip install .[test])')


@pytest.mark.linter
def test_flake8():
    _tool('flake8')
    result = subprocess.run([sys.executable, '-m', 'flake8', *map(str, SOURCES)], cwd=ROOT,
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.linter
def test_pydocstyle_ament_convention():
    _tool('pydocstyle')
    result = subprocess.run([sys.executable, '-m', 'pydocstyle', *map(str, SOURCES)],
                            cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.linter
def test_copyright_headers():
    missing = [str(p.relative_to(ROOT)) for p in SOURCES
               if not p.read_text(encoding='utf-8').startswith('# Copyright 20')
               or 'Licensed under the Apache License, Version 2.0' not in p.read_text()]
    assert not missing, missing
