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
The forward model of a twin pipeline: parameters in, a passage's features out.

.. code-block:: python

    from ttb_sim.twin import ForwardModel

    model = ForwardModel('moving_force_beam', ['bridge.bending_stiffness'],
                         overrides=['sensor_layouts=[span:1]'])
    x = model([2.0e10])            # the feature vector (numpy), e.g. for sbi or emcee
    names = model.feature_names    # what each entry is

A case is the scenario with the overrides, then the parameter values (any scenario
key, indexed list keys included), run to a bag in a scratch folder and reduced to
its sensors' features by :func:`~ttb_sim.twin.features.sensor_features` — the same
definition ``ttb-sim dataset`` and ``ttb-sim identify`` use on recorded bags.  What a
parameter does not change is not rebuilt: the model's compiled kernels stay
compiled in the process, and the reduced pile-soil operators are cached on disk by
a hash of their inputs (:mod:`ttb_sim.model.foundation.operator_cache`), so a
parameter of the girders, bearings, train or environment reuses the substructure's
basis; a parameter of the soil or piles builds it once per new value.

Many cases: :meth:`ForwardModel.evaluate_many` runs one :class:`DesignRun` per row
of ``theta`` through a *runner*, by default one after another in this process.  A
runner is any function that runs the picklable :class:`DesignRun` records with the
top-level :func:`run_design` (in worker processes, on a cluster) and hands each
record back as it finishes, in any order: the records come back in the order of the
rows, and :func:`run_design` is deterministic, so the results do not depend on the
runner.  ``ttb-sim identify --workers/--scheduler`` passes the pool of
:mod:`ttb_sim.commands.pool` this way (the twin layer stays free of processes,
signals and Dask).

