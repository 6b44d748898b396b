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
The ``analyze`` verb: one bag -> figures, ``metrics.json`` and ``index.html``.

The bag is read and every metric computed before the output folder is
touched; figures are written into a staging folder renamed into place at the
end (:func:`ttb_sim.report.output.staged_output`), so a failure leaves no
folder that looks complete.

The paths are checked before the bag reader, the analysis (scipy) and the
figures (matplotlib) are imported: a wrong path is refused in a fraction of a
second instead of after seconds of imports.
"""

from __future__ import annotations

import logging
from pathlib import Path
import sys
import time

from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown
from ttb_sim.io.bag_checks import check_bag_path
from ttb_sim.report.output import check_output, staged_output, write_index, write_json

log = logging.getLogger(__name__)

EXIT_OK = 0
MODES_WINDOWS = ('free', 'whole')
"""Windows of the modes section: the free vibration after the train has left, or the whole."""


def default_output(bag: Path) -> Path:
    """Return the default output folder: ``analysis/`` inside the bag directory."""
    return (bag if bag.is_dir() else bag.parent) / 'analysis'


def analyze(bag: str | Path, *, out: str | Path | None = None,
            modes_window: str = 'free') -> int:
    """
    Run ``ttb-sim analyze``; return the exit code.

    ``modes_window`` is the window of the modes section (``free``: the free vibration after
    the train has left the bridge; ``whole``: the whole record;
    :mod:`ttb_sim.commands.analyze_modes`).

    Raises
    ------
    BagError
        When the bag is missing, not a bag, truncated or has no stream to analyse.
    ScenarioError
        When ``out`` cannot be written, or for a ``modes_window`` not in
        :data:`MODES_WINDOWS`.

    """
    start = time.perf_counter()
    if modes_window not in MODES_WINDOWS:
        raise ScenarioError(f'--modes-window {shown(modes_window)}: allowed values are '
                            f'{", ".join(MODES_WINDOWS)}')
    path = Path(bag)
    check_bag_path(path)
    target = Path(out) if out is not None else default_output(path)
    check_output(target)
    from ttb_sim.io.streams import load_streams   # the bag reader, after the checks
    streams = load_streams(path)
    read = time.perf_counter() - start
    from ttb_sim.report.figures import write_figures   # scipy and matplotlib: a readable bag
    from ttb_sim.report.metrics import bag_metrics
    from ttb_sim.commands.analyze_modes import modes_section
    metrics = bag_metrics(streams)
    modes = modes_section(streams, modes_window)
    metrics['modes'] = modes.metrics
    with staged_output(target) as stage:
        written, skipped = write_figures([streams], stage, [metrics])
        if modes.draw is not None:
            written.append(modes.draw(stage))
        metrics['figures'] = {n.name: n.text for n in written}
        metrics['figures_skipped'] = {n.name: n.text for n in skipped}
        metrics['analysis_time_s'] = time.perf_counter() - start
        write_json(stage / 'metrics.json', metrics)
        write_index(stage, f'ttb-sim analyze: {streams.label}', [streams.label], [str(path)],
                    [metrics], written, skipped, extra=[modes.table()])
    elapsed = time.perf_counter() - start
    if skipped:
        print(f'ttb-sim: skipped {len(skipped)} figures ({", ".join(n.name for n in skipped)}):'
              ' the bag lacks their streams; reasons in index.html and metrics.json',
              file=sys.stderr)
    if modes.reason is not None:
        print(f'ttb-sim: modes skipped: {modes.reason}', file=sys.stderr)
    identified = len(modes.metrics.get('identified', []))
    print(f'{target}: {len(written)} figures, metrics.json, index.html '
          f'({len(skipped)} skipped; {identified} modes identified; read {read:.1f} s, total '
          f'{elapsed:.1f} s)')
    return EXIT_OK
