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
Operational modal analysis: modes identified from response records, paired with a model's.

The identification is the data-driven stochastic subspace method (SSI-data, Van Overschee &
De Moor 1996, reference-based form of Peeters & De Roeck 1999) of the ``strid`` library
(ISC licence): :func:`identify_modes` runs it at every even model order up to
``max_order``, keeps the physical poles (positive frequency inside the band, damping
between 0 and :data:`MAX_DAMPING`), marks a pole *stable* where the previous order has one
within :class:`Stability` (frequency 1 %, damping 5 %, 1 - MAC 2 %: strid's own
stabilisation criteria), and clusters the stable poles (``scipy.cluster.hierarchy``,
average linkage on the distance |f_a - f_b| / max(f_a, f_b) + 1 - MAC_ab). A cluster of at
least :data:`MIN_POLES_FRACTION` of the orders is a mode: the median frequency and damping
of its poles, their spread, and the shape of the pole nearest the median frequency
(rotated to its largest real part, largest component +1).

SSI-data rather than covariance-driven SSI: on a free decay (the bridge after the train
has left) the output correlations are those of a transient, and the covariance estimate's
1 / (N - lag) normalisation biases the damping low (measured 5 % low on the V27 decay
against 1 % for SSI-data); SSI-data projects the data themselves and holds for a free
decay and for ambient records alike.

:func:`pair_modes` pairs each identified mode with a model mode (frequency, damping and
shape at the same channels, e.g. ``ttb-sim modes`` of the structure) within
:data:`PAIR_WINDOW` in frequency and of MAC >= ``min_mac``: the one-to-one assignment of
least total distance 1 - MAC + |ln(f / f_model)|; where the model gives no shape at two
channels or more, the nearest frequency.

Nothing here reads a bag or builds a model: records in, modes out.
"""

from __future__ import annotations

from dataclasses import dataclass
import importlib
import logging
import math
from typing import Any, Sequence

import numpy as np

__all__ = ['IdentificationError', 'Identification', 'IdentifiedMode', 'identify_modes',
           'mac', 'MAX_DAMPING', 'MIN_CHANNELS', 'ModelMode', 'ModePair', 'pair_modes',
           'Pole', 'Stability', 'unit_shapes']

log = logging.getLogger(__name__)

MIN_CHANNELS = 2
"""Fewest channels identified: one channel gives no shape to tell modes apart (MAC 1)."""
MAX_DAMPING = 0.2
"""Poles with more damping than this are taken as noise, not structural modes."""
MIN_POLES_FRACTION = 0.25
"""A cluster of stable poles is a mode when it holds at least this fraction of the orders."""
CLUSTER_DISTANCE = 0.05
"""Average-linkage cut of the pole distance |df| / f + 1 - MAC."""
HANKEL_COLUMNS_PER_ROW = 2.0
"""The block Hankel matrix has at least this many columns per row (a well-posed projection)."""
PAIR_WINDOW = 0.2
"""Relative frequency window of a pair: a few channels cannot tell modes far apart by shape
(spatial aliasing: four accelerometers on one of ten spans see a 27 Hz mode and a 13 Hz
one alike, MAC 0.9995), so a pair is sought only within 20 % of the identified frequency."""
INADMISSIBLE = 1e6
"""Cost of a pair outside the window or below the least MAC in the assignment."""
UNSEEN_RATIO = 1e-6
"""A model shape this much smaller at the channels than the largest mode's is not seen."""
DEFAULT_MAX_ORDER = 40
"""Highest model order of the stabilisation diagram (20 conjugate pairs)."""
DEFAULT_LOWEST_HZ = 1.0
"""Lowest frequency of interest: the block rows span half its period when the data allow."""


class IdentificationError(ValueError):
    """The records cannot be identified (too few channels, too short); the text says why."""


@dataclass(frozen=True)
class Stability:
    """Tolerances between a pole and one of the previous order for it to be stable."""

    frequency: float = 0.01
    """|f - f_prev| / f_prev."""
    damping: float = 0.05
    """|zeta - zeta_prev| / zeta_prev."""
    mac: float = 0.02
    """1 - MAC(shape, shape_prev)."""


@dataclass(frozen=True)
class Pole:
    """One physical pole of one model order."""

    order: int
    frequency_hz: float
    """Undamped natural frequency |lambda| / 2 pi."""
    damping_ratio: float
    """-Re(lambda) / |lambda|."""
    shape: np.ndarray
    """(channels,) complex, unit 2-norm."""
    stable: bool


