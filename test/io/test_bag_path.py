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

"""The default bag directory of runs and of the node's recording (io/bag.py)."""

from pathlib import Path

from ttb_sim.io.bag import default_bag_path


def test_default_bag_path_is_new_and_named_after_the_scenario(tmp_path: Path, monkeypatch):
    monkeypatch.setattr('ttb_sim.io.bag.time.strftime', lambda fmt: '20260101-120000')
    first = default_bag_path('moving_force_beam', tmp_path)
    assert first.parent == tmp_path
    assert first.name == 'moving_force_beam-20260101-120000'
    assert not first.exists()
    first.mkdir()
    second = default_bag_path('moving_force_beam', tmp_path)
    assert second.name == 'moving_force_beam-20260101-120000-2' and not second.exists()
