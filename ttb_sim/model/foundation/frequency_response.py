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
Harmonic response of the pile-soil substructure in the frequency domain.

For each frequency f the linear substructure (soil, piles, cap, the Desai
interface at its initial tangent, the boundary; the same operators the time
stepping and the reduction use) is solved as Z(w) u = F with the complex
symmetric dynamic stiffness Z = K - w^2 M + i w C, w = 2 pi f: the steady
state a harmonic load reaches after its transient has died out. The outputs
are receptances, metres per newton of load: the pile-head mean displacements
and the soil points.

Two things make it a reference a time-domain run cannot be:

- **A perfectly matched layer** (:class:`MatchedLayer`). The block is wrapped in
  a layer of the given thickness on the four sides and under the base (the
  layers continued outwards, the bottom layer downwards), fixed on its outer
  faces, in which the coordinates are complex-stretched,
  s(xi) = 1 - i sigma0 xi^m / w, xi the depth into the layer over its
  thickness L, sigma0 = (m + 1) c ln(1/R) / (2 L) with c the fastest P-wave
  speed: a wave entering it at normal incidence comes back attenuated by the
  nominal factor R whatever its frequency, and the block behaves as part of
  the layered half-space (Berenger 1994; for elastodynamics in the frequency
  domain, Basu & Chopra 2003). The stretch enters the element integrals of
  :func:`ttb_sim.fe.hex8.stiffness` and :func:`ttb_sim.fe.hex8.lumped_mass`.
  The viscous-spring boundary is then not used.
- **Mirror symmetry** (:mod:`ttb_sim.fe.symmetry`). When the mesh and the load
  are symmetric or antisymmetric about x = 0 and/or y = 0, the solve is done on
  the quarter (or half) of the unknowns, exactly.

The sparse direct solve is :func:`ttb_sim.fe.complex_solve.factorize_complex`
(MKL PARDISO when installed, SuperLU otherwise).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import logging
import math
import time
from typing import Callable, Literal, Optional, Sequence

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import FEError
from ttb_sim.fe import hex8
from ttb_sim.fe.assembly import assemble_chunked
from ttb_sim.fe.complex_solve import factorize_complex, resolve_method
from ttb_sim.fe.mesh import node_dofs
from ttb_sim.fe.symmetry import has_parity, mirror_nodes, mirror_reduction, MirrorPlane
from ttb_sim.model.foundation.records import (BlockSize, FoundationError, PileLoad,
                                              SoilParameters, Substructure)
from ttb_sim.model.foundation.substructure import build, materials, PileSoilModel

log = logging.getLogger(__name__)

SymmetryChoice = Literal['auto', 'none']

SLOW_SUPERLU = 20_000
"""Unknowns above which a SuperLU solve is slow enough to say so (measured: 97 s at 47 520)."""


@dataclass(frozen=True)
class MatchedLayer:
    """
    A perfectly matched layer around the block (sides and base).

    Attributes
    ----------
    thickness : float
        Thickness L (m), added outside the block's plan and under its base.
    reflection : float
        Nominal reflection R of a wave at normal incidence, in (0, 1).
    order : int
        Exponent m of the attenuation profile sigma0 xi^m.
    sides : bool
        Wrap the four sides too; False: the base only (a laterally periodic
        block keeps its periodicity, e.g. a site-response column).

    """

    thickness: float
    reflection: float = 1e-3
    order: int = 2
    sides: bool = True

    def __post_init__(self) -> None:
        """Check the fields."""
        if not (self.thickness > 0 and math.isfinite(self.thickness)):
            raise FoundationError(f'matched layer thickness must be > 0 m, not {self.thickness}')
        if not 0 < self.reflection < 1:
            raise FoundationError(f'matched layer reflection must be in (0, 1), not '
                                  f'{self.reflection}')
        if self.order not in (1, 2, 3):
            raise FoundationError(f'matched layer order must be 1, 2 or 3, not {self.order}')

    def strength(self, wave_speed: float) -> float:
        """Return sigma0 (1/s) for the fastest wave speed ``wave_speed`` (m/s)."""
        return (self.order + 1) * wave_speed * math.log(1.0 / self.reflection) / (
            2.0 * self.thickness)


