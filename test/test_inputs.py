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
Bounded input: messages, YAML (aliases, depth, size), regular files only.

Every refusal here exits 2 through the command line (or raises ScenarioError)
with a one-line message, quickly, and writes nothing. The alias bomb is the one
of issue 13 (nine levels of ten aliases: 10^9 items if expanded).
"""

import os
from pathlib import Path
import re
import time

import pytest
from ttb_sim.cli import main
from ttb_sim.config import load_scenario, read_yaml
from ttb_sim.config.loader import MAX_SCENARIO_BYTES, MAX_YAML_DEPTH
from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import MAX_SHOWN, read_user_file, shown
from ttb_sim.model.irregularity import load_csv
from ttb_sim.model.irregularity.measured import MAX_CSV_BYTES
import yaml

BOMB = 'a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n' + ''.join(
    f'a{i}: &a{i} [*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, '
    f'*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}]\n' for i in range(1, 9))


def _cli(tmp_path: Path, capsys: pytest.CaptureFixture[str], *args: str) -> str:
    out = tmp_path / 'bag'
    assert main(['run', *args, '--out', str(out)]) == 2
    assert not out.exists()
    err = capsys.readouterr().err
    assert err.startswith('ttb-sim: error: ') and err.count('\n') == 1
    assert len(err) < 1000
    return err


def test_shown_bounds_long_strings_with_a_length_note():
    text = shown('x' * 100_000)
    assert len(text) < MAX_SHOWN + 40
    assert text.endswith('(100000 characters)')
    assert shown('abc') == "'abc'"
    assert shown(1.5) == '1.5'


def test_shown_never_expands_shared_references():
    value: list = ['x']
    for _ in range(40):  # 10^40 leaves if expanded
        value = [value] * 10
    text = shown(value)
    assert len(text) < MAX_SHOWN + 40 and text.endswith('(list of 10 items)')
    assert 'bits' in shown(10**5000)


@pytest.mark.parametrize('where', ['description', 'output.observers'])
def test_an_alias_bomb_is_refused_fast(tmp_path, capsys, where):
    section, _, key = where.rpartition('.')
    body = BOMB + (f'{section}:\n  {key}: *a8\n' if section else f'{key}: *a8\n')
    path = tmp_path / 'bomb.yaml'
    path.write_text(body)
    start = time.process_time()
    err = _cli(tmp_path, capsys, str(path))
    assert time.process_time() - start < 30  # a hang bound, not a speed check
    assert 'anchors and aliases' in err and 'bomb.yaml' in err


def test_an_alias_in_a_set_value_is_refused():
    with pytest.raises(ScenarioError, match='anchors and aliases'):
        load_scenario('moving_force_beam', ['description=&a [*a]'])


def test_anchors_alone_are_refused():
    with pytest.raises(yaml.YAMLError, match='anchors and aliases'):
        read_yaml('a: &x 1\n')


@pytest.mark.parametrize('depth', [MAX_YAML_DEPTH + 1, 5000])
def test_deep_nesting_is_refused(tmp_path, capsys, depth):
    path = tmp_path / 'deep.yaml'
    path.write_text('description: ' + '[' * depth + ']' * depth + '\n')
    err = _cli(tmp_path, capsys, str(path))
    assert f'nested deeper than {MAX_YAML_DEPTH} levels' in err


def test_nesting_up_to_the_bound_is_parsed():
    depth = MAX_YAML_DEPTH - 1
    assert read_yaml('[' * depth + ']' * depth) is not None


def test_yaml_errors_name_the_file(tmp_path, capsys):
    path = tmp_path / 'broken.yaml'
    path.write_text('bridge: [1, 2\n')
    err = _cli(tmp_path, capsys, str(path))
    assert '<unicode string>' not in err
    assert f'(in "{path}", line 2, column 1)' in err


def test_a_key_given_twice_is_refused_naming_it_and_both_lines(tmp_path, capsys):
    path = tmp_path / 'twice.yaml'
    path.write_text('bridge:\n  span_length: 30\n  n_spans: 3\n  span_length: 25\n'
                    'train:\n  speed_kmh: 250\n')
    err = _cli(tmp_path, capsys, str(path))
    assert err == (f'ttb-sim: error: scenario file {str(path)!r} is not valid YAML: key '
                   "'bridge.span_length' is given twice, on lines 2 and 4; give it once\n")


@pytest.mark.parametrize('text, words', [
    ('name: a\nname: b\n', "key 'name' is given twice, on lines 1 and 2"),
    ('train: {speed_kmh: 1, speed_kmh: 2}\n', "key 'train.speed_kmh' is given twice, on line 1, "
     'columns 9 and 23'),
    ('output:\n  observers: [{a: 1, a: 2}]\n', r"key 'output.observers\[0\].a' is given twice"),
])
def test_duplicate_keys_are_refused_at_any_depth(tmp_path, text, words):
    path = tmp_path / 's.yaml'
    path.write_text(text)
    with pytest.raises(ScenarioError, match=words):
        load_scenario(path)


def test_a_duplicate_key_in_a_set_value_is_refused():
    with pytest.raises(ScenarioError, match="value is not valid YAML .key 'a' is given twice"):
        load_scenario('moving_force_beam', ['description={a: 1, a: 2}'])


@pytest.mark.parametrize('text', ['', '\n\n', '# only a comment\n', '  # indented\n\n# two\n',
                                  '---\n'])
def test_an_empty_scenario_file_is_refused(tmp_path, capsys, text):
    path = tmp_path / 'empty.yaml'
    path.write_text(text)
    err = _cli(tmp_path, capsys, str(path))
    assert err.startswith(f'ttb-sim: error: scenario file {str(path)!r} is empty (no keys, '
                          'only blank lines or comments); give the keys to set')


@pytest.mark.parametrize('text, words', [
    ('a: ' + '1' * 5000, 'a value cannot be read'),
    ('a: 2001-13-45', 'a value cannot be read'),
    ('!!float ', 'a value cannot be read'),
    ('a: !!float', 'a value cannot be read'),
    ('a: !!int', 'a value cannot be read'),
    ('a: !!python/name:os.system', 'could not determine a constructor'),
])
def test_values_yaml_cannot_construct_are_refused(tmp_path, text, words):
    path = tmp_path / 's.yaml'
    path.write_text(text)
    with pytest.raises(ScenarioError, match=words):
        load_scenario(path)


def test_a_huge_value_gives_a_short_message(tmp_path, capsys):
    err = _cli(tmp_path, capsys, 'moving_force_beam', '--set',
               'bridge.span_length=' + 'x' * 50_000)
    assert '(50000 characters)' in err


def test_a_huge_unknown_key_gives_a_short_message(tmp_path, capsys):
    path = tmp_path / 's.yaml'
    path.write_text('bridge:\n  ? ' + 'k' * 20_000 + '\n  : 1\n')  # an explicit long key
    err = _cli(tmp_path, capsys, str(path))
    assert 'unknown key' in err and 'characters)' in err


def test_too_many_list_entries_are_refused():
    with pytest.raises(ScenarioError, match='too many entries'):
        load_scenario('moving_force_beam', values=[('train.axle_offsets', [0.0] * 5000)])


def test_a_large_scenario_file_is_refused(tmp_path, capsys):
    path = tmp_path / 'big.yaml'
    path.write_text('# ' + 'x' * MAX_SCENARIO_BYTES + '\n')
    err = _cli(tmp_path, capsys, str(path))
    assert 'is too large' in err and str(MAX_SCENARIO_BYTES) in err


def test_a_directory_is_not_a_scenario_file(tmp_path, capsys):
    folder = tmp_path / 'folder.yaml'
    folder.mkdir()
    err = _cli(tmp_path, capsys, str(folder))
    assert 'is a directory, not a file' in err


def test_a_folder_named_like_a_builtin_does_not_hide_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / 'moving_force_beam').mkdir()
    assert load_scenario('moving_force_beam', ['solver.duration=0.01']).name == \
        'moving_force_beam'
    (tmp_path / 'my_case').mkdir()
    with pytest.raises(ScenarioError, match="'my_case' is a directory"):
        load_scenario('my_case')


@pytest.mark.skipif(not os.path.exists('/dev/zero'), reason='needs /dev/zero')
def test_dev_zero_is_refused_as_scenario_and_irregularity(tmp_path, capsys):
    err = _cli(tmp_path, capsys, '/dev/zero')
    assert "scenario file '/dev/zero' is not a regular file" in err
    err = _cli(tmp_path, capsys, 'sprung_mass_beam', '--duration', '0.01', '--set',
               'irregularity.file=/dev/zero')
    assert "irregularity file '/dev/zero' is not a regular file" in err


def test_irregularity_file_refusals(tmp_path, capsys):
    err = _cli(tmp_path, capsys, 'sprung_mass_beam', '--duration', '0.01', '--set',
               f'irregularity.file={tmp_path}')
    assert 'is a directory, not a file' in err
    err = _cli(tmp_path, capsys, 'sprung_mass_beam', '--duration', '0.01', '--set',
               f'irregularity.file={tmp_path / "none.csv"}')
    assert 'does not exist' in err


def test_a_large_csv_is_refused_without_reading_it(tmp_path):
    path = tmp_path / 'big.csv'
    with path.open('wb') as fh:  # sparse: no disk used
        fh.truncate(MAX_CSV_BYTES + 1)
    with pytest.raises(ScenarioError, match='is too large'):
        load_csv(path)


def test_a_csv_resampling_to_too_many_points_is_refused(tmp_path):
    path = tmp_path / 'spread.csv'
    path.write_text('x,z_left,z_right,y_left,y_right\n0,0,0,0,0\n1e-9,0,0,0,0\n'
                    '2e-9,0,0,0,0\n3e-9,0,0,0,0\n1e6,0,0,0,0\n')
    with pytest.raises(ScenarioError, match='over the limit'):
        load_csv(path)


def test_a_csv_spanning_an_infinite_length_is_refused(tmp_path):
    path = tmp_path / 'wide.csv'
    path.write_text('x,z_left,z_right,y_left,y_right\n-1e308,0,0,0,0\n0,0,0,0,0\n'
                    '1e308,0,0,0,0\n1.5e308,0,0,0,0\n')
    with pytest.raises(ScenarioError, match='must be finite'):
        load_csv(path)


def test_a_huge_csv_cell_gives_a_short_message(tmp_path):
    path = tmp_path / 'cell.csv'
    path.write_text('x,z_left,z_right,y_left,y_right\n' + '0,0,0,0,0\n' * 3
                    + 'q' * 10_000 + ',0,0,0,0\n')
    with pytest.raises(ScenarioError, match=r'\(10000 characters\)') as info:
        load_csv(path)
    assert len(str(info.value)) < 500


@pytest.mark.parametrize('text, message', [
    ('x,z_left,z_right,y_left,y_right\n0,0,0,0,0\n0.25,abc,0,0,0\n',
     "row 3: non-numeric value 'abc' in column z_left"),
    ('0,0,0,0,0\nq,0,0,0,0\n', "row 2: non-numeric value 'q' in column x"),
    ('y_right,x,z_left,z_right,y_left\n0,0,0,0,0\n1,0.25,0,0,\n',
     "row 3: non-numeric value '' in column y_left"),
    ('x,z_left,z_right,y_left,y_right\n0,0,0,0,0\n0.25,0,0,inf,0\n',
     "row 3: value 'inf' in column y_left is not a finite number"),
    ('x,z_left,z_right,y_left,y_right\n0,0,0,0\n', 'row 2: expected 5 fields as in the header'),
])
def test_a_short_csv_with_a_bad_cell_names_the_cell(tmp_path, capsys, text, message):
    path = tmp_path / 'short.csv'
    path.write_text(text)
    err = _cli(tmp_path, capsys, 'sprung_mass_beam', '--duration', '0.01', '--set',
               f'irregularity.file={path}')
    assert message in err and 'too few rows' not in err
    with pytest.raises(ScenarioError, match=f'^{re.escape(str(path))}: {re.escape(message)}'):
        load_csv(path)


def test_a_short_csv_of_good_cells_is_refused_for_its_rows(tmp_path):
    path = tmp_path / 'short.csv'
    path.write_text('x,z_left,z_right,y_left,y_right\n0,0,0,0,0\n0.25,0,0,0,0\n')
    with pytest.raises(ScenarioError, match=r'row 3: too few rows: 2 data row\(s\) \(last data '
                       r'row 3\), need at least 4'):
        load_csv(path)
    path.write_text('x,z_left,z_right,y_left,y_right\n# no data\n')
    with pytest.raises(ScenarioError, match=r'row 1: too few rows: 0 data row\(s\) \(no data '
                       r'rows\)'):
        load_csv(path)


def test_a_name_too_long_for_the_file_system_is_refused(tmp_path, capsys):
    """Found by the fuzz suite: Path.is_file() raises for ENAMETOOLONG (not for ENOENT)."""
    err = _cli(tmp_path, capsys, 'x' * 300)
    assert err.startswith("ttb-sim: error: scenario file 'xxxxx") and \
        err.endswith('cannot be reached (File name too long)\n')
    assert main(['analyze', 'y' * 300]) == 2
    assert capsys.readouterr().err.endswith('cannot be reached (File name too long)\n')
    (tmp_path / 'loop').symlink_to('loop')
    assert main(['analyze', str(tmp_path / 'bag'), '--out', str(tmp_path / 'loop' / 'a')]) == 2
    assert 'does not exist' in capsys.readouterr().err   # the bag is checked first
    assert main(['analyze', str(tmp_path / 'loop')]) == 2
    assert capsys.readouterr().err.endswith('cannot be reached (Too many levels of symbolic '
                                            'links)\n')


def test_control_characters_of_a_value_stay_on_one_line(capsys):
    """Found by the fuzz suite: a record separator in a case name split the message."""
    assert main(['validate', 'a\x1eb\u2028c']) == 2
    err = capsys.readouterr().err
    assert err.startswith("ttb-sim: error: unknown validation case(s) 'a\\x1eb\\u2028c'; allowed")
    assert len(err.splitlines()) == 1


def test_a_span_too_short_for_finite_beam_elements_is_refused(tmp_path, capsys):
    """Found by the fuzz suite: 2e-282 m is in (0, 500] but its elements' L^3 is 0."""
    err = _cli(tmp_path, capsys, 'moving_force_beam', '--duration', '0.002', '--set',
               'bridge.span_length=2.0273994802272575e-282')
    assert err.startswith('ttb-sim: error: bridge.span_length = 2.0274e-282 m over '
                          'bridge.elements_per_span = 16 gives beam elements of 1.26712e-283 m')
    assert err.endswith('is not a finite number: give a span of a bridge (metres)\n')


def test_read_user_file_reads_a_small_regular_file(tmp_path):
    path = tmp_path / 'a.txt'
    path.write_text('hello')
    assert read_user_file(path, 'file', 10) == 'hello'
    with pytest.raises(ScenarioError, match="file '.*a.txt' is too large: 5 bytes"):
        read_user_file(path, 'file', 4)
