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
Every built-in scenario runs as shipped, and the cross-key track rules refuse up front.

Each built-in is run through the command line unmodified except a short
``--duration`` (0.02 s: a handful of steps, enough to build the whole model and
write a readable bag). The refusals check that a wheel off the modelled rails,
a run longer than the track and an observer off its component give exit 2
naming the right key, before any model is built and with nothing written.
"""

from pathlib import Path

import pytest
from ttb_sim.cli import main
from ttb_sim.config import builtin_scenarios, load_scenario
from ttb_sim.errors import ScenarioError

SHIPPED = ('live_train', 'moving_force_beam', 'sprung_mass_beam', 'ten_span_train',
           'track_approach', 'paper_ttbi', 'paper_ttbcpsi')


def test_the_shipped_list_is_complete():
    assert set(SHIPPED) <= set(builtin_scenarios())


COARSE_SOIL = {'paper_ttbcpsi': ['soil.mesh.h=1.5', 'soil.mesh.h_max=5.0',
                                 'soil.mesh.h_shaft=3.0', 'soil.block.lx=30.0',
                                 'soil.block.ly=24.0']}
"""Built-ins run on a coarser soil mesh here: reducing the shipped one takes minutes (it is
cached on disk after its first build; test_reduction.py checks the reduction itself)."""


@pytest.mark.parametrize('name', sorted(builtin_scenarios()))
def test_every_builtin_runs_as_shipped(name: str, tmp_path: Path) -> None:
    out = tmp_path / name
    sets = [arg for key in COARSE_SOIL.get(name, []) for arg in ('--set', key)]
    assert main(['run', name, '--out', str(out), '--duration', '0.02', *sets]) == 0
    assert (out / 'metadata.yaml').is_file()
    assert (out / 'summary.json').is_file()


@pytest.mark.parametrize('name', sorted(builtin_scenarios()))
def test_every_builtin_loads_with_its_own_duration(name: str) -> None:
    load_scenario(name)  # the cross-key rules hold for the automatic duration too


def _refused(tmp_path: Path, capsys: pytest.CaptureFixture[str], *args: str) -> str:
    out = tmp_path / 'bag'
    assert main(['run', *args, '--out', str(out)]) == 2
    assert not out.exists()
    err = capsys.readouterr().err
    assert err.startswith('ttb-sim: error: ') and err.count('\n') == 1
    return err


def test_axles_starting_off_the_track_name_the_start_position(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    err = _refused(tmp_path, capsys, 'track_approach', '--set', 'train.start_position=-40')
    assert 'train.start_position = -40 m' in err
    assert 'x = -61.60' in err and 'track.approach_length' in err


def test_a_head_beyond_the_track_is_refused() -> None:
    with pytest.raises(ScenarioError, match=r'train.start_position = 500 m: the axles'):
        load_scenario('track_approach', ['train.start_position=500'])


def test_a_run_longer_than_the_track_names_the_duration(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    err = _refused(tmp_path, capsys, 'track_approach', '--duration', '3')
    assert 'solver.duration = 3 s: the run is longer than the track' in err


def test_an_automatic_duration_longer_than_the_track_is_refused() -> None:
    with pytest.raises(ScenarioError, match=r'solver.duration = 0 \(automatic.*longer than '
                       'the track'):
        load_scenario('paper_ttbi', ['solver.free_vibration_periods=100'])


def test_the_automatic_approach_is_named() -> None:
    with pytest.raises(ScenarioError, match=r'track.approach_length = 0 m = automatic'):
        load_scenario('paper_ttbi', ['train.start_position=-1000'])


@pytest.mark.parametrize('entry, words', [
    ('a=girder@33', r'x is not on the girder, which runs from 0 to 32 m'),
    ('a=girder@-0.5', r'x is not on the girder'),
    ('a=slab@3', r"component 'slab' needs track.model = 'slab'"),
])
def test_observers_off_their_component_are_refused_before_building(entry: str,
                                                                   words: str) -> None:
    with pytest.raises(ScenarioError, match=words):
        load_scenario('moving_force_beam', values=[('output.observers', [entry])])


@pytest.mark.parametrize('entry', ['a=rail_left@-45', 'a=base@80', 'a=slab@1e4'])
def test_track_observers_off_the_track_are_refused(entry: str) -> None:
    with pytest.raises(ScenarioError, match=r"output.observers\[0\] = 'a=.*x is not on the"):
        load_scenario('track_approach', values=[('output.observers', [entry])])
