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
Bayesian updating of scenario keys from a recorded passage.

The data are the log10 PSDs of the chosen sensors' channels on the common grid
(:mod:`ttb_sim.twin.features`), the model the :class:`~ttb_sim.twin.forward.ForwardModel`
with ideal sensors, and the link between them the sensors' own noise model:

- **Prediction.** A scenario run with noiseless sensors gives the structure's PSD S(f);
  the sensor adds white noise of one-sided density N = noise_density^2 + q^2 / (6 f_s)
  (q the quantisation step), so the record's PSD is P = S + N.  A Gaussian process
  (scikit-learn, an anisotropic squared-exponential kernel plus a white term, fitted to
  a Sobol' design over the priors) stands in for the runs, so the sampler costs
  milliseconds per step instead of a passage; its own predictive spread and its
  cross-validated error enter the likelihood, and the posterior median is checked by
  one more real run.
- **Likelihood.** log10 of Welch's estimate of P over K half-overlapping segments
  scatters about log10 P with a standard deviation of
  sqrt(2 S N + N^2) / (P sqrt(K) ln 10) for a passage (``response='passage'``: the
  response to the train is deterministic, only the sensor noise is random), or
  1 / (sqrt(K) ln 10) for an ambient record (``response='ambient'``: the response
  itself is a random process, chi-square with 2K degrees of freedom); a model
  discrepancy (``discrepancy``, log10 units) is added in quadrature.
  Grid points closer than two Welch bins (2 / segment) are thinned out, so the points
  used are nearly independent; grid points a channel does not resolve are dropped.
- **Sampler.** emcee's affine-invariant ensemble on the priors' probability scale
  (u = F(theta) in (0, 1), where every prior is uniform), seeded, so the same inputs
  give the same chains bit for bit.  The burn-in is two integrated autocorrelation
  times (at least a fifth of the chain), the thinning half of one; the chain is
  called converged when it is at least 50 autocorrelation times long.
- **Identifiability.** A parameter whose posterior 90 % interval spans more than
  ``flat_ratio`` of its prior's on the probability scale is reported as not
  identified from these data (``identified: false``), whatever its median says.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import logging
import math
from typing import Any, Callable, Sequence
import warnings

import numpy as np

from ttb_sim.config.sensor_records import SensorConfig
from ttb_sim.errors import ScenarioError, SimulationError, TtbSimError
from ttb_sim.twin.design import design_size, DesignRuns, refined_design
from ttb_sim.twin.features import Features, FeatureSpec
from ttb_sim.twin.forward import ForwardModel, Runner
from ttb_sim.twin.priors import Prior, unit_design

__all__ = ['data_grid', 'Identification', 'identify', 'IdentifySettings', 'Observation',
           'Surrogate']

log = logging.getLogger(__name__)

LN10 = math.log(10.0)
RESPONSES = ('passage', 'ambient')
"""What scatters in the data: the sensor noise alone, or the response too."""
CONVERGED_TAUS = 50.0
"""A chain at least this many autocorrelation times long is called converged."""


@dataclass(frozen=True)
class IdentifySettings:
    """How to identify: design size, sampler, seed, discrepancy, flat-posterior threshold."""

    design: int = 0
    """Forward runs of the surrogate's design (0: 8 d + 8 for d parameters)."""
    walkers: int = 0
    """emcee walkers (0: max(16, 4 d))."""
    steps: int = 3000
    seed: int = 0
    discrepancy: float = 0.02
    """Model discrepancy, log10 units (0.02: about 5 % in the PSD)."""
    flat_ratio: float = 0.7
    response: str = 'passage'
    """'passage' (deterministic response plus sensor noise) or 'ambient' (random response)."""
    refine: int = 0
    """Forward runs of a second design over the first posterior's box (0: none)."""

    def __post_init__(self) -> None:
        """Refuse settings that cannot run."""
        checks = [('design', self.design, 0, 10_000), ('walkers', self.walkers, 0, 10_000),
                  ('steps', self.steps, 100, 10_000_000), ('seed', self.seed, 0, 2 ** 32 - 1),
                  ('refine', self.refine, 0, 10_000)]
        for name, value, low, high in checks:
            if not (isinstance(value, int) and low <= value <= high):
                raise ScenarioError(f'--{name} {value!r} must be an integer from {low} to {high}')
        if not (0.0 <= self.discrepancy <= 10.0):
            raise ScenarioError(f'--discrepancy {self.discrepancy!r} must be in [0, 10] '
                                '(log10 units)')
        if self.response not in RESPONSES:
            raise ScenarioError(f'--response {self.response!r}: allowed {", ".join(RESPONSES)}')
        if not (0.0 < self.flat_ratio <= 1.0):
            raise ScenarioError(f'flat_ratio {self.flat_ratio!r} must be in (0, 1]')


def data_grid(record_s: float, sensors: Sequence[SensorConfig], *, fmin: float | None = None,
              fmax: float | None = None, points: int = 48, segment: float | None = None
              ) -> FeatureSpec:
    """
    Return the PSD grid of the data.

    By default: segments of min(2 s, record / 4) (seven half-overlapping ones at
    least), from one bin (1 / segment) to 0.8 of the lowest Nyquist frequency (the
    anti-alias filter's flat band).

    Raises
    ------
    ScenarioError
        For a grid the arguments make empty or out of range (naming the option).

    """
    from ttb_sim.config.schema import from_mapping
    seg = segment if segment is not None else min(2.0, record_s / 4.0)
    nyquist = min(s.rate_hz for s in sensors) / 2.0
    grid = {'psd_fmin_hz': fmin if fmin is not None else 1.0 / seg,
            'psd_fmax_hz': fmax if fmax is not None else 0.8 * nyquist,
            'psd_points': points, 'psd_segment_s': seg}
    spec: FeatureSpec = from_mapping(grid, FeatureSpec, 'features.')
    return spec


def noise_psd(config: SensorConfig) -> float:
    """Return a sensor's white-noise PSD (one-sided, unit^2/Hz): density and quantisation."""
    return config.noise_density ** 2 + config.resolution ** 2 / (6.0 * config.rate_hz)


@dataclass(frozen=True)
class Observation:
    """The recorded passage as the likelihood sees it."""

    log_psd: np.ndarray
    """(m,) log10 PSD of each feature used."""
    noise: np.ndarray
    """(m,) the sensor noise PSD N under each feature."""
    segments: float
    """Welch segments K of the estimate."""
    used: np.ndarray
    """Indices of the features used, into the forward model's vector."""
    names: list[str]

    @classmethod
    def of(cls, model: ForwardModel, features: Features, record_s: float) -> Observation:
        """Select the features to use from a recorded passage's features."""
        vector = model.vector.of(features)
        names = model.feature_names
        per_channel = len(model.vector.frequencies_hz)
        spaced = _spaced(model.vector.frequencies_hz, 2.0 / model.spec.psd_segment_s)
        noise_of = {f'{s.name}.{a}': noise_psd(s) for s in model.sensors
                    for a in s.measured_axes}
        used, noise = [], []
        for c, channel in enumerate(model.vector.channels):
            for j in spaced:
                i = c * per_channel + j
                if np.isfinite(vector[i]):
                    used.append(i)
                    noise.append(noise_of[channel])
        if not used:
            raise ScenarioError('the recorded sensors resolve no point of the PSD grid; lower '
                                '--fmin or give sensors of a higher rate')
        segments = max(1.0, 2.0 * record_s / model.spec.psd_segment_s - 1.0)
        index = np.array(used)
        return cls(vector[index], np.array(noise), segments, index, [names[i] for i in used])

    def observable(self, model_vectors: np.ndarray) -> np.ndarray:
        """Return log10(S + N) of noiseless model vectors (rows), at the features used."""
        s = 10.0 ** model_vectors[..., self.used]
        return np.log10(s + self.noise)

    def measurement_sd(self, predicted: np.ndarray, response: str = 'passage') -> np.ndarray:
        """Return the sd of log10 Welch estimates about ``predicted`` log10 P (rows)."""
        if response == 'ambient':
            return np.full(predicted.shape, 1.0 / (math.sqrt(self.segments) * LN10))
        p = 10.0 ** predicted
        s = np.clip(p - self.noise, 0.0, None)
        spread = np.sqrt(2.0 * s * self.noise + self.noise ** 2)
        return spread / (p * math.sqrt(self.segments) * LN10)


def _spaced(frequencies: np.ndarray, spacing: float) -> list[int]:
    """Return indices of grid points at least ``spacing`` apart, from the lowest."""
    kept: list[int] = []
    for i, f in enumerate(frequencies):
        if not kept or f - frequencies[kept[-1]] >= spacing:
            kept.append(i)
    return kept


class Surrogate:
    """A Gaussian process over the probability-scale design: u -> log10(S + N)."""

    def __init__(self, u: np.ndarray, z: np.ndarray, seed: int) -> None:
        from sklearn.exceptions import ConvergenceWarning
        from sklearn.gaussian_process import GaussianProcessRegressor
        from sklearn.gaussian_process.kernels import ConstantKernel, RBF, WhiteKernel
        d = u.shape[1]
        kernel = ConstantKernel(1.0, (1e-3, 1e3)) * RBF(np.full(d, 0.3), (1e-2, 1e2)) + \
            WhiteKernel(1e-4, (1e-10, 1e-1))
        self.gp = GaussianProcessRegressor(kernel, normalize_y=True, n_restarts_optimizer=3,
                                           random_state=seed)
        with warnings.catch_warnings(record=True) as caught:
            # A length scale at its upper bound is the GP's way of saying the features do
            # not depend on that key: the flat posterior reports it, the warning would not.
            warnings.simplefilter('always', ConvergenceWarning)
            self.gp.fit(u, z)
        for w in caught:
            quiet = issubclass(w.category, ConvergenceWarning)
            log.log(logging.DEBUG if quiet else logging.WARNING, 'surrogate fit: %s', w.message)
        self.cv_rmse = self._cross_validated(u, z)

    def _cross_validated(self, u: np.ndarray, z: np.ndarray, folds: int = 5) -> np.ndarray:
        """Return each output's RMS error predicting held-out design points (kernel fixed)."""
        from sklearn.base import clone
        n = len(u)
        errors = np.zeros_like(z)
        for k in range(min(folds, n)):
            test = np.arange(n) % min(folds, n) == k
            gp = clone(self.gp).set_params(kernel=self.gp.kernel_, optimizer=None)
            gp.fit(u[~test], z[~test])
            errors[test] = gp.predict(u[test]) - z[test]
        return np.sqrt(np.mean(errors ** 2, axis=0))

    def predict(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return the mean and sd of log10(S + N) at probability-scale points (rows)."""
        mean, sd = self.gp.predict(np.atleast_2d(u), return_std=True)
        mean = mean.reshape(len(np.atleast_2d(u)), -1)
        sd = np.asarray(sd).reshape(mean.shape)
        return mean, sd


@dataclass
class Identification:
    """What :func:`identify` found: the posterior, its chains and how they were made."""

    priors: tuple[Prior, ...]
    samples: np.ndarray
    """(n, d) posterior samples of the parameters (after burn-in and thinning)."""
    chain: np.ndarray
    """(steps, walkers, d) the whole chain, parameters."""
    log_prob: np.ndarray
    """(steps, walkers) its log posterior."""
    acceptance: float
    tau: np.ndarray
    """(d,) integrated autocorrelation time of each parameter (steps)."""
    burn: int
    thin: int
    design_theta: np.ndarray
    design_z: np.ndarray
    observation: Observation
    surrogate_cv_rmse: np.ndarray
    check: dict[str, Any] = field(default_factory=dict)
    failed_design: list[str] = field(default_factory=list)
    settings: IdentifySettings = field(default_factory=IdentifySettings)
    median_z: np.ndarray | None = None
    """log10(S + N) of a real run at the posterior median, at the features used."""

    def summary(self) -> dict[str, Any]:
        """Return posterior.json's contents: per key median, q05, q95, ..., and diagnostics."""
        steps = self.chain.shape[0]
        tau_max = float(np.max(self.tau))
        out: dict[str, Any] = {'parameters': {}, 'diagnostics': {
            'walkers': int(self.chain.shape[1]), 'steps': int(steps), 'burn': self.burn,
            'thin': self.thin, 'samples': int(len(self.samples)),
            'acceptance_fraction': self.acceptance,
            'autocorrelation_time': {p.key: float(t) for p, t in zip(self.priors, self.tau)},
            'converged': bool(steps >= CONVERGED_TAUS * tau_max),
            'converged_rule': f'chain length >= {CONVERGED_TAUS:g} autocorrelation times',
            'design_runs': int(len(self.design_theta)), 'failed_design_runs': self.failed_design,
            'features_used': len(self.observation.used),
            'welch_segments': self.observation.segments,
            'surrogate_cv_rmse_log10': {'median': float(np.median(self.surrogate_cv_rmse)),
                                        'max': float(np.max(self.surrogate_cv_rmse))},
            'discrepancy_log10': self.settings.discrepancy,
            'response': self.settings.response,
            'seed': self.settings.seed},
            'check_at_median': self.check}
        u_samples = np.column_stack([_cdf(p, self.samples[:, j])
                                     for j, p in enumerate(self.priors)])
        for j, prior in enumerate(self.priors):
            column = self.samples[:, j]
            q05, q50, q95 = (float(v) for v in np.quantile(column, [0.05, 0.5, 0.95]))
            u05, u95 = np.quantile(u_samples[:, j], [0.05, 0.95])
            ratio = float((u95 - u05) / 0.9)
            identified = ratio <= self.settings.flat_ratio
            out['parameters'][prior.key] = {
                'median': q50, 'q05': q05, 'q95': q95, 'mean': float(np.mean(column)),
                'sd': float(np.std(column)), 'prior': prior.describe(),
                'prior_q05': prior.quantile(np.array([0.05]))[0],
                'prior_q95': prior.quantile(np.array([0.95]))[0],
                'interval_vs_prior': ratio, 'identified': bool(identified),
                'note': '' if identified else (
                    f'not identified from these data: the posterior 90 % interval spans '
                    f"{100 * ratio:.0f} % of the prior's (probability scale); the median "
                    'says little')}
        return out


def _cdf(prior: Prior, values: np.ndarray) -> np.ndarray:
    """Return the prior's CDF at values (the probability scale)."""
    from scipy import stats
    a, b = prior.parameters
    if prior.kind == 'uniform':
        return (values - a) / (b - a)
    if prior.kind == 'normal':
        return stats.norm.cdf(values, loc=a, scale=b)
    return stats.norm.cdf(np.log(values), loc=a, scale=b)


def identify(model: ForwardModel, priors: Sequence[Prior], observed: Features,
             record_s: float, settings: IdentifySettings | None = None,
             progress: Callable[[str], None] | None = None,
             runner: Runner | None = None) -> Identification:
    """
    Update the priors of ``model``'s keys from a recorded passage's features.

    Parameters
    ----------
    model
        The forward model (its keys in the order of ``priors``), with ideal sensors.
    priors
        One numeric prior per key (uniform, normal or lognormal).
    observed
        The recorded passage's features (:func:`~ttb_sim.twin.features.sensor_features`).
    record_s
        The recorded passage's length (s): the Welch segments of its estimate.
    settings
        Design size, sampler, seed, discrepancy.
    progress
        Called with one line per design run, as each finishes.
    runner
        Runs the design (:meth:`ForwardModel.evaluate_many`); default one run after
        another in this process.  Any runner gives the same result bit for bit: the
        design, its order and each run are deterministic.

    Raises
    ------
    ScenarioError
        For a prior that is not numeric, or data with no usable feature.
    SimulationError
        When too few design runs succeed to fit the surrogate.

    """
    settings = settings or IdentifySettings()
    d = len(priors)
    if [p.key for p in priors] != list(model.keys):
        raise ScenarioError('the priors must be those of the model keys, in order')
    for p in priors:
        if p.kind == 'choice':
            raise ScenarioError(f'--param {p.key}: identify takes uniform, normal or lognormal '
                                'priors (a choice has no density to update)')
    observation = Observation.of(model, observed, record_s)
    n_design = design_size(settings.design, d)
    u_design = unit_design(n_design, d, 'sobol', settings.seed)
    runs = DesignRuns(model, priors, runner, progress, n_design + settings.refine)
    runs.run(u_design)
    if len(runs.thetas) < d + 3:
        raise SimulationError(f'only {len(runs.thetas)} of {n_design} design runs succeeded (at '
                              f'least {d + 3} needed): {"; ".join(runs.failed[:3])}')
    fit = _sample(observation, priors, runs, settings)
    if settings.refine:   # a second design over the first posterior's box, then again
        runs.run(refined_design(fit.flat_u, settings.refine, settings.seed))
        fit = _sample(observation, priors, runs, settings)
    samples = np.column_stack([np.array(p.quantile(fit.flat_u[:, j]))
                               for j, p in enumerate(priors)])
    chain = np.stack([np.array(p.quantile(fit.chain_u[:, :, j].ravel())).reshape(
        fit.chain_u.shape[:2]) for j, p in enumerate(priors)], axis=-1)
    result = Identification(tuple(priors), samples, chain, fit.sampler.get_log_prob(),
                            float(np.mean(fit.sampler.acceptance_fraction)), fit.tau,
                            fit.burn, fit.thin, np.array(runs.thetas), fit.z, observation,
                            fit.surrogate.cv_rmse, failed_design=runs.failed, settings=settings)
    result.check, result.median_z = _check_median(model, priors, observation, fit.surrogate,
                                                  samples)
    return result


@dataclass
class _Fit:
    """A surrogate fitted to the design runs and the chain sampled on it."""

    z: np.ndarray
    surrogate: Surrogate
    sampler: Any
    chain_u: np.ndarray
    flat_u: np.ndarray
    tau: np.ndarray
    burn: int
    thin: int


def _sample(observation: Observation, priors: Sequence[Prior], runs: DesignRuns,
            settings: IdentifySettings) -> _Fit:
    """Fit the surrogate to every successful run so far; sample the posterior with emcee."""
    import emcee
    d = len(priors)
    design_theta = np.array(runs.thetas)
    z = observation.observable(np.array(runs.vectors))
    u_ok = np.column_stack([_cdf(p, design_theta[:, j]) for j, p in enumerate(priors)])
    surrogate = Surrogate(u_ok, z, settings.seed)
    y = observation.log_psd
    floor = surrogate.cv_rmse ** 2 + settings.discrepancy ** 2

    def log_posterior(u: np.ndarray) -> np.ndarray:
        u = np.atleast_2d(u)
        inside = np.all((u > 0.0) & (u < 1.0), axis=1)
        out = np.full(len(u), -np.inf)
        if inside.any():
            mean, sd = surrogate.predict(u[inside])
            var = observation.measurement_sd(mean, settings.response) ** 2 + sd ** 2 + floor
            out[inside] = -0.5 * np.sum((y - mean) ** 2 / var + np.log(2 * np.pi * var),
                                        axis=1)
        return out

    walkers = settings.walkers or max(16, 4 * d)
    rng = np.random.default_rng(settings.seed)
    start = rng.uniform(0.05, 0.95, (walkers, d))
    sampler = emcee.EnsembleSampler(walkers, d, log_posterior, vectorize=True)
    sampler.random_state = np.random.RandomState(settings.seed).get_state()
    sampler.run_mcmc(start, settings.steps, progress=False)
    chain_u = sampler.get_chain()
    tau = emcee.autocorr.integrated_time(chain_u, tol=0)
    burn = int(max(settings.steps // 5, 2 * np.max(tau)))
    burn = min(burn, settings.steps - 10)
    thin = max(1, int(np.max(tau) / 2))
    return _Fit(z, surrogate, sampler, chain_u, chain_u[burn::thin].reshape(-1, d),
                np.asarray(tau), burn, thin)


def _check_median(model: ForwardModel, priors: Sequence[Prior], observation: Observation,
                  surrogate: Surrogate, samples: np.ndarray
                  ) -> tuple[dict[str, Any], np.ndarray | None]:
    """Run the model at the posterior median: how far the surrogate was, and the data."""
    median = np.median(samples, axis=0)
    try:
        z = observation.observable(model(median))
    except TtbSimError as exc:
        return {'theta': dict(model.values(median)), 'error': str(exc)}, None
    u = np.array([[float(_cdf(p, np.array([m]))[0]) for p, m in zip(priors, median)]])
    predicted, _ = surrogate.predict(u)
    return {'theta': dict(model.values(median)),
            'rms_run_vs_data_log10': float(np.sqrt(np.mean((z - observation.log_psd) ** 2))),
            'rms_run_vs_surrogate_log10': float(np.sqrt(np.mean((z - predicted[0]) ** 2)))}, z
