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
The ``compare`` verb: several bags -> the analysis figures overlaid and a table of differences.

Typical use is [P] Example 1, ``paper_ttbi`` against ``paper_ttbcpsi``.  Every
bag is read and its metrics computed before anything is written; the figures
carry one trace per bag (labels from ``--labels``, else the bag folder names or,
where those repeat, the scenario and speed of each bag: :func:`default_labels`);
``differences.csv`` and the page list every numeric metric of every bag with
its difference from the first bag (absolute and relative).
"""

from __future__ import annotations

import csv
import logging
from pathlib import Path
import sys
import time
from typing import Sequence

from ttb_sim.errors import ScenarioError
from ttb_sim.io.bag_checks import check_bag_path
from ttb_sim.report.output import check_output, staged_output, write_index, write_json

log = logging.getLogger(__name__)

EXIT_OK = 0


def _scenario_label(bag: Path) -> str | None:
    """Return 'scenario speed km/h' from the summary.json beside a bag (None without one)."""
    from ttb_sim.io.streams import read_summary   # (the bag reader: after the path checks)
    summary = read_summary(bag)
    scenario = summary.get('scenario') if summary else None
    if not isinstance(scenario, dict) or not isinstance(scenario.get('name'), str):
        return None
    train = scenario.get('train')
    speed = train.get('speed_kmh') if isinstance(train, dict) else None
    if isinstance(speed, (int, float)) and not isinstance(speed, bool):
        return f'{scenario["name"]} {speed:g} km/h'
    return str(scenario['name'])


def default_labels(bags: Sequence[Path]) -> list[str]:
    """
    Return a distinct label per bag: its folder name, else what tells the bags apart.

    When folder names repeat (``a/bag``, ``b/bag``) the labels are the scenario
    name and speed of each bag's ``summary.json`` (``ten_span_train 300 km/h``);
    when those repeat too or a bag has no summary, the parent and folder names
    (``a/bag``); as a last resort the folder names numbered in order (``1:bag``).
    """
    names = [b.name if b.is_dir() else b.stem for b in bags]
    if len(set(names)) == len(names):
        return names
    scenario = [_scenario_label(b) for b in bags]
    parents = [f'{b.resolve().parent.name}/{n}' for b, n in zip(bags, names)]
    for candidate in ([n for n in scenario if n is not None], parents,
                      [f'{s} ({p})' for s, p in zip(scenario, parents) if s is not None]):
        if len(candidate) == len(names) and len(set(candidate)) == len(names):
            return candidate
    return [f'{i + 1}:{n}' for i, n in enumerate(names)]


def _labels(bags: Sequence[Path], labels: str | Sequence[str] | None) -> list[str]:
    if labels is None:
        return default_labels(bags)
    given = [s.strip() for s in labels.split(',')] if isinstance(labels, str) else list(labels)
    if len(given) != len(bags) or not all(given) or len(set(given)) != len(given):
        raise ScenarioError(f'--labels {",".join(given)!r} must give {len(bags)} distinct '
                            f'non-empty labels, one per bag, comma-separated')
    return given


def compare(bags: Sequence[str | Path], *, labels: str | Sequence[str] | None = None,
            out: str | Path | None = None) -> int:
    """Run ``ttb-sim compare``; return the exit code (BagError / ScenarioError: exit 2)."""
    start = time.perf_counter()
    paths = [Path(b) for b in bags]
    if len(paths) < 2:
        raise ScenarioError(f'compare needs at least two bags, got {len(paths)}')
    for p in paths:
        check_bag_path(p)
    names = _labels(paths, labels)
    if out is not None:
        check_output(Path(out))
    from ttb_sim.io.streams import load_streams   # the bag reader, after the checks
    streams = [load_streams(p, label) for p, label in zip(paths, names)]
    if out is None:   # (io.bag imports the stepping core: not for a refusal)
        from ttb_sim.io.bag import default_bag_path
    target = Path(out) if out is not None else default_bag_path('compare')
    check_output(target)
    from ttb_sim.report.figures import write_figures   # scipy and matplotlib: readable bags
    from ttb_sim.report.metrics import bag_metrics, differences
    metrics = [bag_metrics(s) for s in streams]
    rows = differences(names, metrics)
    head = ['metric', *names]
    for other in names[1:]:
        head.extend([f'{other} - {names[0]}', f'relative ({other})'])
    with staged_output(target) as stage:
        written, skipped = write_figures(streams, stage, metrics)
        write_json(stage / 'metrics.json', {
            'bags': dict(zip(names, metrics)),
            'differences': [dict(zip(head, r)) for r in rows],
            'figures': {n.name: n.text for n in written},
            'figures_skipped': {n.name: n.text for n in skipped},
            'analysis_time_s': time.perf_counter() - start})
        with (stage / 'differences.csv').open('w', newline='') as fh:
            writer = csv.writer(fh)
            writer.writerow(head)
            writer.writerows(['' if c is None else c for c in r] for r in rows)
        write_index(stage, f'ttb-sim compare: {" vs ".join(names)}', names,
                    [str(p) for p in paths], metrics, written, skipped,
                    extra=[(f'Differences from {names[0]}', head, rows)])
    if skipped:
        print(f'ttb-sim: skipped {len(skipped)} figures ({", ".join(n.name for n in skipped)}):'
              ' no bag has their streams; reasons in index.html', file=sys.stderr)
    print(f'{target}: {len(written)} figures, differences.csv, metrics.json, index.html '
          f'({time.perf_counter() - start:.1f} s)')
    return EXIT_OK