@dataclass(frozen=True)
class IdentifiedMode:
    """A mode identified from a cluster of stable poles."""

    frequency_hz: float
    """Median frequency of the cluster's poles."""
    damping_ratio: float
    """Median damping ratio of the cluster's poles."""
    frequency_std_hz: float
    """Standard deviation of the poles' frequencies."""
    damping_std: float
    """Standard deviation of the poles' damping ratios."""
    shape: np.ndarray
    """(channels,) real: the shape of the pole nearest the median, largest component +1."""
    phase_collinearity: float
    """Modal phase collinearity of that shape (1 = a real, classically damped mode)."""
    poles: int
    """Stable poles in the cluster."""


@dataclass(frozen=True)
class Identification:
    """The result of :func:`identify_modes`: the stabilisation diagram and the modes."""

    rate_hz: float
    samples: int
    channels: int
    block_rows: int
    orders: tuple[int, ...]
    band_hz: tuple[float, float]
    poles: tuple[Pole, ...]
    modes: tuple[IdentifiedMode, ...]


@dataclass(frozen=True)
class ModelMode:
    """A model mode to pair with: frequency, damping and shape at the identified channels."""

    frequency_hz: float
    damping_ratio: float
    shape: np.ndarray | None = None
    """(channels,) real; NaN where the model has no value at a channel; None: no shape."""


@dataclass(frozen=True)
class ModePair:
    """An identified mode and the model mode it is paired with (None: no model mode)."""

    identified: int
    """Index into the identification's modes."""
    model: int | None
    """Index into the model modes, or None."""
    mac: float | None
    """MAC of the pair (None without shapes); unpaired: the best MAC within the window."""
    frequency_difference: float | None
    """(f_identified - f_model) / f_model."""
    damping_difference: float | None
    """(zeta_identified - zeta_model) / zeta_model (None for an undamped model mode)."""


def _strid() -> Any:
    """Return the strid module (imported on first use; it imports matplotlib)."""
    try:
        return importlib.import_module('strid')
    except ImportError:
        raise IdentificationError("operational modal analysis needs the 'strid' package: "
                                  "pip install 'ttb_sim[oma]'") from None


def mac(a: np.ndarray, b: np.ndarray) -> float:
    """Return the modal assurance criterion of two shapes (strid's), over their finite entries."""
    keep = np.isfinite(a) & np.isfinite(b)
    u, v = np.asarray(a)[keep], np.asarray(b)[keep]
    if u.size == 0 or not np.any(u) or not np.any(v):
        return 0.0
    return float(np.real(_strid().modal_assurance_criterion(u, v)))