The feature vector is, per channel (``<sensor>.<axis>``, in the sensors' order),
log10 of its PSD at the grid points every channel resolves (below the lowest
sensor Nyquist frequency), then, when asked, its RMS: a log spectrum is what the
likelihood of :mod:`ttb_sim.twin.identify` treats as Gaussian.
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
from pathlib import Path
import tempfile
import time
from typing import Any, Callable, Sequence

import numpy as np

from ttb_sim.errors import ScenarioError, SimulationError, TtbSimError
from ttb_sim.twin.features import Features, FeatureSpec

__all__ = ['DesignRun', 'evaluate_many', 'FeatureVector', 'ForwardModel', 'in_process',
           'noiseless',
           'OnRecord', 'run_design', 'Runner']

log = logging.getLogger(__name__)

PSD_FLOOR = 1e-30
"""Added to a PSD before its logarithm (a channel that reads exactly zero)."""


@dataclass(frozen=True)
class FeatureVector:
    """Which features make the vector, and their order."""

    channels: tuple[str, ...]
    """``<sensor>.<axis>`` of each channel, in order."""
    frequencies_hz: np.ndarray
    """The PSD grid points kept (every channel resolves them)."""
    rms: bool = False

    @property
    def names(self) -> list[str]:
        """Return the name of each entry: ``log10_psd.<channel>@<f>Hz``, ``rms.<channel>``."""
        out = [f'log10_psd.{c}@{f:.4g}Hz' for c in self.channels for f in self.frequencies_hz]
        if self.rms:
            out += [f'rms.{c}' for c in self.channels]
        return out

    def of(self, features: Features) -> np.ndarray:
        """Return the vector of a case's features."""
        keep = np.isin(features.frequencies_hz, self.frequencies_hz)
        parts = [np.log10(np.asarray(features.psd[c])[keep] + PSD_FLOOR) for c in self.channels]
        if self.rms:
            parts.append(np.array([features.scalars[f'{c}.rms'] for c in self.channels]))
        return np.concatenate(parts) if parts else np.zeros(0)


class ForwardModel:
    """
    A scenario as a function of some of its keys: ``model(theta) -> features``.

    Parameters
    ----------
    scenario
        A built-in name or a YAML path.
    keys
        The scenario keys ``theta`` sets, in order.
    overrides
        ``KEY=VALUE`` strings applied before ``theta``.
    features
        The PSD grid and segment length.
    sensors
        The names of the sensors whose channels make the vector (default: all).
    rms
        Also put each channel's RMS in the vector.
    storage
        The scratch bags' storage.
    noise
        False: the sensors record without noise, bias, quantisation, clipping or
        dropouts (their filter, rate and clock kept): the prediction to which a
        likelihood adds the sensors' noise model (:mod:`ttb_sim.twin.identify`).

    Raises
    ------
    ScenarioError
        If the scenario, a key or a sensor name is refused, or the scenario has no
        sensors (checked at once, with the scenario as it is).

    """

    def __init__(self, scenario: str | Path, keys: Sequence[str], *,
                 overrides: Sequence[str] = (), features: FeatureSpec | None = None,
                 sensors: Sequence[str] | None = None, rms: bool = False,
                 storage: str = 'mcap', noise: bool = True) -> None:
        from ttb_sim.config import load_scenario
        self.scenario = str(scenario)
        self.keys = tuple(keys)
        self.overrides = tuple(overrides)
        self.spec = features or FeatureSpec()
        self.storage = storage
        self.noise = noise
        base = load_scenario(self.scenario, self.overrides)
        if base.substructure_only:
            raise ScenarioError(f'scenario {self.scenario!r} runs the pile-soil substructure '
                                'alone; a forward model needs passages')
        self.sensors = _chosen(base.all_sensors, sensors)
        channels = tuple(f'{s.name}.{a}' for s in self.sensors for a in s.measured_axes)
        nyquist = min(s.rate_hz / 2.0 for s in self.sensors)
        grid = self.spec.frequencies()
        self.vector = FeatureVector(channels, grid[grid <= nyquist], rms)
        if len(self.vector.names) == 0:
            raise ScenarioError('the forward model has no features: give features.psd_points '
                                "> 0 below the sensors' Nyquist frequency, or rms=True")
        self.evaluations = 0

    @property
    def feature_names(self) -> list[str]:
        """Return the name of each entry of the vector."""
        return self.vector.names

    def values(self, theta: Sequence[float] | np.ndarray) -> list[tuple[str, Any]]:
        """Return the ``(key, value)`` settings of ``theta``."""
        theta = np.atleast_1d(np.asarray(theta, dtype=float))
        if theta.shape != (len(self.keys),):
            raise ValueError(f'theta has shape {theta.shape}; the model takes '
                             f'{len(self.keys)} values ({", ".join(self.keys)})')
        return [(k, float(v)) for k, v in zip(self.keys, theta)]

    def simulate(self, theta: Sequence[float] | np.ndarray, bag: Path | None = None
                 ) -> Features:
        """
        Run one case and return its features; ``bag`` keeps its bag there.

        Raises
        ------
        ScenarioError
            If a value of ``theta`` is refused by the scenario.
        SimulationError
            If the run diverged or failed.

        """
        from ttb_sim.io.passage import run_to_bag
        from ttb_sim.config import load_scenario
        from ttb_sim.sim import Simulation
        from ttb_sim.twin.features import sensor_features
        scenario = load_scenario(self.scenario, self.overrides, self.values(theta))
        if not self.noise:
            scenario = noiseless(scenario)
        with tempfile.TemporaryDirectory(prefix='ttb-sim-forward-') as scratch:
            where = bag if bag is not None else Path(scratch) / 'bag'
            result = run_to_bag(scenario, where, self.storage, simulation=Simulation(scenario))
            if result.status != 'ok':
                raise SimulationError(f'the case {dict(self.values(theta))} {result.status}: '
                                      f'{result.summary.get("message", "")}')
            self.evaluations += 1
            return sensor_features(where, self.sensors, self.spec)

    def __call__(self, theta: Sequence[float] | np.ndarray) -> np.ndarray:
        """Return the feature vector at ``theta`` (a 2-D ``theta``: one row per case)."""
        array = np.asarray(theta, dtype=float)
        if array.ndim == 2:
            return np.stack([self(row) for row in array])
        return self.vector.of(self.simulate(array))

    def evaluate_many(self, thetas: Sequence[Sequence[float]] | np.ndarray,
                      runner: Runner | None = None,
                      on_record: OnRecord | None = None) -> list[dict[str, Any]]:
        """
        Run one case per row of ``thetas``; return their records in the order of the rows.

        Parameters
        ----------
        thetas
            (n, d) parameter values, one case per row.
        runner
            Runs the :class:`DesignRun` records with :func:`run_design` and hands each
            ``(run, record)`` to its callback as it finishes (default :func:`in_process`).
        on_record
            Called with each ``(run, record)`` as it finishes (progress).

        Returns
        -------
        list of dict
            Per row: ``status`` ('ok' with ``vector``, or 'failed' with ``error``) and
            ``wall_time_s``.  A failing case is recorded and the others go on.

        """
        rows = np.atleast_2d(np.asarray(thetas, dtype=float))
        for row in rows:
            self.values(row)   # the shape, before any run
        return evaluate_many(self, rows, runner, on_record)


@dataclass(frozen=True)
class DesignRun:
    """One case of :meth:`ForwardModel.evaluate_many`: picklable, for any process."""

    name: str
    """``design007``: unique in its design."""
    index: int
    """Its row in the design."""
    model: Callable[[np.ndarray], np.ndarray]
    """The model (a :class:`ForwardModel`): ``model(theta)`` is the run."""
    theta: tuple[float, ...]


OnRecord = Callable[[DesignRun, dict[str, Any]], None]
"""Takes a finished run and its record."""
Runner = Callable[[Sequence[DesignRun], OnRecord], None]
"""Runs the runs with :func:`run_design`, handing each record on as it finishes."""


def run_design(run: DesignRun) -> dict[str, Any]:
    """
    Run one case; return its record (never raises for a case the model refuses).

    ``status`` 'ok' with ``vector`` (the feature vector), or 'failed' with ``error``
    (a value the scenario refuses, a run that diverged); and ``wall_time_s``.
    """
    start = time.perf_counter()
    try:
        vector = run.model(np.array(run.theta))
    except TtbSimError as exc:   # a case refused or diverged: recorded, the others go on
        return {'status': 'failed', 'error': str(exc),
                'wall_time_s': time.perf_counter() - start}
    return {'status': 'ok', 'vector': vector, 'wall_time_s': time.perf_counter() - start}


def evaluate_many(model: Callable[[np.ndarray], np.ndarray],
                  thetas: Sequence[Sequence[float]] | np.ndarray, runner: Runner | None = None,
                  on_record: OnRecord | None = None, first: int = 0) -> list[dict[str, Any]]:
    """
    Run ``model`` at each row of ``thetas``; return the records in the order of the rows.

    :meth:`ForwardModel.evaluate_many` for any model (a function of ``theta``;
    picklable for a runner in other processes).  The runs are named from
    ``design{first:03d}`` on (a second design goes on from the first's count).
    """
    rows = np.atleast_2d(np.asarray(thetas, dtype=float))
    runs = [DesignRun(f'design{first + i:03d}', i, model, tuple(float(v) for v in row))
            for i, row in enumerate(rows)]
    records: dict[int, dict[str, Any]] = {}

    def take(run: DesignRun, record: dict[str, Any]) -> None:
        records[run.index] = record
        if on_record is not None:
            on_record(run, record)
    (runner or in_process)(runs, take)
    missing = [r.name for r in runs if r.index not in records]
    if missing:
        raise SimulationError(f'the runner returned no record for {", ".join(missing)}')
    return [records[r.index] for r in runs]


def in_process(runs: Sequence[DesignRun], on_record: OnRecord) -> None:
    """Run the runs one after another in this process (the default runner)."""
    for run in runs:
        on_record(run, run_design(run))


def noiseless(scenario: Any) -> Any:
    """Return the scenario with every sensor ideal but for its filter, rate and clock."""
    import dataclasses
    ideal = tuple(dataclasses.replace(
        c, noise_density=0.0, bias=0.0, bias_walk=0.0, resolution=0.0, full_scale=0.0,
        dropout_probability=0.0) for c in scenario.all_sensors)
    return dataclasses.replace(scenario, sensors=ideal, sensor_layouts=())


def _chosen(sensors: Sequence[Any], names: Sequence[str] | None) -> list[Any]:
    """Return the named sensors (all by default); ScenarioError for an unknown name."""
    if not sensors:
        raise ScenarioError('the scenario has no sensors: add a sensors list or '
                            "sensor_layouts (e.g. --set 'sensor_layouts=[span:1]')")
    if names is None:
        return list(sensors)
    by_name = {s.name: s for s in sensors}
    unknown = [n for n in names if n not in by_name]
    if unknown:
        raise ScenarioError(f'--sensors {",".join(names)}: no sensor {unknown[0]!r} in the '
                            f'scenario; it has {", ".join(by_name)}')
    return [by_name[n] for n in names]