def with_matched_layer(spec: Substructure, layer: MatchedLayer) -> Substructure:
    """Return ``spec`` with its block grown by the layer on every side and the base, fixed."""
    soil = spec.soil
    bottom = replace(soil.layers[-1], thickness=soil.layers[-1].thickness + layer.thickness)
    grown = replace(soil, layers=tuple(soil.layers[:-1]) + (bottom,), boundary='fixed')
    if layer.sides:
        grown = replace(grown, block=BlockSize(lx=soil.lx + 2 * layer.thickness,
                                               ly=soil.ly + 2 * layer.thickness),
                        periodic=False)
    return replace(spec, soil=grown)


def layer_depth(points: np.ndarray, soil: SoilParameters, layer: MatchedLayer) -> np.ndarray:
    """
    Return xi, the depth into the layer over its thickness along x, y, z, shape (..., 3).

    ``soil`` is the *inner* block's (before :func:`with_matched_layer`); xi is 0
    inside it.
    """
    inner = np.array([0.5 * soil.lx, 0.5 * soil.ly])
    xi = np.zeros(points.shape)
    if layer.sides:
        xi[..., :2] = np.maximum(0.0, np.abs(points[..., :2]) - inner) / layer.thickness
    xi[..., 2] = np.maximum(0.0, -soil.depth - points[..., 2]) / layer.thickness
    return np.minimum(xi, 1.0)


def stretch(points: np.ndarray, soil: SoilParameters, layer: MatchedLayer, omega: float
            ) -> np.ndarray:
    """Return the complex stretch s = 1 - i sigma0 xi^m / w at ``points``, shape (..., 3)."""
    if not omega > 0:
        raise FoundationError('a matched layer needs a frequency above 0 Hz')
    sigma0 = layer.strength(max(lay.vp for lay in soil.layers))
    return 1.0 - 1j * sigma0 * layer_depth(points, soil, layer)**layer.order / omega


@dataclass
class FrequencyResponse:
    """
    Receptances of the substructure, metres per newton of load.

    Attributes
    ----------
    frequencies : array (n_f,)
        Hz.
    heads : complex array (n_f, n_piles, 3)
        Pile-head mean displacement (x, y, z) per newton.
    points : complex array (n_f, n_points, 3)
        Soil-point displacement per newton.
    point_names : tuple of str
        Names of the soil points.
    unknowns : int
        Unknowns of each solve (after the symmetry reduction).
    dofs : int
        DOFs of the mesh (with the matched layer).
    symmetry : tuple of MirrorPlane
        Planes used.
    method : str
        Complex solver used.
    seconds : list of float
        Wall time of each frequency's solve (s).

    """

    frequencies: np.ndarray
    heads: np.ndarray
    points: np.ndarray
    point_names: tuple[str, ...]
    unknowns: int
    dofs: int
    symmetry: tuple[MirrorPlane, ...]
    method: str
    seconds: list[float] = field(default_factory=list)


