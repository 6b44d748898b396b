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
The ``identify`` verb: Bayesian updating of scenario keys from a recorded passage.

``ttb-sim identify BAG --param KEY=uniform:A,B [--param ...] --out DIR
[--scenario SCENARIO] [--set KEY=VALUE ...] [--sensors a,b] [--design N] [--steps N]
[--walkers N] [--seed N] [--discrepancy X] [--fmin HZ] [--fmax HZ] [--points N]
[--segment S] [--refine N] [--workers N | --scheduler ADDRESS]``

The model to update is ``--scenario`` (with ``--set``), or by default the scenario the
bag was recorded from (stored in its metadata by ``ttb-sim run``; a bag recorded
elsewhere needs ``--scenario``).  The data are the bag's sensor topics
(``sensors/<name>`` in any namespace) — ``summary.json`` is never read.  The method
is :mod:`ttb_sim.twin.identify`.  ``DIR`` receives ``posterior.json`` (per key
``median``, ``q05``, ``q95``, ``identified`` and the diagnostics), ``chains.npz``,
``corner.png``, ``trace.png``, ``fit.png`` and ``index.html``; it is written whole
at the end (nothing half-written on an error or a signal).

The design runs go to local worker processes or a Dask cluster
(:mod:`ttb_sim.commands.pool`, as for ``dataset`` and ``sweep``): the command hands
:func:`~ttb_sim.twin.identify.identify` a runner over the pool, so the twin layer
needs no processes of its own.  The result is the same bit for bit whatever the
number of workers; a Ctrl-C stops the workers and writes nothing (exit 128 + signal).
"""

from __future__ import annotations

from pathlib import Path
import re
import sys
import threading
import time
from typing import Any, Sequence

import numpy as np

from ttb_sim.commands.pool import check_workers, make_pool, run_cases
from ttb_sim.commands.signals import signal_name, SignalHandlers, StopFlag, Stopped
from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown

__all__ = ['identify_command', 'parse_param', 'PoolRunner']

EXIT_OK = 0
PARAM = re.compile(r'^(?P<key>[^=]+)=(?P<kind>[a-z]+):(?P<args>.*)$')
FAMILIES = ('uniform', 'normal', 'lognormal')
MAX_PARAMS = 8
MODEL_SCENARIO = 'model_scenario.yaml'
"""The bag's own scenario, as the model loads it (in the output folder)."""


def parse_param(text: str) -> Any:
    """Parse ``--param KEY=uniform:A,B`` (or ``normal:MEAN,SD``, ``lognormal:MU,SIGMA``)."""
    from ttb_sim.twin.priors import parse_prior
    match = PARAM.match(str(text).strip())
    if match is None or match['kind'] not in FAMILIES:
        raise ScenarioError(f'--param {shown(text)}: give KEY=FAMILY:A,B with FAMILY one of '
                            f'{", ".join(FAMILIES)}, e.g. damage.girders[0].loss=uniform:0,0.6')
    values: list[Any] = []
    for part in match['args'].split(','):
        try:
            values.append(float(part))
        except ValueError:
            raise ScenarioError(f'--param {shown(text)}: {part.strip()!r} is not a '
                                'number') from None
    return parse_prior(match['key'].strip(), {match['kind']: values})


def _model_scenario(bag: Path, scenario: str | None, stage: Path) -> str:
    """Return the scenario to update: ``--scenario``, or the bag's own (written to ``stage``)."""
    if scenario is not None:
        return scenario
    from ttb_sim.io.passage import recorded_scenario
    import yaml
    data = recorded_scenario(bag)
    if data is None:
        raise ScenarioError(f'bag {str(bag)!r} does not carry the scenario it was recorded from '
                            '(recorded by ros2 bag record, or by another tool): give the model '
                            'with --scenario NAME_OR_YAML')
    path = stage.resolve() / MODEL_SCENARIO   # the same path for every worker
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding='utf-8')
    return str(path)


