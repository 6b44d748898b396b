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
The README as a user guide: short, the two set-up commands first, links that resolve.

CI (``.ci/run``) runs the README's test command verbatim, and builds the
documentation site (``mkdocs build --strict``), which checks every link and
anchor; the link check here needs no mkdocs and covers the relative file links
as GitHub resolves them.
"""

from pathlib import Path
import re

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / 'README.md'
MAX_BYTES = 15_000
RUN = 'python3 -m venv .venv && .venv/bin/pip install . && .venv/bin/ttb-sim run'
TEST = ("python3 -m venv .venv && .venv/bin/pip install '.[test]' "
        '&& .venv/bin/python -m pytest test -q')
VENV = 'python3 -m venv .venv && '
LINK = re.compile(r'\]\(([^)#\s]+)(#[^)\s]*)?\)')


def _lines() -> list[str]:
    return README.read_text(encoding='utf-8').splitlines()


def test_readme_is_at_most_15_kb():
    size = README.stat().st_size
    assert size <= MAX_BYTES, f'README.md is {size} bytes; move detail into docs/'


def test_readme_starts_with_exactly_the_two_set_up_commands():
    lines = [line for line in _lines() if line.strip()]
    assert lines[0].startswith('# '), lines[0]
    assert lines[1] == '```bash', lines[1]
    assert lines[2:5] == [RUN, TEST, '```'], lines[2:5]


def test_ci_runs_the_readme_test_command_verbatim():
    ci = (ROOT / '.ci' / 'run').read_text(encoding='utf-8').splitlines()
    # .ci/run makes the fresh venv itself, then runs the rest of the command as written.
    assert TEST.startswith(VENV)
    assert TEST[len(VENV):] in ci


def test_relative_links_of_readme_and_docs_resolve():
    pages = [README, *sorted((ROOT / 'docs').rglob('*.md'))]
    broken = []
    for page in pages:
        for target, _ in LINK.findall(page.read_text(encoding='utf-8')):
            if re.match(r'[a-z]+:', target):
                continue
            path = (page.parent / target).resolve()
            if not path.exists() or not path.is_relative_to(ROOT):
                broken.append(f'{page.relative_to(ROOT)}: {target}')
    assert not broken, broken