class DynamicStiffness:
    """
    Z(w) of a built model on its free DOFs, with an optional matched layer.

    Parameters
    ----------
    model : PileSoilModel
        Built from :func:`with_matched_layer` of ``inner`` when ``layer`` is given.
    layer : MatchedLayer, optional
        The layer; cells with a node in it are integrated with the stretch.
    inner : SoilParameters, optional
        The block inside the layer (required with ``layer``).

    """

    def __init__(self, model: PileSoilModel, layer: Optional[MatchedLayer] = None,
                 inner: Optional[SoilParameters] = None) -> None:
        if layer is not None and inner is None:
            raise FoundationError('a matched layer needs the inner block')
        self.model = model
        self.layer = layer
        self.inner = inner
        self.free = np.flatnonzero(model.free)
        self.stiffness = (model.linear_stiffness()
                          + model.initial_interface_stiffness()).tocsr()
        self.damping = model.linear_damping()
        self.mass = model.mass
        self._cells = np.zeros(0, dtype=int)
        if layer is not None and inner is not None:
            coords = model.cell_coordinates
            self._cells = np.flatnonzero(layer_depth(coords, inner, layer).max(axis=(1, 2)) > 0)
            sel = self._cells
            mats = materials(model.spec)
            mat = model.mesh.material[sel]
            self._coords = coords[sel]
            self._dofs = node_dofs(model.mesh.cells)[sel]
            self._elastic = (mats.young[mat], mats.poisson[mat], mats.density[mat])
            self._rayleigh = (mats.alpha[mat], mats.beta[mat])
            self._enriched = model.spec.mesh.enriches(soil=True)   # the layer's cells are soil
            self._gauss = np.einsum('ga,eai->egi', hex8.shape_functions(hex8.GAUSS_POINTS),
                                    self._coords)
            # the same cells unstretched, once: Z_plain(w) = (1 + i w beta) K + (i w alpha - w^2) M
            self._plain = [self._assemble(None, *weights) for weights in
                           ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0),
                            (0.0, 0.0, 0.0, 1.0))]

    @property
    def layer_cells(self) -> int:
        """Number of cells in the matched layer."""
        return len(self._cells)

    def matrix(self, omega: float) -> sp.csr_matrix:
        """Return Z(w) on all DOFs (complex symmetric)."""
        w = float(omega)
        z = (self.stiffness + (1j * w) * self.damping
             - sp.diags(w * w * self.mass)).tocsr()
        if len(self._cells):
            assert self.layer is not None and self.inner is not None
            stretched = self._assemble(stretch(self._gauss, self.inner, self.layer, w),
                                       1.0, 1j * w, 1j * w, -w * w)
            k, k_beta, m_alpha, m = self._plain
            z = z + stretched - (k + (1j * w) * k_beta + (1j * w) * m_alpha - (w * w) * m)
        return z.tocsr()

    def _assemble(self, s: Optional[np.ndarray], k_weight: complex, beta_weight: complex,
                  alpha_weight: complex, mass_weight: complex = 0.0) -> sp.csr_matrix:
        """
        Return the layer cells' sum of k_w K + beta_w beta K + alpha_w alpha M + mass_w M.

        K and M integrated with the stretch ``s`` at the Gauss points (None: unstretched).
        """
        young, poisson, rho = self._elastic
        alpha, beta = self._rayleigh

        def kernel(ids: np.ndarray) -> np.ndarray:
            part = None if s is None else s[ids]
            k = hex8.stiffness(self._coords[ids], young[ids], poisson[ids], part,
                               incompatible=self._enriched)
            out = (k_weight + beta_weight * beta[ids])[:, None, None] * k
            m = hex8.lumped_mass(self._coords[ids], rho[ids], part)
            diag = ((alpha_weight * alpha[ids] + mass_weight)[:, None] * m).repeat(3, axis=1)
            idx = np.arange(24)
            out[:, idx, idx] += diag
            return out

        return assemble_chunked(self.model.n_dofs, self._dofs, kernel, dtype=complex).tocsr()


def symmetry_planes(model: PileSoilModel, load: np.ndarray) -> tuple[MirrorPlane, ...]:
    """
    Return the mirror planes of the mesh under which ``load`` is symmetric or antisymmetric.

    A plane is used when the mesh is its own mirror image about it and the load
    has one of the two parities there.
    """
    mesh = model.mesh
    if model.spec.soil.periodic:
        return ()
    chosen: list[MirrorPlane] = []
    for axis in ('x', 'y'):
        try:
            image = mirror_nodes(mesh.nodes, mesh.cells, mesh.material, axis)
        except FEError as exc:  # not a symmetric mesh
            log.debug('no mirror about %s = 0: %s', axis, exc)
            continue
        for parity in ('symmetric', 'antisymmetric'):
            plane = MirrorPlane(axis, parity)
            if has_parity(load, image, plane):
                chosen.append(plane)
                break
    return tuple(chosen)


