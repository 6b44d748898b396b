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
``ttb-sim analyze`` and ``compare`` end to end, on bags whose signals are known.

The synthetic bag (``synthetic_bag.py``) is written with the project's own
topic table and recorder and read back through ``ttb_sim.io.read_bag``;
every number checked in ``metrics.json`` is computed here from the sines
that went in (Sperling, Wk, VAL, Q/P, wheel-load reduction, deck
acceleration, pile rotation, power flow per layer, Eq. 16).
"""

from __future__ import annotations

import csv
import json
import math
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

from ttb_sim.cli import main
from ttb_sim.commands.compare import default_labels
from ttb_sim.commands.sweep_case import case_row
from ttb_sim.io.streams import load_streams
from ttb_sim.io.topics import topic_table
from ttb_sim.report.metrics import bag_metrics, flatten
from ttb_sim.sim import Layout

import synthetic_bag as sb   # noqa: I100 - the helper next to this file


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    return sb.write_bag(tmp_path_factory.mktemp('syn') / 'bag')


@pytest.fixture(scope='module')
def analysed(bag, tmp_path_factory):
    out = tmp_path_factory.mktemp('out') / 'analysis'
    assert main(['analyze', str(bag), '--out', str(out)]) == 0
    return out, json.loads((out / 'metrics.json').read_text())


def test_every_figure_and_the_page(analysed):
    out, metrics = analysed
    expected = {'car_body.png', 'wheel_rail.png', 'girder.png', 'observers.png',
                'power_flow.png', 'piles.png', 'rigid_displacement.png', 'ground.png',
                'soil_val.png', 'soil_contour.png', 'soil_grid.png', 'indices.png'}
    assert set(metrics['figures']) == expected
    assert metrics['figures_skipped'] == {}
    page = (out / 'index.html').read_text()
    for name in expected:
        assert (out / name).stat().st_size > 10_000
        assert f'src="{name}"' in page
    assert not list(out.parent.glob('.analysis.partial-*'))


def test_ride_metrics_of_the_car_body(analysed):
    car = analysed[1]['car_body']['car01']
    az, fz = sb.CAR_Z
    ay, fy = sb.CAR_Y
    assert car['sperling_vertical'] == pytest.approx(
        7.08 * ((az / 9.81) ** 3 * 0.325 * fz**2 / fz) ** 0.1, rel=1e-6)
    assert car['sperling_lateral'] == pytest.approx(
        7.08 * ((ay / 9.81) ** 3 * 0.8 * fy**2 / fy) ** 0.1, rel=1e-6)
    assert car['vertical_peak_m_s2'] == pytest.approx(az, rel=1e-3)
    # |Wk(2 Hz)| = 0.531 and |Wd(1 Hz)| = 1.011 (ISO 2631-1 Table 3), to 1 %
    assert car['wk_weighted_rms_m_s2'] == pytest.approx(az / math.sqrt(2) * 0.531, rel=0.01)
    assert car['wd_weighted_rms_m_s2'] == pytest.approx(ay / math.sqrt(2) * 1.011, rel=0.01)


def test_safety_metrics_of_the_wheels(analysed):
    m = analysed[1]
    static, amp, _, lateral = sb.WHEEL
    wheel = m['wheel_rail']
    # the 10 Hz tone sampled at 500 Hz peaks at cos(pi / 50) = 0.998 of its amplitude
    assert wheel['derailment_coefficient_max'] == pytest.approx(lateral / (static - amp),
                                                                rel=3e-3)
    assert wheel['wheel_load_reduction_max'] == pytest.approx(amp / static, rel=3e-3)
    assert wheel['wheel_load_reduction_dynamic_max'] == pytest.approx(amp / static, rel=3e-3)
    assert wheel['lateral_wheelset_force_max_N'] == pytest.approx(2 * lateral)
    assert wheel['lateral_wheelset_force_limit_N'] == pytest.approx(10e3 + 2 * static / 3)
    assert m['indices']['derailment_coefficient']['within_limit']
    # the first wheel's r.m.s.: the tone's amplitude / sqrt(2), all of it below 20 Hz
    dynamic = wheel['first_wheel_vertical_dynamic_rms_N']
    assert dynamic == pytest.approx(amp / math.sqrt(2), rel=0.01)
    bands = wheel['first_wheel_vertical_band_rms_N']
    assert bands['0-20 Hz'] == pytest.approx(amp / math.sqrt(2), rel=0.02)
    assert bands['20-100 Hz'] < 0.05 * amp and bands['100-500 Hz'] < 0.05 * amp
    assert wheel['first_wheel_lateral_rms_N'] == pytest.approx(lateral)


def test_girder_piles_and_soil(analysed):
    m = analysed[1]
    a, f = sb.MID
    deck = m['girder']['span01']['deck_acceleration_peak_m_s2']
    assert deck == pytest.approx((2 * math.pi * f) ** 2 * a, rel=0.02)
    pile = m['piles']['pier01_pile01']
    assert pile['vertical_acceleration_peak_m_s2'] == pytest.approx(sb.PILE_A[0], rel=3e-3)
    assert pile['rotation_peak_rad'] == pytest.approx(sb.PILE_ROT[0], rel=0.02)
    assert pile['vertical_acceleration_rms_m_s2'] == pytest.approx(sb.PILE_A[0] / math.sqrt(2),
                                                                   rel=0.01)
    points = m['soil']['points']
    assert sorted(points) == ['point_(1.0,_5.0)_m', 'point_(3.0,_5.0)_m']   # off the line
    assert m['soil']['line_peak_acceleration_m_s2'] == pytest.approx(5 * sb.SOIL[0], rel=3e-3)
    first = points['point_(1.0,_5.0)_m']
    level = 20 * math.log10(sb.SOIL[0] / math.sqrt(2) / 1e-6)
    assert first['val_max_db'] == pytest.approx(level, abs=1e-6)
    assert first['val_max_band_hz'] == pytest.approx(6.31, abs=0.01)
    assert first['vertical_acceleration_rms_m_s2'] == pytest.approx(sb.SOIL[0] / math.sqrt(2),
                                                                    rel=0.01)
    last = points['point_(3.0,_5.0)_m']   # amplitude x5
    assert last['val_max_db'] - first['val_max_db'] == pytest.approx(20 * math.log10(5),
                                                                     abs=1e-6)


def test_power_flow_per_layer_matches_closed_form(analysed):
    m = analysed[1]['power_flow_mean_W_per_m'][f'x={sb.STATION:g} m']
    expected = sb.interface_power()
    for layer, value in expected.items():
        # velocities from central differences at 500 Hz: (2 pi 5 / 500)^2 / 6 = 0.07 %
        assert m[layer] == pytest.approx(value, rel=0.005), layer


def test_sqlite3_bag_gives_the_same_metrics(analysed, tmp_path):
    other = sb.write_bag(tmp_path / 'bag3', storage='sqlite3')
    m3 = json.loads(json.dumps(bag_metrics(load_streams(other))))
    m = analysed[1]
    a, b = flatten(m3['car_body']), flatten(m['car_body'])
    assert a == pytest.approx(b, rel=1e-12)
    assert flatten(m3['power_flow_mean_W_per_m']) == pytest.approx(
        flatten(m['power_flow_mean_W_per_m']), rel=1e-12)


def test_a_renamed_node_without_summary_is_read_by_topic_endings(tmp_path):
    """A bag recorded from a node run as ``__node:=twin`` (no summary.json) still analyses."""
    bag = sb.write_bag(tmp_path / 'bag', summary=False, namespace='/twin')
    m = bag_metrics(load_streams(bag))
    assert m['speed_kmh'] == pytest.approx(300.0)
    assert m['car_body']['car01']['vertical_peak_m_s2'] == pytest.approx(sb.CAR_Z[0], rel=1e-3)
    assert 'power_flow_mean_W_per_m' not in m   # observer positions unknown without summary
    assert m['excitation_hz'] == {'V/\u03bb (Eq. 15)': [pytest.approx(300 / 3.6)] * 2}


def test_without_summary_figures_needing_it_are_skipped_and_rerun_replaces(tmp_path):
    bag = sb.write_bag(tmp_path / 'bag', summary=False)
    (bag / 'analysis').mkdir()
    (bag / 'analysis' / 'metrics.json').write_text('{}')   # an earlier analysis
    (bag / 'analysis' / 'stale.png').write_bytes(b'x')
    assert main(['analyze', str(bag)]) == 0
    metrics = json.loads((bag / 'analysis' / 'metrics.json').read_text())
    assert set(metrics['figures_skipped']) == {'observers', 'power_flow', 'soil_grid'}
    assert 'summary.json' in metrics['figures_skipped']['observers']
    assert 'car_body.png' in metrics['figures']
    assert not (bag / 'analysis' / 'stale.png').exists()


def run_cli(*args):
    return subprocess.run([sys.executable, '-m', 'ttb_sim.cli', *args], capture_output=True,
                          text=True, timeout=300)


def test_bad_input_exit_2_without_traceback(bag, tmp_path, capsys):
    not_bag = tmp_path / 'plain'
    not_bag.mkdir()
    (not_bag / 'x.txt').write_text('hello')
    truncated = tmp_path / 'trunc'
    truncated.mkdir()
    (truncated / 'metadata.yaml').write_bytes((bag / 'metadata.yaml').read_bytes())
    data = next(bag.glob('*.mcap')).read_bytes()
    (truncated / next(bag.glob('*.mcap')).name).write_bytes(data[:len(data) // 3])
    killed = tmp_path / 'killed'       # before its first chunk was written
    killed.mkdir()
    (killed / 'bag_0.mcap').write_bytes(data[:200])
    empty = tmp_path / 'clock_only'
    sb.write_bag(empty, layout=Layout(n_spans=0, n_supports=0, n_bodies=0), summary=False)
    busy = tmp_path / 'busy'
    busy.mkdir()
    (busy / 'thesis.tex').write_text('keep me')
    cases = [((str(not_bag),), 'not a rosbag2 directory'),
             ((str(truncated),), 'truncated or corrupt'),
             ((str(killed),), 'did not finish'),
             ((str(tmp_path / 'missing'),), 'does not exist'),
             ((str(empty),), 'none of the topics'),
             ((str(bag), '--out', str(busy)), 'not an earlier analysis')]
    for args, message in cases:
        assert main(['analyze', *args]) == 2, args
        err = capsys.readouterr().err
        assert message in err
        assert len(err.strip().splitlines()) == 1
    result = run_cli('analyze', str(truncated))   # as a program: one line, no traceback
    assert result.returncode == 2
    assert result.stderr.startswith('ttb-sim: error: ')
    assert len(result.stderr.strip().splitlines()) == 1
    assert [p.name for p in busy.iterdir()] == ['thesis.tex']
    for folder in (not_bag, truncated, killed, empty):
        assert not (folder / 'analysis').exists()


def test_a_killed_runs_bag_is_read_up_to_its_last_complete_chunk(bag, tmp_path, capsys,
                                                                 caplog):
    """Issue #28 6: no metadata.yaml, the MCAP file cut short: analysed, one warning line."""
    killed = tmp_path / 'killed'
    killed.mkdir()
    data = next(bag.glob('*.mcap')).read_bytes()
    (killed / 'bag_0.mcap').write_bytes(data[:len(data) * 2 // 3])
    with caplog.at_level('WARNING'):
        assert main(['analyze', str(killed)]) == 0
    [warning] = [r.getMessage() for r in caplog.records if r.levelname == 'WARNING']
    assert re.fullmatch(rf'bag {re.escape(str(killed))} was not closed \(a killed recording\?\): '
                        r'read up to its last complete chunk: \d+ messages of \d+ topics, '
                        r't = [\d.]+ \.\. [\d.]+ s; `ttb-sim recover .*` writes a closed copy',
                        warning), warning
    assert (killed / 'analysis' / 'metrics.json').is_file()
    assert sorted(p.name for p in killed.iterdir()) == ['analysis', 'bag_0.mcap']


def test_a_broken_metadata_file_is_one_line_exit_2(bag, tmp_path, capsys):
    """Issue #28 5.5: what is wrong with which file, in one line; no advice to recover."""
    broken = tmp_path / 'broken'
    broken.mkdir()
    (broken / 'metadata.yaml').write_text('rosbag2_bagfile_information: [\n')
    for data in bag.glob('*.mcap'):
        (broken / data.name).write_bytes(data.read_bytes())
    assert main(['analyze', str(broken)]) == 2
    err = capsys.readouterr().err
    # libyaml words the problem 'did not find expected node content', PyYAML's Python parser
    # 'expected the node content, but found ...'
    assert re.fullmatch(f"ttb-sim: error: bag metadata '{re.escape(str(broken))}/metadata.yaml' "
                        r'is not valid YAML: while parsing a flow node; [^\n]*node content[^\n]* '
                        r'\(line 2, column 1\)\n', err), err
    assert not (broken / 'analysis').exists()
    result = run_cli('analyze', str(broken))
    assert (result.returncode, result.stderr) == (2, err)


def test_a_cut_mcap_points_to_recovery_in_one_line(bag, tmp_path, capsys):
    cut = tmp_path / 'cut'
    cut.mkdir()
    (cut / 'metadata.yaml').write_bytes((bag / 'metadata.yaml').read_bytes())
    data = next(bag.glob('*.mcap'))
    (cut / data.name).write_bytes(data.read_bytes()[:len(data.read_bytes()) // 3])
    assert main(['analyze', str(cut)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"ttb-sim: error: bag '{cut}' is truncated or corrupt "
                          f"('{cut / data.name}': ")
    assert err.endswith('; a recording that was killed leaves such a file: `ttb-sim recover` '
                        'may rescue it\n')
    assert err.count('\n') == 1


@pytest.fixture(scope='module')
def quarter_cars(tmp_path_factory):
    """Two 0.1 s quarter-car runs in folders both named ``bag`` (at 100 and 120 km/h)."""
    root = tmp_path_factory.mktemp('qc')
    bags = []
    for folder, speed in (('a', '100'), ('b', '120')):
        bag = root / folder / 'bag'
        assert main(['run', 'sprung_mass_beam', '--duration', '0.1', '--speed-kmh', speed,
                     '--out', str(bag)]) == 0
        bags.append(bag)
    return bags


def test_indices_a_quarter_car_cannot_produce_are_n_a(quarter_cars, tmp_path, capsys):
    """Issue #28 5.7: no lateral dynamics, no roll: null with the reason, not 0 'within'."""
    out = tmp_path / 'analysis'
    assert main(['analyze', str(quarter_cars[0]), '--out', str(out)]) == 0
    metrics = json.loads((out / 'metrics.json').read_text())
    lateral = 'quarter cars (train.vehicle = sprung_mass) have no lateral dynamics'
    roll = 'quarter cars (train.vehicle = sprung_mass) have no roll: left and right wheel ' \
        'loads are equal'
    for name, reason in (('derailment_coefficient', lateral), ('wheel_load_reduction', roll),
                         ('lateral_wheelset_force', lateral)):
        entry = metrics['indices'][name]
        assert (entry['value'], entry['within_limit'], entry['status'], entry['reason']) == \
            (None, None, 'n/a', reason)
    assert metrics['indices']['deck_acceleration']['status'] == 'within'
    wheel = metrics['wheel_rail']
    assert wheel['derailment_coefficient_max'] is None
    assert wheel['lateral_wheelset_force_max_N'] is None
    assert wheel['wheel_load_reduction_max'] is None
    assert wheel['not_available']['wheel_load_reduction_max'] == roll
    assert wheel['wheel_load_reduction_dynamic_max'] > 0   # vertical dynamics: rated
    page = (out / 'index.html').read_text()
    assert f'<td>n/a</td><td>n/a</td><td>n/a: {lateral}</td>' in page   # value, verdict, why
    row = case_row({'case': 'v100', 'speed_kmh': 100.0, 'status': 'ok', 'metrics': metrics})
    assert row['derailment_coefficient_max'] is None   # an empty cell of sweep.csv, no point
    assert row['wheel_load_reduction_max'] == wheel['wheel_load_reduction_dynamic_max']


def test_without_summary_the_bag_shows_what_it_lacks(quarter_cars, tmp_path):
    bag = tmp_path / 'bag'
    shutil.copytree(quarter_cars[0], bag)
    (bag / 'summary.json').unlink()
    indices = bag_metrics(load_streams(bag))['indices']
    assert indices['derailment_coefficient']['reason'] == 'the bag has no lateral wheel-rail force'
    assert indices['wheel_load_reduction']['reason'] == \
        'left and right wheel loads are equal in the bag'


def test_compare_labels_bags_of_one_folder_name_by_scenario_and_speed(quarter_cars, tmp_path):
    out = tmp_path / 'cmp'
    assert main(['compare', *map(str, quarter_cars), '--out', str(out)]) == 0
    with (out / 'differences.csv').open() as fh:
        head = next(csv.reader(fh))
    assert head[:3] == ['metric', 'sprung_mass_beam 100 km/h', 'sprung_mass_beam 120 km/h']
    assert set(json.loads((out / 'metrics.json').read_text())['bags']) == {
        'sprung_mass_beam 100 km/h', 'sprung_mass_beam 120 km/h'}


def test_default_labels_fall_back_to_parent_folders_then_numbers(quarter_cars, tmp_path):
    same = [tmp_path / 'x' / 'bag', tmp_path / 'y' / 'bag']
    for bag in same:
        shutil.copytree(quarter_cars[0], bag)   # the same scenario and speed
    assert default_labels(same) == ['x/bag', 'y/bag']
    assert default_labels([same[0], same[0]]) == ['1:bag', '2:bag']
    assert default_labels(quarter_cars) == ['sprung_mass_beam 100 km/h',
                                            'sprung_mass_beam 120 km/h']
    assert default_labels([same[0], quarter_cars[1].parent]) == ['bag', 'b']


HEAVY = ('matplotlib', 'scipy', 'ttb_sim.analysis', 'ttb_sim.sim')
"""What analyze and compare import only for a bag they can read (seconds at load)."""


def test_refusals_come_before_the_heavy_imports(bag, tmp_path):
    """Issue #28 5.6: a wrong path is refused before scipy, matplotlib or the model load."""
    broken = tmp_path / 'broken'
    broken.mkdir()
    (broken / 'metadata.yaml').write_text('rosbag2_bagfile_information: {relative_file_paths: '
                                          '[gone.mcap]}\n')
    cut = tmp_path / 'cut'
    cut.mkdir()
    (cut / 'metadata.yaml').write_bytes((bag / 'metadata.yaml').read_bytes())
    data = next(bag.glob('*.mcap'))
    (cut / data.name).write_bytes(data.read_bytes()[:1000])
    (tmp_path / 'file').write_text('x')
    cases = [['analyze', str(tmp_path / 'missing')], ['analyze', str(broken)],
             ['analyze', str(cut)], ['analyze', str(bag), '--out', str(tmp_path / 'file')],
             ['compare', str(bag), str(tmp_path / 'missing')], ['compare', str(bag), str(cut)]]
    script = ('import json, sys\nfrom ttb_sim.cli import main\n'
              'code = main(json.loads(sys.argv[1]))\n'
              f'print(code, [m for m in {HEAVY!r} if m in sys.modules])')
    for args in cases:
        result = subprocess.run([sys.executable, '-c', script, json.dumps(args)],
                                capture_output=True, text=True, timeout=300)
        assert result.stdout == '2 []\n', (args, result.stdout, result.stderr)
        assert result.stderr.startswith('ttb-sim: error: ') and result.stderr.count('\n') == 1


def test_compare_overlays_and_differences(bag, tmp_path):
    other = sb.write_bag(tmp_path / 'louder', scale=1.5)
    out = tmp_path / 'cmp'
    assert main(['compare', str(bag), str(other), '--labels', 'ttbi,ttbcpsi',
                 '--out', str(out)]) == 0
    with (out / 'differences.csv').open() as fh:
        rows = {r['metric']: r for r in csv.DictReader(fh)}
    row = rows['car_body.car01.vertical_peak_m_s2']
    az = sb.CAR_Z[0]
    assert float(row['ttbi']) == pytest.approx(az, rel=1e-3)
    assert float(row['ttbcpsi - ttbi']) == pytest.approx(0.5 * az, rel=1e-3)
    assert float(row['relative (ttbcpsi)']) == pytest.approx(0.5, rel=1e-3)
    sperling = rows['car_body.car01.sperling_vertical']
    assert float(sperling['relative (ttbcpsi)']) == pytest.approx(1.5 ** 0.3 - 1, rel=1e-6)
    page = (out / 'index.html').read_text()
    assert 'Differences from ttbi' in page
    assert (out / 'soil_contour_ttbi.png').is_file()
    assert (out / 'soil_contour_ttbcpsi.png').is_file()
    assert main(['compare', str(bag), str(other), '--labels', 'a', '--out',
                 str(tmp_path / 'x')]) == 2
    assert not (tmp_path / 'x').exists()


def test_topic_table_used_for_the_synthetic_bag_has_every_family():
    names = [t.name for t in topic_table(sb.LAYOUT)]
    for part in ('body/imu', 'wheel_rail', 'midspan', 'bearings', 'piles', 'soil/points',
                 'observers'):
        assert any(part in n for n in names), part
    assert np.isfinite(sb.interface_power()['slab'])
