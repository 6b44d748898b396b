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
Bag destinations (io/bag.py): the default directory, and why a destination is refused.

The default directory of runs and of the node's recording is new and named
after the scenario; an empty destination is named as empty (not as ``'.'``,
which exists), and a folder on a read-only file system as read-only (not as a
permission problem).
"""

import errno
import os
from pathlib import Path
import tempfile

import pytest
from ttb_sim.cli import main
from ttb_sim.errors import ScenarioError
from ttb_sim.io.bag import check_destination, default_bag_path


def test_default_bag_path_is_new_and_named_after_the_scenario(tmp_path: Path, monkeypatch):
    monkeypatch.setattr('ttb_sim.io.bag.time.strftime', lambda fmt: '20260101-120000')
    first = default_bag_path('moving_force_beam', tmp_path)
    assert first.parent == tmp_path
    assert first.name == 'moving_force_beam-20260101-120000'
    assert not first.exists()
    first.mkdir()
    second = default_bag_path('moving_force_beam', tmp_path)
    assert second.name == 'moving_force_beam-20260101-120000-2' and not second.exists()


def test_an_empty_destination_is_named_empty(capsys, tmp_path: Path, monkeypatch):
    with pytest.raises(ScenarioError, match='output directory path is empty'):
        check_destination('', 'mcap')
    with pytest.raises(ScenarioError, match=r'path is empty \(give a folder to create with '
                                            r'bag\.path\)'):
        check_destination('', 'mcap', option='bag.path')
    monkeypatch.chdir(tmp_path)
    assert main(['run', 'moving_force_beam', '--out', '']) == 2
    err = capsys.readouterr().err
    assert 'output directory path is empty' in err and "'.'" not in err
    assert not list(tmp_path.iterdir())


def _read_only(*args: object, **kwargs: object) -> str:
    raise OSError(errno.EROFS, os.strerror(errno.EROFS))


def test_a_read_only_file_system_is_named_read_only(tmp_path: Path, monkeypatch):
    """access() says no on a read-only mount (to root too): the reason is the mount."""
    monkeypatch.setattr(tempfile, 'mkdtemp', _read_only)
    monkeypatch.setattr(os, 'access', lambda path, mode: False)
    with pytest.raises(ScenarioError, match=r'is not writable \(read-only file system\)'):
        check_destination(tmp_path / 'bag', 'mcap')
    monkeypatch.setattr(os, 'access', lambda path, mode: True)   # as root
    with pytest.raises(ScenarioError, match=r'is not writable \(read-only file system\)'):
        check_destination(tmp_path / 'a' / 'bag', 'sqlite3')


def test_no_permission_is_named_permission_denied(tmp_path: Path, monkeypatch):
    def denied(*args: object, **kwargs: object) -> str:
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES))
    monkeypatch.setattr(tempfile, 'mkdtemp', denied)
    with pytest.raises(ScenarioError, match=r'is not writable \(permission denied\)'):
        check_destination(tmp_path / 'bag', 'mcap')