def frequency_response(model: PileSoilModel, load: PileLoad, frequencies: Sequence[float], *,
                       layer: Optional[MatchedLayer] = None,
                       inner: Optional[SoilParameters] = None,
                       symmetry: SymmetryChoice = 'auto', method: str = 'auto',
                       progress: Optional[Callable[[int, float, float], None]] = None
                       ) -> FrequencyResponse:
    """
    Return the receptances of ``model`` to ``load`` at ``frequencies`` (Hz).

    Parameters
    ----------
    model : PileSoilModel
        The substructure (with the layer: built from :func:`with_matched_layer`).
    load : PileLoad
        The load: where and along which axis (its amplitude is ignored: the
        response is per newton).
    frequencies : sequence of float
        Hz; > 0 with a matched layer, >= 0 otherwise.
    layer, inner : optional
        The matched layer and the block inside it.
    symmetry : {'auto', 'none'}
        Solve on the symmetric part when the mesh and the load allow it.
    method : str
        Complex solver (:data:`ttb_sim.fe.complex_solve.METHODS`).
    progress : callable, optional
        Called as ``progress(index, frequency, seconds)`` after each solve.

    """
    freqs = np.asarray(frequencies, dtype=float)
    if freqs.ndim != 1 or len(freqs) == 0 or not np.all(np.isfinite(freqs)) or \
            np.any(freqs < 0):
        raise FoundationError('frequencies must be a non-empty list of finite values >= 0 Hz')
    if layer is not None and np.any(freqs <= 0):
        raise FoundationError('a matched layer needs frequencies above 0 Hz')
    force = model.load_vector(replace(load, amplitude=1.0))
    planes = symmetry_planes(model, force) if symmetry == 'auto' else ()
    if planes:
        mesh = model.mesh
        t = mirror_reduction(mesh.nodes, mesh.cells, mesh.material, planes)
    else:
        t = sp.identity(model.n_dofs, format='csr')
    t = t[np.flatnonzero(model.free)] if not model.free.all() else t
    t = t.tocsc()
    t = t[:, np.flatnonzero(np.asarray(abs(t).sum(axis=0)).ravel() > 0)].tocsr()
    free = np.flatnonzero(model.free)
    operator = DynamicStiffness(model, layer, inner)
    rhs = t.T @ force[free]
    observe = sp.vstack([model.head_displacement, model.soil_points.operator]).tocsr()
    observe = (observe[:, free] @ t).tocsr()
    n_heads = model.head_displacement.shape[0]
    if t.shape[1] > SLOW_SUPERLU and resolve_method(method) == 'superlu':
        log.warning('%d unknowns by SuperLU: minutes per frequency; MKL PARDISO is about 17x '
                    "faster (pip install 'ttb_sim[pardiso]')", t.shape[1])
    out = np.zeros((len(freqs), observe.shape[0]), dtype=complex)
    seconds: list[float] = []
    chosen = method
    for i, f in enumerate(freqs):
        start = time.perf_counter()
        z = operator.matrix(2.0 * math.pi * f)[free][:, free]
        reduced = (t.T @ z @ t).tocsr()
        factor = factorize_complex(reduced, method)
        chosen = factor.method
        out[i] = observe @ factor.solve(rhs.astype(complex))
        del factor
        seconds.append(time.perf_counter() - start)
        if progress is not None:
            progress(i, float(f), seconds[-1])
    return FrequencyResponse(freqs, out[:, :n_heads].reshape(len(freqs), -1, 3),
                             out[:, n_heads:].reshape(len(freqs), -1, 3),
                             tuple(model.soil_points.names), t.shape[1], model.n_dofs, planes,
                             chosen, seconds)


def substructure_response(spec: Substructure, load: PileLoad, frequencies: Sequence[float], *,
                          layer: Optional[MatchedLayer] = None, symmetry: SymmetryChoice = 'auto',
                          method: str = 'auto',
                          progress: Optional[Callable[[int, float, float], None]] = None
                          ) -> FrequencyResponse:
    """Build ``spec`` (wrapped in ``layer`` if given) and return its :func:`frequency_response`."""
    inner = spec.soil if layer is not None else None
    model = build(with_matched_layer(spec, layer) if layer is not None else spec, load)
    return frequency_response(model, load, frequencies, layer=layer, inner=inner,
                              symmetry=symmetry, method=method, progress=progress)