def identify_command(bag: str | Path, params: Sequence[str], *, out: str | Path | None,
                     scenario: str | None = None, overrides: Sequence[str] = (),
                     sensors: str | None = None, design: int = 0, steps: int = 3000,
                     walkers: int = 0, seed: int = 0, discrepancy: float = 0.02,
                     fmin: float | None = None, fmax: float | None = None, points: int = 48,
                     segment: float | None = None, response: str = 'passage',
                     workers: int | None = None, scheduler: str | None = None,
                     refine: int = 0) -> int:
    """Run ``ttb-sim identify``; return the exit code."""
    from ttb_sim.io.bag_checks import check_bag_path
    from ttb_sim.report.output import staged_output
    from ttb_sim.twin.identify import IdentifySettings
    start = time.perf_counter()
    path = Path(bag)
    check_workers(workers, scheduler)
    if not params:
        raise ScenarioError('give at least one --param KEY=FAMILY:A,B to identify')
    if len(params) > MAX_PARAMS:
        raise ScenarioError(f'{len(params)} --param given; at most {MAX_PARAMS}')
    priors = [parse_param(p) for p in params]
    keys = [p.key for p in priors]
    if len(set(keys)) != len(keys):
        raise ScenarioError(f'--param names a key twice ({", ".join(keys)})')
    settings = IdentifySettings(design=design, walkers=walkers, steps=steps, seed=seed,
                                discrepancy=discrepancy, response=response, refine=refine)
    check_bag_path(path)
    target = Path(out) if out is not None else \
        (path if path.is_dir() else path.parent) / 'identify'
    _check_out(target)
    try:
        with SignalHandlers() as handlers, staged_output(target) as stage:
            if threading.current_thread() is threading.main_thread():
                handlers.install(STOP)   # a flag, read between the stages (never raised
                # inside a library call, which could swallow it)
            summary = _identify(path, stage, scenario, overrides, keys, sensors, fmin, fmax,
                                points, segment, priors, settings, workers, scheduler, start,
                                target)
    except Stopped as stop:
        print(f'ttb-sim: stopped by {signal_name(stop.signum)}; nothing written',
              file=sys.stderr)
        return 128 + stop.signum
    _report(target, summary)
    return EXIT_OK


def _identify(path: Path, stage: Path, scenario: str | None, overrides: Sequence[str],
              keys: Sequence[str], sensors: str | None, fmin: float | None,
              fmax: float | None, points: int, segment: float | None, priors: Sequence[Any],
              settings: Any, workers: int | None, scheduler: str | None,
              start: float, target: Path) -> dict[str, Any]:
    """Set up, run the design on the pool, sample; write the files; return the summary."""
    from ttb_sim.twin.identify import identify
    model, observed, record = _set_up(path, stage, scenario, overrides, keys, sensors,
                                      fmin, fmax, points, segment, priors)
    stop_if_asked()
    from ttb_sim.twin.design import design_size
    n_design = design_size(settings.design, len(keys))
    print(f'ttb-sim: identify: {len(keys)} parameter(s) from {len(model.sensors)} '
          f'sensor(s), {record:.3g} s recorded; design of {n_design} runs'
          + (f', then {settings.refine} over the first posterior' if settings.refine else ''),
          file=sys.stderr)
    result = identify(model, priors, observed, record, settings,
                      progress=lambda line: print(f'ttb-sim: identify: {line}',
                                                  file=sys.stderr, flush=True),
                      runner=PoolRunner(workers, scheduler))
    summary = result.summary()
    staged = Path(model.scenario) == stage.resolve() / MODEL_SCENARIO
    summary.update(bag=str(path), scenario=str(target / MODEL_SCENARIO) if staged else
                   model.scenario, overrides=list(model.overrides),
                   sensors=[s.name for s in model.sensors],
                   features=result.observation.names,
                   psd_grid={'fmin_hz': model.spec.psd_fmin_hz,
                             'fmax_hz': model.spec.psd_fmax_hz,
                             'points': model.spec.psd_points,
                             'segment_s': model.spec.psd_segment_s},
                   wall_time_s=time.perf_counter() - start)
    stop_if_asked()
    _write(stage, path, result, summary)
    return summary


class PoolRunner:
    """
    The design runs of :func:`~ttb_sim.twin.identify.identify` on the pool of ``dataset``.

    A runner of :meth:`~ttb_sim.twin.forward.ForwardModel.evaluate_many`: local worker
    processes (``workers``; default one per core, at most one per run; each runs its
    kernels on one thread when there are several) or a Dask cluster (``scheduler``).
    A pool per design (its workers end with it).  A signal stops the workers and raises
    :class:`~ttb_sim.commands.signals.Stopped`.
    """

    def __init__(self, workers: int | None = None, scheduler: str | None = None) -> None:
        check_workers(workers, scheduler)
        self.workers, self.scheduler = workers, scheduler

    def __call__(self, runs: Sequence[Any], on_record: Any) -> None:
        """Run the runs on a new pool, handing each record to ``on_record`` as it finishes."""
        from ttb_sim.twin.forward import run_design
        stop_if_asked()
        pool = make_pool(run_design, len(runs), self.workers, self.scheduler)

        def take(run: Any, record: dict[str, Any]) -> None:
            on_record(run, record)
            stop_if_asked()   # a signal during the submission: stop at the first record
        stop = run_cases(pool, runs, _lost, 'identify', take, case_lines=False)
        if stop is not None:   # run_cases stopped the pool
            raise stop


STOP = StopFlag()
STOP.setup = False   # a signal sets the flag; stop_if_asked raises it where it is safe


def stop_if_asked() -> None:
    """Raise :class:`Stopped` if SIGINT or SIGTERM arrived (and clear the flag)."""
    signum, STOP.signal = STOP.signal, None
    if signum is not None:
        raise Stopped(signum)


