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
MkDocs hook: the repository's README.md is the site's home page.

On GitHub the README sits at the repository root and links to ``docs/NAME.md``;
the site's pages are the files of ``docs/``. This hook adds README.md to the
site as ``index.md`` and rewrites its ``docs/`` links to the site's pages, and
the pages' links to the README (``../README.md``, ``../../README.md``) to the
home page. It also drops the backslash of an escaped pipe inside the code spans
of table rows: GitHub needs the escape there, Python-Markdown keeps code spans
whole and would show it. Nothing is copied or written into the repository.
"""

from pathlib import Path
import posixpath
import re

from mkdocs.structure.files import File

_README_LINK = re.compile(r'\]\((?:\.\./)+README\.md')
_DOCS_LINK = re.compile(r'\]\(docs/')
_CODE_SPAN = re.compile(r'`[^`]*`')


def on_files(files, config):
    """Add README.md as the home page ``index.md``."""
    readme = Path(config.config_file_path).parent / 'README.md'
    files.append(File.generated(config, 'index.md', abs_src_path=str(readme)))
    return files


def _table_pipes(markdown):
    lines, fenced = markdown.split('\n'), False
    for i, line in enumerate(lines):
        if line.lstrip().startswith('```'):
            fenced = not fenced
        elif not fenced and line.startswith('|'):
            lines[i] = _CODE_SPAN.sub(lambda m: m.group(0).replace('\\|', '|'), line)
    return '\n'.join(lines)


def on_page_markdown(markdown, page, config, files):
    """Point the README's ``docs/`` links, and the pages' README links, at the site's pages."""
    if page.file.src_uri == 'index.md':
        markdown = _DOCS_LINK.sub('](', markdown)
    else:
        home = posixpath.relpath('index.md', posixpath.dirname(page.file.src_uri) or '.')
        markdown = _README_LINK.sub(f']({home}', markdown)
    return _table_pipes(markdown)
