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
Linear lateral stability (hunting) of one multibody car on rigid, straight, smooth track.

The car of :mod:`ttb_sim.model.vehicle.car` is linearised at speed V about the
centred static state (every wheelset at y = 0, every wheel load P0):

    M q'' + (C + G(V) + C_c(V)) q' + (K + K_c) q = 0

M, C, K are the suspension matrices of the car, G(V) its wheelset
gyroscopic matrix (:func:`ttb_sim.model.vehicle.matrices.gyroscopic_matrix`) and C_c, K_c
the linearised wheel-rail contact of
:func:`~ttb_sim.model.vehicle.linear_contact.contact_matrices` (the contact laws of the
time-domain solver with the rails held fixed, so this is an independent check of
that implementation; :mod:`.linear_contact` lists them).

Rigid-body roots.  The wheelset spin angles (the wheelset ``pitch`` DOFs) and
the rigid longitudinal motion of the whole car produce no force at all (only
their velocities appear, through the longitudinal creepage), so K + K_c is
singular and the quadratic eigenproblem has that many exact zero roots, which
numerically come out as +-1e-9-sized numbers of either sign.  They are removed
exactly, not by a threshold on the eigenvalues: with N an orthonormal basis of
the null space of K + K_c and W one of its row space (both from one SVD),
(K + K_c) q = (K + K_c) W p with p = W^T q, and the state (p, u = q') obeys
p' = W^T u, M u' = -(C + G + C_c) u - (K + K_c) W p.  The discarded
coordinates a = N^T q only integrate N^T u and feed back nowhere, so they
carry exactly the zero roots; the reduced state of size 2 n - n0 carries
all others.  No other eigenvalue sits at zero for a speed V > 0, so
``critical_speed`` can use the largest real part of the reduced spectrum
without false crossings.

Comparison with the time domain (open point)
--------------------------------------------
Table 1 car, scenario damper counts (4/2/2), no anti-yaw dampers, 300 km/h,
LMA/CHN60 table: this analysis gives bogie hunting at 4.52 Hz with
Re(lambda) = +1.41 1/s; ``TrainTrackCoupling`` on the slab track gives
4.27 Hz and +3.0 1/s, the same for 0.3 and 3 mm initial offsets, dt = 1e-4
and 2e-4 s and a 100 times stiffer lateral fastener.  With the default
anti-yaw dampers the time domain also decays more slowly (about -2.8 vs
-3.5 1/s).  The signs (and so the stable/unstable verdicts at 200, 300 and
400 km/h) agree; the rates do not yet.  Most of the difference is the
track's lateral flexibility at the rail head, which this rigid-track
analysis leaves out: the rail rolls on its pads (k_v w^2 / 12 per fastener)
and the head moves sideways.  With the lateral fastener 100 times and the
rail-roll stiffness 11 times stiffer (``track.rail_foot_width`` 0.5 m) the
time domain gives 4.3 Hz and +2.1..2.2 1/s.  Not modelled here either: the
vertical and torsional flexibility of the track and the Shen-Hedrick-Elkins
factor (its derivative at the static state is 0.91 on the lateral creep
force).

Functions
---------
* :mod:`.linear_contact` -- linearised geometry and the contact matrices C_c, K_c.
* :func:`linear_car` -- the total matrices at one speed, optionally without
  suspension or on a DOF subset.
* :func:`eigen`, :func:`modes`, :func:`least_damped_mode` -- the spectrum.
* :func:`critical_speed` -- coarse scan plus Brent bisection.
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
import math
from typing import Sequence, TYPE_CHECKING, TypedDict

import numpy as np
import scipy.linalg
from scipy.optimize import brentq

from ttb_sim.errors import ModelError
from ttb_sim.model.vehicle.car import CarParameters
from ttb_sim.model.vehicle.dofs import dofs as car_dofs, N_BODIES, N_DOF
from ttb_sim.model.vehicle.linear_contact import contact_matrices, LinearGeometry
from ttb_sim.model.vehicle.matrices import gyroscopic_matrix, mass_matrix
from ttb_sim.model.vehicle.suspension import damping_matrix, stiffness_matrix

if TYPE_CHECKING:
    from typing_extensions import Unpack

log = logging.getLogger(__name__)

__all__ = [
    'LATERAL_DOFS',
    'LinearCar',
    'LinearCarOptions',
    'Mode',
    'NULL_TOLERANCE',
    'critical_speed',
    'eigen',
    'least_damped_mode',
    'linear_car',
    'max_real_part',
    'modes',
]

#: Relative singular-value threshold defining the null space of K + K_c.
NULL_TOLERANCE = 1e-9
#: Lateral DOFs of the car (y, roll, yaw of every body), for mode classification.
LATERAL_DOFS = car_dofs(range(N_BODIES), ['y', 'roll', 'yaw'])


@dataclass(frozen=True)
class LinearCar:
    """
    Linearised equations M q'' + C q' + K q = 0 of a car at one speed.

    Attributes
    ----------
    mass, damping, stiffness : numpy.ndarray
        Square matrices over ``dofs``; damping includes G(V) and C_c(V),
        stiffness includes K_c.
    dofs : numpy.ndarray
        Car DOF indices (0..41) kept; the others are held fixed.
    speed : float
        V (m/s).

    """

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    dofs: np.ndarray
    speed: float


class LinearCarOptions(TypedDict, total=False):
    """The keyword options of :func:`linear_car`, passed on by the speed-scan helpers."""

    tread: str
    creep_factor: float
    suspension: bool
    dofs: Sequence[int] | np.ndarray | None


def linear_car(params: CarParameters | None, speed: float, geometry: LinearGeometry, *,
               tread: str = 'lm', creep_factor: float = 1.0, suspension: bool = True,
               dofs: Sequence[int] | np.ndarray | None = None) -> LinearCar:
    """
    Build the linearised car on rigid track at speed V.

    Parameters
    ----------
    params : CarParameters or None
        Car parameters; Table 1 defaults if None.
    speed : float
        V (m/s), > 0.
    geometry : LinearGeometry
        Linearised contact geometry.
    tread : {'lm', 'conical'}
        Tread of the Hertz constant.
    creep_factor : float
        Factor on the creep coefficients (1 = linear Kalker).
    suspension : bool
        False drops the suspension K and C (keeps M, G(V) and the contact),
        e.g. for a free wheelset together with ``dofs``.
    dofs : sequence of int, optional
        DOFs kept (others held at 0); all 42 if omitted.

    Returns
    -------
    LinearCar
        The matrices.

    """
    p = params or CarParameters()
    c_c, k_c = contact_matrices(p, speed, geometry, tread=tread, creep_factor=creep_factor)
    damping = gyroscopic_matrix(p, speed) + c_c
    stiffness = k_c
    if suspension:
        damping = damping + damping_matrix(p)
        stiffness = stiffness + stiffness_matrix(p)
    idx = np.arange(N_DOF) if dofs is None else np.asarray(dofs, dtype=int)
    sub = np.ix_(idx, idx)
    return LinearCar(mass_matrix(p)[sub], damping[sub], stiffness[sub], idx, float(speed))


def eigen(system: LinearCar) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the eigenvalues and displacement shapes without the rigid-body zero roots.

    The zero roots are removed exactly in two steps (module docstring):
    positions that produce no force (null space of K), then steady
    velocities in that null space whose damping force the stiffness balances
    statically (the uniform change of forward speed with matching wheel
    spin, which has zero creepage).

    Parameters
    ----------
    system : LinearCar
        Linearised equations.

    Returns
    -------
    eigenvalues : numpy.ndarray
        Complex, shape (2 n - n0 - n1,).
    shapes : numpy.ndarray
        Complex displacement shapes q = q' / lambda, shape (n, 2 n - n0 - n1),
        normalised to unit kinetic-energy norm (sum m |q|^2 = 1).

    """
    m, c, k = system.mass, system.damping, system.stiffness
    n = m.shape[0]
    # Step 1: positions without force, K N = 0; keep p = W^T q.
    _, sv, vt = scipy.linalg.svd(k)
    rank = int(np.sum(sv > NULL_TOLERANCE * sv[0]))
    w, null = vt[:rank].T, vt[rank:].T
    m_inv = np.linalg.inv(m)
    a = np.zeros((rank + n, rank + n))
    a[:rank, rank:] = w.T
    a[rank:, :rank] = -m_inv @ k @ w
    a[rank:, rank:] = -m_inv @ c
    basis = np.eye(rank + n)
    if null.shape[1]:
        # Step 2: states (p, u = N a) with K W p + C N a = 0 (kernel of the reduced matrix).
        b = np.hstack([k @ w, c @ null])
        scale = np.linalg.norm(b, axis=0)
        scale[scale == 0.0] = 1.0
        _, sv2, vt2 = scipy.linalg.svd(b / scale, full_matrices=True)
        sv2 = np.concatenate([sv2, np.zeros(vt2.shape[0] - sv2.size)])
        kernel = (vt2[sv2 <= NULL_TOLERANCE * sv2[0]] / scale).T      # (rank + n0, n1)
        if kernel.shape[1]:
            z = np.vstack([kernel[:rank], null @ kernel[rank:]])
            basis = scipy.linalg.null_space(z.T)                     # orthonormal complement
        log.debug('deflated %d force-free positions and %d steady velocities',
                  n - rank, kernel.shape[1])
    lam, vec = scipy.linalg.eig(basis.T @ a @ basis)
    # With Q = [Z, Y] (Z the kernel), Q^T A Q = [[0, X], [0, T]]; an eigenvector v of
    # T = Y^T A Y is the eigenvector Y v + Z X v / lambda of A.
    full = basis @ vec
    full = full + _kernel_part(a, basis, full, lam)
    shapes = full[rank:] / lam[None, :]
    norm = np.sqrt(np.einsum('i,ij->j', np.diag(m), np.abs(shapes) ** 2))
    return lam, shapes / norm[None, :]


def _kernel_part(a: np.ndarray, basis: np.ndarray, vec: np.ndarray,
                 lam: np.ndarray) -> np.ndarray:
    """Return the component of each eigenvector along the deflated kernel, Z X v / lambda."""
    if basis.shape[1] == a.shape[0]:
        return np.zeros_like(vec)
    residual = a @ vec - basis @ (basis.T @ a @ vec)               # Z Z^T A Y v
    return residual / lam[None, :]


@dataclass(frozen=True)
class Mode:
    """
    One complex mode of the linearised car.

    Attributes
    ----------
    eigenvalue : complex
        lambda (1/s); the motion grows as exp(Re(lambda) t).
    frequency : float
        Damped frequency |Im(lambda)| / 2 pi (Hz).
    damping_ratio : float
        -Re(lambda) / |lambda| (-); negative when unstable.
    lateral_fraction : float
        Share of the modal kinetic energy in the lateral DOFs (y, roll, yaw).
    shape : numpy.ndarray
        Complex displacement shape over the system's DOFs.

    """

    eigenvalue: complex
    frequency: float
    damping_ratio: float
    lateral_fraction: float
    shape: np.ndarray


def modes(system: LinearCar) -> list[Mode]:
    """
    Return every mode (one per complex-conjugate pair), ascending damping ratio.

    Parameters
    ----------
    system : LinearCar
        Linearised equations.

    Returns
    -------
    list of Mode
        Oscillatory modes with Im(lambda) > 0 and real roots.

    """
    lam, shapes = eigen(system)
    keep = lam.imag >= 0.0
    lam, shapes = lam[keep], shapes[:, keep]
    lateral = np.isin(system.dofs, LATERAL_DOFS)
    energy = np.diag(system.mass)[:, None] * np.abs(shapes) ** 2
    frac = energy[lateral].sum(axis=0) / energy.sum(axis=0)
    zeta = -lam.real / np.abs(lam)
    order = np.argsort(zeta)
    return [Mode(complex(lam[i]), float(abs(lam[i].imag) / (2.0 * math.pi)), float(zeta[i]),
                 float(frac[i]), shapes[:, i]) for i in order]


def least_damped_mode(params: CarParameters | None, speed: float, geometry: LinearGeometry, *,
                      lateral: bool = True, oscillatory: bool = True,
                      **kwargs: Unpack[LinearCarOptions]) -> Mode:
    """
    Return the least-damped (lateral, oscillatory) mode at speed V.

    Parameters
    ----------
    params : CarParameters or None
        Car parameters; Table 1 defaults if None.
    speed : float
        V (m/s), > 0.
    geometry : LinearGeometry
        Linearised contact geometry.
    lateral : bool
        Only modes with more than half of their kinetic energy in lateral DOFs.
    oscillatory : bool
        Only complex modes (frequency > 0).
    **kwargs
        Passed to :func:`linear_car` (tread, creep_factor, suspension, dofs).

    Returns
    -------
    Mode
        The mode with the smallest damping ratio among the candidates.

    Raises
    ------
    ModelError
        If no mode qualifies.

    """
    candidates = [md for md in modes(linear_car(params, speed, geometry, **kwargs))
                  if (md.lateral_fraction > 0.5 or not lateral)
                  and (md.frequency > 0.0 or not oscillatory)]
    if not candidates:
        raise ModelError('no mode matches the selection (lateral / oscillatory)')
    return candidates[0]


def max_real_part(params: CarParameters | None, speed: float, geometry: LinearGeometry,
                  **kwargs: Unpack[LinearCarOptions]) -> float:
    """
    Return the largest real part of the non-rigid eigenvalues at speed V (1/s).

    Parameters
    ----------
    params : CarParameters or None
        Car parameters.
    speed : float
        V (m/s), > 0.
    geometry : LinearGeometry
        Linearised contact geometry.
    **kwargs
        Passed to :func:`linear_car`.

    Returns
    -------
    float
        max Re(lambda); > 0 means unstable.

    """
    lam, _ = eigen(linear_car(params, speed, geometry, **kwargs))
    return float(np.max(lam.real))


def critical_speed(params: CarParameters | None, geometry: LinearGeometry, *,
                   speed_range: tuple[float, float] = (5.0, 200.0), n_scan: int = 40,
                   tol: float = 0.01, **kwargs: Unpack[LinearCarOptions]) -> float:
    """
    Return the lowest speed at which an eigenvalue crosses into Re(lambda) > 0.

    The largest real part is evaluated on ``n_scan`` equally spaced speeds;
    the first sign change is refined by Brent's method (``brentq``) to
    ``tol``.  A stable window narrower than the scan spacing between two
    unstable speeds could be missed; crossings are found to within ``tol``.

    Parameters
    ----------
    params : CarParameters or None
        Car parameters; Table 1 defaults if None.
    geometry : LinearGeometry
        Linearised contact geometry.
    speed_range : tuple of float
        Lowest and highest speed scanned (m/s), 0 < low < high.
    n_scan : int
        Number of scan speeds, >= 2.
    tol : float
        Absolute tolerance on the critical speed (m/s), > 0.
    **kwargs
        Passed to :func:`linear_car`.

    Returns
    -------
    float
        Critical speed (m/s); ``math.inf`` if stable over the whole range.

    Raises
    ------
    ModelError
        On invalid arguments, or if the car is already unstable at the lowest speed.

    """
    low, high = (float(v) for v in speed_range)
    if not (math.isfinite(low) and math.isfinite(high) and 0.0 < low < high):
        raise ModelError(f'speed_range = {speed_range!r} is invalid; allowed: 0 < low < high')
    if int(n_scan) < 2 or not (math.isfinite(tol) and tol > 0.0):
        raise ModelError(f'n_scan = {n_scan!r} / tol = {tol!r} are invalid; '
                         'allowed: n_scan >= 2, tol > 0')

    def growth(v: float) -> float:
        return max_real_part(params, v, geometry, **kwargs)

    speeds = np.linspace(low, high, int(n_scan))
    previous = growth(speeds[0])
    if previous > 0.0:
        raise ModelError(f'the car is unstable already at {low:.3g} m/s '
                         f'(max Re(lambda) = {previous:.3g} 1/s); lower speed_range')
    for v0, v1 in zip(speeds[:-1], speeds[1:]):
        current = growth(v1)
        if current > 0.0:
            v_cr = float(brentq(growth, v0, v1, xtol=tol))
            log.info('critical speed %.3f m/s (%.2f km/h)', v_cr, 3.6 * v_cr)
            return v_cr
        previous = current
    log.info('stable up to %.3f m/s (max Re(lambda) = %.3g 1/s)', high, previous)
    return math.inf