def _lost(run: Any, error: BaseException) -> dict[str, Any]:
    """Return the failed record of a design run whose worker died."""
    return {'status': 'failed', 'error': f'worker lost: {type(error).__name__}: {error}'}


def _check_out(target: Path) -> None:
    """Refuse an output folder that holds something else than an earlier identification."""
    if target.exists() and not target.is_dir():
        raise ScenarioError(f'--out {str(target)!r} is a file; give a folder')
    if target.is_dir() and any(target.iterdir()) and not (target / 'posterior.json').is_file():
        raise ScenarioError(f'--out {str(target)!r} is a non-empty folder that is not an '
                            'earlier identification (no posterior.json); give a new folder')


def _set_up(path: Path, stage: Path, scenario: str | None, overrides: Sequence[str],
            keys: Sequence[str], sensors: str | None, fmin: float | None,
            fmax: float | None, points: int, segment: float | None,
            priors: Sequence[Any]) -> tuple[Any, Any, float]:
    """Build the forward model and read the data (every check before a run)."""
    from ttb_sim.config import load_scenario
    from ttb_sim.twin.features import record_length, sensor_features
    from ttb_sim.twin.forward import ForwardModel
    from ttb_sim.twin.identify import data_grid
    source = _model_scenario(path, scenario, stage)
    base = load_scenario(source, overrides)
    for prior in priors:   # each key, at its prior's 5 % and 95 % points
        for u in (0.05, 0.95):
            load_scenario(source, overrides, [(prior.key, prior.quantile(np.array([u]))[0])])
    names = [n.strip() for n in sensors.split(',')] if sensors else None
    chosen = _in_bag(path, base.all_sensors, names)
    record = record_length(path, chosen)
    spec = data_grid(record, chosen, fmin=fmin, fmax=fmax, points=points, segment=segment)
    model = ForwardModel(source, keys, overrides=overrides, features=spec,
                         sensors=[s.name for s in chosen], noise=False)
    return model, sensor_features(path, model.sensors, spec), record


def _in_bag(path: Path, sensors: Sequence[Any], names: Sequence[str] | None) -> list[Any]:
    """Return the chosen sensors (all with a topic in the bag by default)."""
    from ttb_sim.io.reader import bag_topics
    topics = bag_topics(path)

    def recorded(name: str) -> bool:
        return any(t == f'sensors/{name}' or t.endswith(f'/sensors/{name}') for t in topics)
    by_name = {s.name: s for s in sensors}
    if names is not None:
        for n in names:
            if n not in by_name:
                raise ScenarioError(f'--sensors: no sensor {n!r} in the model scenario; it has '
                                    f'{", ".join(by_name) or "none"}')
            if not recorded(n):
                raise ScenarioError(f'--sensors: the bag has no topic sensors/{n}')
        return [by_name[n] for n in names]
    chosen = [s for s in sensors if recorded(s.name)]
    if not chosen:
        raise ScenarioError(f'bag {str(path)!r} has no topic of the sensors of the model '
                            f'({", ".join(by_name) or "the model has none"})')
    return chosen


def _write(stage: Path, bag: Path, result: Any, summary: dict[str, Any]) -> None:
    """Write posterior.json, chains.npz and the figures into the staging folder."""
    from ttb_sim.report.identify_report import (corner_figure, fit_figure, trace_figure,
                                                write_identify_index)
    from ttb_sim.report.output import write_json
    labels = [p.key for p in result.priors]
    np.savez_compressed(stage / 'chains.npz', chain=result.chain, log_prob=result.log_prob,
                        samples=result.samples, design_theta=result.design_theta,
                        design_features=result.design_z, observed=result.observation.log_psd,
                        keys=np.array(labels))
    written = [corner_figure(stage / 'corner.png', result.samples, labels),
               trace_figure(stage / 'trace.png', result.chain, labels, result.burn),
               fit_figure(stage / 'fit.png', result.observation.names,
                          result.observation.log_psd, result.design_z, result.median_z)]
    write_json(stage / 'posterior.json', summary)
    write_identify_index(stage, str(bag), summary, written)


def _report(target: Path, summary: dict[str, Any]) -> None:
    """Print the posterior table to stdout."""
    for key, p in summary['parameters'].items():
        flag = '' if p['identified'] else '  (NOT identified: flat posterior)'
        print(f'{key}: median {p["median"]:.6g}, 90 % interval [{p["q05"]:.6g}, '
              f'{p["q95"]:.6g}]{flag}')
    d = summary['diagnostics']
    print(f'{target}: posterior.json, chains.npz, corner.png, trace.png, fit.png, index.html '
          f'(acceptance {d["acceptance_fraction"]:.2f}, converged: {d["converged"]}; '
          f'{summary["wall_time_s"]:.1f} s)')