def block_rows_for(samples: int, channels: int, rate: float, *, max_order: int,
                   lowest_hz: float) -> int:
    """
    Return the block rows of SSI-data for a record, or raise why it is too short.

    Half a period of ``lowest_hz`` when the record allows, at least ``max_order / channels``
    (strid's order <= block_rows x references), and at most what leaves
    :data:`HANKEL_COLUMNS_PER_ROW` columns per row of the block Hankel matrix.

    Raises
    ------
    IdentificationError
        When even the fewest block rows leave too few columns.

    """
    floor = math.ceil(max_order / channels)
    ceiling = int(samples // (2.0 * (1.0 + HANKEL_COLUMNS_PER_ROW * channels)))
    if ceiling < floor:
        need = math.ceil(2.0 * floor * (1.0 + HANKEL_COLUMNS_PER_ROW * channels))
        raise IdentificationError(
            f'{samples} samples ({samples / rate:.2f} s at {rate:g} Hz) of {channels} channels '
            f'are too few for model orders up to {max_order}: at least {need} samples '
            f'({need / rate:.2f} s) are needed')
    wanted = math.ceil(rate / (2.0 * lowest_hz))
    return int(min(max(wanted, floor), ceiling))


def _rounded_shape(v: np.ndarray) -> np.ndarray:
    """Return a complex shape rotated to its largest real part, real, largest component +1."""
    angles = np.linspace(0.0, math.pi, 181)
    rotated = v[None, :] * np.exp(-1j * angles)[:, None]
    best = rotated[int(np.argmax(np.linalg.norm(rotated.real, axis=1)))].real
    k = int(np.argmax(np.abs(best)))
    return best / best[k] if best[k] else best


def _physical(strid: Any, a: np.ndarray, c: np.ndarray, rate: float, order: int,
              band: tuple[float, float], max_damping: float) -> list[Pole]:
    out = []
    for mode in strid.Mode.find_modes_from_ss(a, c, rate):
        lam = complex(mode.eigenvalue)
        if not (lam.imag > 0.0 and lam.real < 0.0 and np.all(np.isfinite(mode.v))):
            continue
        f, zeta = abs(lam) / (2.0 * math.pi), -lam.real / abs(lam)
        if band[0] <= f <= band[1] and 0.0 < zeta <= max_damping:
            out.append(Pole(order, f, zeta, np.asarray(mode.v), False))
    return out


def _mark_stable(by_order: list[list[Pole]], tol: Stability) -> list[Pole]:
    """Return every pole, stable where the previous order has a pole within ``tol``."""
    out: list[Pole] = list(by_order[0])
    for previous, current in zip(by_order[:-1], by_order[1:]):
        for p in current:
            stable = any(abs(p.frequency_hz - q.frequency_hz) < tol.frequency * q.frequency_hz
                         and abs(p.damping_ratio - q.damping_ratio) < tol.damping * q.damping_ratio
                         and 1.0 - mac(p.shape, q.shape) < tol.mac for q in previous)
            out.append(Pole(p.order, p.frequency_hz, p.damping_ratio, p.shape, stable))
    return out


def _clusters(stable: list[Pole]) -> list[list[Pole]]:
    """Group stable poles by average linkage on |df| / f + 1 - MAC."""
    from scipy.cluster.hierarchy import fcluster, linkage

    if len(stable) < 2:
        return [stable] if stable else []
    f = np.array([p.frequency_hz for p in stable])
    shapes = np.array([p.shape for p in stable])
    gram = np.abs(shapes.conj() @ shapes.T) ** 2
    norms = np.real(np.einsum('ij,ij->i', shapes.conj(), shapes))
    macs = gram / np.outer(norms, norms)
    distance = np.abs(f[:, None] - f[None, :]) / np.maximum(f[:, None], f[None, :]) + 1.0 - macs
    np.fill_diagonal(distance, 0.0)
    upper = distance[np.triu_indices(len(stable), 1)]
    labels = fcluster(linkage(np.clip(upper, 0.0, None), method='average'), CLUSTER_DISTANCE,
                      criterion='distance')
    return [[p for p, lab in zip(stable, labels) if lab == k] for k in np.unique(labels)]


def _mode_of(strid: Any, cluster: list[Pole]) -> IdentifiedMode:
    f = np.array([p.frequency_hz for p in cluster])
    zeta = np.array([p.damping_ratio for p in cluster])
    median = float(np.median(f))
    nearest = cluster[int(np.argmin(np.abs(f - median)))]
    return IdentifiedMode(median, float(np.median(zeta)), float(np.std(f)), float(np.std(zeta)),
                          _rounded_shape(nearest.shape),
                          float(strid.modal_phase_collinearity(nearest.shape)), len(cluster))


def identify_modes(values: np.ndarray, rate: float, *, max_order: int = DEFAULT_MAX_ORDER,
                   block_rows: int | None = None, lowest_hz: float = DEFAULT_LOWEST_HZ,
                   highest_hz: float | None = None, max_damping: float = MAX_DAMPING,
                   stability: Stability = Stability()) -> Identification:
    """
    Identify modes from records of several channels with SSI-data and a stabilisation diagram.

    Parameters
    ----------
    values : (channels, samples) array
        Evenly sampled records of one quantity (e.g. accelerations, m/s^2); each channel's
        mean is removed.
    rate : float
        Sampling rate (Hz).
    max_order : int
        Highest model order (even orders from 2).
    block_rows : int, optional
        Block rows of the Hankel matrix; default :func:`block_rows_for`.
    lowest_hz, highest_hz : float
        The band of the modes kept; ``highest_hz`` defaults to 0.8 x Nyquist (the anti-alias
        filter's pass band).
    max_damping : float
        Poles damped more are dropped.
    stability : Stability
        Tolerances of a stable pole.

    Raises
    ------
    IdentificationError
        For fewer than :data:`MIN_CHANNELS` channels, non-finite values, or a record too
        short for the orders; the message says what is missing.

    """
    y = np.asarray(values, dtype=float)
    if y.ndim != 2 or y.shape[0] < MIN_CHANNELS:
        have = y.shape[0] if y.ndim == 2 else 0
        raise IdentificationError(f'{have} channel(s): operational modal analysis needs at '
                                  f'least {MIN_CHANNELS} channels')
    if not (math.isfinite(rate) and rate > 0.0):
        raise IdentificationError(f'sampling rate {rate!r} Hz: allowed a finite rate > 0')
    if not np.all(np.isfinite(y)):
        raise IdentificationError('the records hold non-finite values')
    channels, samples = y.shape
    i = block_rows if block_rows is not None else block_rows_for(
        samples, channels, rate, max_order=max_order, lowest_hz=lowest_hz)
    top = min(max_order, i * channels)
    orders = tuple(range(2, top + 1, 2))
    band = (float(lowest_hz), float(highest_hz if highest_hz is not None else 0.4 * rate))
    y = y - y.mean(axis=1, keepdims=True)
    strid = _strid()
    from threadpoolctl import threadpool_limits   # small matrices: one BLAS thread is fastest

    with threadpool_limits(limits=1, user_api='blas'):
        ssid = strid.DataDrivenStochasticSID(y, rate)
        by_order = []
        for n in orders:
            a, c = ssid.perform(n, i)[:2]
            by_order.append(_physical(strid, a, c, rate, n, band, max_damping))
    poles = _mark_stable(by_order, stability)
    needed = max(2, math.ceil(MIN_POLES_FRACTION * len(orders)))
    clusters = [c for c in _clusters([p for p in poles if p.stable]) if len(c) >= needed]
    modes = sorted((_mode_of(strid, c) for c in clusters), key=lambda m: m.frequency_hz)
    log.info('SSI-data: %d channels x %d samples, %d block rows, orders 2-%d: %d stable poles, '
             '%d modes', channels, samples, i, top, sum(p.stable for p in poles), len(modes))
    return Identification(float(rate), samples, channels, i, orders, band, tuple(poles),
                          tuple(modes))


def unit_shapes(model: Sequence[ModelMode]) -> list[ModelMode]:
    """
    Return the model modes with shapes scaled to a largest component of +1.

    A mode whose shape at the channels is below :data:`UNSEEN_RATIO` of the largest mode's
    (round-off: a torsion mode at vertical accelerometers on the axis) gets a zero shape:
    the channels do not see it, its MAC is 0 and it is never paired.
    """
    norms = [float(np.linalg.norm(np.nan_to_num(m.shape))) if m.shape is not None else 0.0
             for m in model]
    top = max(norms, default=0.0)
    out = []
    for m, norm in zip(model, norms):
        if m.shape is None:
            out.append(m)
            continue
        shape = np.array(m.shape, dtype=float)
        finite = np.isfinite(shape)
        if norm <= UNSEEN_RATIO * top:
            shape[finite] = 0.0
        else:
            k = int(np.argmax(np.where(finite, np.abs(shape), -1.0)))
            shape = shape / shape[k]
        out.append(ModelMode(m.frequency_hz, m.damping_ratio, shape))
    return out


def pair_modes(modes: Sequence[IdentifiedMode], model: Sequence[ModelMode], *,
               min_mac: float = 0.8) -> list[ModePair]:
    """
    Pair identified modes with model modes; return one :class:`ModePair` per identified mode.

    Every (identified, model) pair within :data:`PAIR_WINDOW` in frequency and of MAC >=
    ``min_mac`` is admissible; of those, the one-to-one assignment of least total modal
    distance 1 - MAC + |ln(f_identified / f_model)| (the clustering's distance;
    ``scipy.optimize.linear_sum_assignment``): MAC alone cannot rank the modes of identical
    spans, which have equal shapes at the channels of one span. Without a model shape at
    two or more channels: the nearest model frequency within the window.
    """
    def shaped(m: ModelMode) -> bool:
        return m.shape is not None and int(np.sum(np.isfinite(m.shape))) >= MIN_CHANNELS

    def near(i: int, k: int) -> bool:
        return abs(modes[i].frequency_hz / model[k].frequency_hz - 1.0) <= PAIR_WINDOW

    def distance(i: int, k: int) -> float:
        return abs(math.log(modes[i].frequency_hz / model[k].frequency_hz))

    macs = np.full((len(modes), len(model)), np.nan)
    for i, ident in enumerate(modes):
        for k, mm in enumerate(model):
            if shaped(mm) and near(i, k):
                assert mm.shape is not None
                macs[i, k] = mac(ident.shape, mm.shape)
    from scipy.optimize import linear_sum_assignment

    admissible = np.isfinite(macs) & (np.nan_to_num(macs) >= min_mac)
    cost = np.full(macs.shape, INADMISSIBLE)
    for i, k in zip(*np.nonzero(admissible)):
        cost[i, k] = 1.0 - macs[i, k] + distance(int(i), int(k))
    taken_i: dict[int, int] = {}
    used: set[int] = set()
    if cost.size:
        for i, k in zip(*linear_sum_assignment(cost)):
            if admissible[i, k]:
                taken_i[int(i)] = int(k)
                used.add(int(k))
    for i, ident in enumerate(modes):
        if i in taken_i:
            continue
        free = [k for k, mm in enumerate(model) if k not in used and not shaped(mm)]
        if not free:
            continue
        k = min(free, key=lambda k: distance(i, k))
        if near(i, k):
            taken_i[i] = k
            used.add(k)
    out = []
    for i, ident in enumerate(modes):
        k_or_none = taken_i.get(i)
        row = macs[i]
        if k_or_none is None:
            best = float(np.nanmax(row)) if np.any(np.isfinite(row)) else None
            out.append(ModePair(i, None, best, None, None))
            continue
        mm = model[k_or_none]
        pair_mac = float(row[k_or_none]) if np.isfinite(row[k_or_none]) else None
        zeta = (ident.damping_ratio / mm.damping_ratio - 1.0 if mm.damping_ratio > 0.0
                else None)
        out.append(ModePair(i, k_or_none, pair_mac, ident.frequency_hz / mm.frequency_hz - 1.0,
                            zeta))
    return out
