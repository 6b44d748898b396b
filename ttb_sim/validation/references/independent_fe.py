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
An independent 3-D FE of a pile-soil block in the frequency domain (scikit-fem).

The validation reference of V15: the same block, piles and boundary as a
:class:`~ttb_sim.model.foundation.records.Substructure`, solved as
(K + i w C - w^2 M) u = F at one frequency by `scikit-fem
<https://scikit-fem.readthedocs.io>`_ (BSD-3-Clause): its trilinear hexahedra,
its quadrature, its facet integration and its DOF numbering. Nothing here
uses the model's element kernels, material tables, boundary faces, load or
observation operators. From the model it takes only the mesh geometry (node
coordinates and cell corners: the comparison is of two codes on one
discretisation, not of two meshes) and the records' numbers; every cell's
material is found again from its centroid (inside a pile square above the
tip: pile; else the layer at its depth), the boundary faces from the block's
outer planes, the loaded head from the plan position of the pile.

What it models ([P] Eq. 3 and the scenario's keys): linear elastic soil
layers and piles bonded to it (``interface.model: bonded``; no cap), Rayleigh
damping alpha M + beta K per material with its damping ratio at the two
Rayleigh frequencies, row-sum lumped mass, and on the outer faces the
boundary of ``soil.boundary``: ``viscoelastic`` springs alpha G / R and
dashpots rho Vs, rho Vp per unit area (R from the pile group's centre to the
face centre), ``lysmer`` the dashpots only, ``fixed`` the base fixed and the
sides on rollers, ``rigid_base`` the base fixed under viscous-spring sides.
Boundary matrices are lumped by row sums (tributary areas) when
``soil.boundary_lumping`` is ``lumped``.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Callable

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import ModelError
from ttb_sim.fe.complex_solve import factorize_complex
from ttb_sim.model.foundation.records import EQUAL_AREA_SIDE, Substructure

#: Corner order of scikit-fem's ElementHex1 (its ``doflocs``) as (x, y, z) bits.
SKFEM_CORNERS = ((1, 1, 1), (1, 1, 0), (1, 0, 1), (0, 1, 1),
                 (1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, 0))


@dataclass(frozen=True)
class BlockResponse:
    """
    Receptances of the independent FE at one frequency.

    Attributes
    ----------
    frequency : float
        Hz.
    head : complex
        Mean displacement of the loaded pile head along the load per unit force (m/N).
    points : array of complex, shape (n_points, 3)
        Displacement at each observation point per unit force (m/N).
    dofs : int
        Unknowns solved (free DOFs, summed over the parities solved).

    """

    frequency: float
    head: complex
    points: np.ndarray
    dofs: int


def skfem_cells(nodes: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """
    Return ``cells`` (m, 8) reordered to scikit-fem's hexahedron corner order, shape (8, m).

    Each corner is named by which side of the cell centroid it lies on along
    x, y and z (the cells are boxes or close to them); a cell whose eight
    corners do not fill the eight octants is refused.
    """
    xyz = nodes[cells]
    octant = (xyz > xyz.mean(axis=1, keepdims=True)).astype(int)
    code = octant[..., 0] * 4 + octant[..., 1] * 2 + octant[..., 2]
    if np.any(np.sort(code, axis=1) != np.arange(8)):
        raise ModelError('independent FE: a cell is not a box-like hexahedron')
    wanted = np.array([4 * x + 2 * y + z for x, y, z in SKFEM_CORNERS])
    position = np.argsort(code, axis=1)[:, wanted]
    return np.take_along_axis(cells, position, axis=1).T


def cell_materials(spec: Substructure, centroids: np.ndarray) -> np.ndarray:
    """
    Return each cell's material index from its centroid: the layer, or ``len(layers)`` for a pile.

    Layers are counted from the surface (z = 0) downwards; a cell whose
    centroid lies inside the square of equal area of a pile and above its
    tip is pile.
    """
    tops = -np.cumsum([0.0] + [lay.thickness for lay in spec.soil.layers])
    z = centroids[:, 2]
    layer = np.clip(np.searchsorted(-tops[1:], -z, side='right'), 0,
                    len(spec.soil.layers) - 1)
    piles = spec.piles
    if piles is None:
        return layer
    half = 0.5 * EQUAL_AREA_SIDE * piles.diameter
    inside = np.zeros(len(centroids), dtype=bool)
    for cx, cy in piles.centres():
        inside |= ((np.abs(centroids[:, 0] - cx) < half) & (np.abs(centroids[:, 1] - cy) < half)
                   & (z > -piles.length))
    return np.where(inside, len(spec.soil.layers), layer)


@dataclass(frozen=True)
class _Tables:
    """Per material (layers, then pile): E, nu, rho, Rayleigh alpha and beta."""

    young: np.ndarray
    poisson: np.ndarray
    density: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray


def _tables(spec: Substructure, residual: float) -> _Tables:
    layers, piles = spec.soil.layers, spec.piles
    rows = [(lay.E, lay.nu, lay.rho, lay.damping_ratio) for lay in layers]
    rows.append((piles.E, piles.nu, piles.rho, piles.damping_ratio) if piles is not None
                else (0.0, 0.0, 0.0, 0.0))
    rows += [(lay.E * residual, lay.nu, lay.rho * residual, lay.damping_ratio)
             for lay in layers]
    young, poisson, density, zeta = (np.array(c, dtype=float) for c in zip(*rows))
    w1, w2 = (2.0 * math.pi * f for f in spec.rayleigh_frequencies)
    return _Tables(young, poisson, density, 2.0 * zeta * w1 * w2 / (w1 + w2),
                   2.0 * zeta / (w1 + w2))


def _row_sum_lumped(matrix: sp.spmatrix) -> sp.csr_matrix:
    """Lump a vector-field matrix by rows, per direction: 3 x 3 nodal blocks -> their row sums."""
    coo = sp.coo_matrix(matrix)
    # DOFs of scikit-fem's ElementVector are interleaved: node a, direction i -> 3 a + i
    same_node_col = 3 * (coo.row // 3) + coo.col % 3
    return sp.csr_matrix((coo.data, (coo.row, same_node_col)), shape=matrix.shape)


class IndependentBlock:
    """
    The block of ``spec`` on the mesh (``nodes``, ``cells``) assembled by scikit-fem.

    Parameters
    ----------
    spec : Substructure
        Layers, piles, boundary and Rayleigh frequencies (a cap or a Desai
        interface is refused: the reference models bonded piles without cap).
    nodes : array, shape (n, 3)
        Node coordinates (m).
    cells : array of int, shape (m, 8)
        Cell corners, any order within each cell.
    removed_above : float
        Depth (m) above which the soil is removed (scour): a soil cell whose
        centroid lies above it, and the outer faces above it, take ``residual``
        times the modulus and density of their layer. 0 removes nothing.
    residual : float
        Fraction of modulus and density left in removed soil.

    """

    def __init__(self, spec: Substructure, nodes: np.ndarray, cells: np.ndarray,
                 removed_above: float = 0.0, residual: float = 1e-6) -> None:
        from skfem import Basis, ElementHex1, ElementVector, MeshHex1  # noqa: I202

        if spec.cap.enabled:
            raise ModelError('independent FE: a cap is not modelled (cap.enabled: false)')
        if spec.piles is not None and spec.interface.model != 'bonded':
            raise ModelError('independent FE: piles are bonded to the soil; set '
                             'interface.model: bonded')
        self.spec = spec
        self.mesh = MeshHex1(np.ascontiguousarray(np.asarray(nodes, dtype=float).T),
                             np.ascontiguousarray(skfem_cells(nodes, cells)))
        self.element = ElementVector(ElementHex1())
        centroids = self.mesh.p[:, self.mesh.t].mean(axis=1).T
        material = cell_materials(spec, centroids)
        n_layers = len(spec.soil.layers)
        removed = (material < n_layers) & (centroids[:, 2] > -removed_above)
        self.material = np.where(removed, material + n_layers + 1, material)
        self.removed_above, self.residual = float(removed_above), float(residual)
        self.tables = _tables(spec, residual)
        # the whole-mesh basis numbers the DOFs and interpolates (probes): one point per
        # cell is enough for that and keeps its memory at 1/8 of an integrating one
        self.basis = Basis(self.mesh, self.element, intorder=1)
        self.stiffness, self.damping, self.mass = self._domain_operators(Basis)
        self.fixed = self._fixed_dofs()
        k_b, c_b = self._boundary_operators()
        self.stiffness = (self.stiffness + k_b).tocsr()
        self.damping = (self.damping + c_b).tocsr()

    # -- assembly ----------------------------------------------------------------------------

    def _domain_operators(self, basis_type: type
                          ) -> tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix]:
        """Return K, C = sum(alpha M + beta K) and the lumped M, per material subset."""
        from skfem import BilinearForm  # noqa: I202
        from skfem.helpers import dot
        from skfem.models.elasticity import lame_parameters, linear_elasticity

        n = self.basis.N
        k_sum, c_sum, m_sum = (sp.csr_matrix((n, n)) for _ in range(3))
        t = self.tables

        @BilinearForm
        def unit_mass(u, v, w):
            return dot(u, v)

        for m in np.unique(self.material):
            sub = basis_type(self.mesh, self.element, intorder=3,
                             elements=np.flatnonzero(self.material == m))
            k_m = linear_elasticity(*lame_parameters(t.young[m], t.poisson[m])).assemble(sub)
            m_m = _row_sum_lumped(t.density[m] * unit_mass.assemble(sub))
            k_sum = k_sum + k_m
            m_sum = m_sum + m_m
            c_sum = c_sum + t.alpha[m] * m_m + t.beta[m] * k_m
        return k_sum.tocsr(), c_sum.tocsr(), m_sum.tocsr()

    def _outer_facets(self) -> dict[str, np.ndarray]:
        """Return the facets of the block's four sides and base by name."""
        lo, hi = self.mesh.p.min(axis=1), self.mesh.p.max(axis=1)
        tol = 1e-9 * float(np.max(hi - lo))

        def on(axis: int, value: float) -> Callable[[np.ndarray], np.ndarray]:
            return lambda x: np.abs(x[axis] - value) < tol

        return {'xmin': self.mesh.facets_satisfying(on(0, lo[0])),
                'xmax': self.mesh.facets_satisfying(on(0, hi[0])),
                'ymin': self.mesh.facets_satisfying(on(1, lo[1])),
                'ymax': self.mesh.facets_satisfying(on(1, hi[1])),
                'zmin': self.mesh.facets_satisfying(on(2, lo[2]))}

    def _fixed_dofs(self) -> np.ndarray:
        """Return the DOFs the boundary fixes (fixed base; rollers on the sides of 'fixed')."""
        kind = self.spec.soil.boundary
        facets = self._outer_facets()
        fixed: list[np.ndarray] = []
        if kind in ('fixed', 'rigid_base'):
            fixed.append(self.basis.get_dofs(facets['zmin']).all())
        if kind == 'fixed':
            for name, comp in (('xmin', 'u^1'), ('xmax', 'u^1'), ('ymin', 'u^2'),
                               ('ymax', 'u^2')):
                fixed.append(self.basis.get_dofs(facets[name]).nodal[comp])
        return np.unique(np.concatenate(fixed)) if fixed else np.zeros(0, dtype=int)

    def _boundary_operators(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Return the viscous-spring boundary's springs and dashpots (zero where none)."""
        from skfem import BilinearForm, FacetBasis  # noqa: I202
        from skfem.helpers import dot

        soil, n = self.spec.soil, self.basis.N
        k_b, c_b = sp.csr_matrix((n, n)), sp.csr_matrix((n, n))
        if soil.boundary == 'fixed':
            return k_b, c_b
        names: tuple[str, ...] = ('xmin', 'xmax', 'ymin', 'ymax')
        if soil.boundary != 'rigid_base':
            names += ('zmin',)
        facets = np.concatenate([f for k, f in self._outer_facets().items() if k in names])
        layers = soil.layers
        tops = -np.cumsum([0.0] + [lay.thickness for lay in layers])
        g = np.array([lay.E / (2 * (1 + lay.nu)) for lay in layers])
        rho = np.array([lay.rho for lay in layers])
        vs = np.sqrt(g / rho)
        vp = vs * np.array([math.sqrt(2 * (1 - lay.nu) / (1 - 2 * lay.nu)) for lay in layers])
        piles = self.spec.piles
        source = np.array([*piles.centre, 0.0]) if piles is not None else np.zeros(3)
        centre = self.mesh.p[:, self.mesh.facets[:, facets]].mean(axis=1).T
        layer = np.clip(np.searchsorted(-tops[1:], -centre[:, 2], side='right'), 0,
                        len(layers) - 1)
        distance = np.linalg.norm(centre - source, axis=1)
        kept = np.where(centre[:, 2] > -self.removed_above, self.residual, 1.0)
        g, rho = g[layer] * kept, rho[layer] * kept
        vs, vp = vs[layer], vp[layer]
        springs = soil.boundary in ('viscoelastic', 'rigid_base')
        fb = FacetBasis(self.mesh, self.element, facets=facets, intorder=3)
        per_facet = {
            'kn': soil.alpha_n * g / distance if springs else 0.0 * distance,
            'kt': soil.alpha_t * g / distance if springs else 0.0 * distance,
            'cn': rho * vp, 'ct': rho * vs}
        fields = {k: np.repeat(v[:, None], fb.X.shape[1], axis=1) for k, v in per_facet.items()}

        @BilinearForm
        def oriented(u, v, w):
            return w.t * dot(u, v) + (w.nn - w.t) * dot(u, w.n) * dot(v, w.n)

        for normal, tangential, out in (('kn', 'kt', 'k'), ('cn', 'ct', 'c')):
            mat = oriented.assemble(fb, nn=fields[normal], t=fields[tangential])
            if soil.boundary_lumping == 'lumped':
                mat = _row_sum_lumped(mat)
            if out == 'k':
                k_b = k_b + mat
            else:
                c_b = c_b + mat
        return k_b.tocsr(), c_b.tocsr()

    # -- load, observation, solve --------------------------------------------------------

    def head_weights(self, pile: int, axis: int = 2) -> np.ndarray:
        """
        Return w with w . u = mean displacement of pile ``pile``'s head along ``axis``.

        w times a force is the uniform pressure of that force on the head (the
        load of ``load.target: pile``).
        """
        from skfem import FacetBasis, Functional, LinearForm  # noqa: I202

        piles = self.spec.piles
        if piles is None or not 1 <= pile <= piles.count:
            raise ModelError(f'independent FE: no pile {pile}')
        cx, cy = piles.centres()[pile - 1]
        half = 0.5 * EQUAL_AREA_SIDE * piles.diameter
        top = self.mesh.p[2].max()
        tol = 1e-6 * half
        facets = self.mesh.facets_satisfying(
            lambda x: (np.abs(x[2] - top) < tol) & (np.abs(x[0] - cx) < half + tol)
            & (np.abs(x[1] - cy) < half + tol))
        fb = FacetBasis(self.mesh, self.element, facets=facets, intorder=3)
        area = Functional(lambda w: 1.0 + 0.0 * w.x[0]).assemble(fb)

        @LinearForm
        def component(v, w):
            return v[axis]

        return np.asarray(component.assemble(fb)) / area

    def point_operator(self, points: np.ndarray) -> sp.csr_matrix:
        """Return P (3 k x N) with (P u)[3 j + i] = u_i at points[j] (the FE interpolation)."""
        probes = self.basis.probes(np.asarray(points, dtype=float).T)
        return sp.csr_matrix(probes)

    def parity_bases(self) -> list[sp.csr_matrix]:
        """
        Return the bases T of the four mirror parities of the mesh about the group centre.

        The planes x = x_c and y = y_c through the pile group's centre; each T
        (N x n_p, entries 0 and +-1, up to 4 on a node in both planes) spans the
        displacement fields symmetric or antisymmetric about each plane, and the
        four together span every field. A mesh that its mirrors do not map onto
        itself gives the identity alone.
        """
        from scipy.spatial import cKDTree  # noqa: I202

        p = self.mesh.p.T
        piles = self.spec.piles
        centre = np.array(piles.centre) if piles is not None else np.zeros(2)
        scale = float(np.ptp(p, axis=0).max())
        tree = cKDTree(p)
        images = []
        for axis in (0, 1):
            mirrored = p.copy()
            mirrored[:, axis] = 2.0 * centre[axis] - p[:, axis]
            dist, idx = tree.query(mirrored)
            if dist.max() > 1e-9 * scale:
                return [sp.identity(self.basis.N, format='csr')]
            images.append(idx)
        mx, my = images
        rep = np.flatnonzero((p[:, 0] >= centre[0] - 1e-9 * scale)
                             & (p[:, 1] >= centre[1] - 1e-9 * scale))
        out = []
        for px in (1.0, -1.0):
            for py in (1.0, -1.0):
                # a field symmetric about x = x_c flips u_x in the mirror, keeps u_y, u_z
                sx = px * np.array([-1.0, 1.0, 1.0])
                sy = py * np.array([1.0, -1.0, 1.0])
                rows, cols, vals = [], [], []
                column = 3 * np.arange(len(rep))[:, None] + np.arange(3)
                for nodes, sign in ((rep, np.ones(3)), (mx[rep], sx), (my[rep], sy),
                                    (mx[my[rep]], sx * sy)):
                    rows.append((3 * nodes[:, None] + np.arange(3)).ravel())
                    cols.append(column.ravel())
                    vals.append(np.tile(sign, len(rep)))
                t = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                          np.concatenate(cols))),
                                  shape=(self.basis.N, 3 * len(rep)))
                t.eliminate_zeros()
                out.append(t[:, np.flatnonzero(np.diff(t.indptr))].tocsr())
        return out

    def response(self, frequency: float, load: np.ndarray, head: np.ndarray,
                 points: np.ndarray, method: str = 'auto') -> BlockResponse:
        """
        Solve (K + i w C - w^2 M) u = load at ``frequency``; return head and point values.

        The solution is the sum of its four mirror-parity parts
        (:meth:`parity_bases`), each solved on its own quarter-size subspace
        (T^T Z T q = T^T F: exact, as Z commutes with the mirrors).
        """
        w = 2.0 * math.pi * frequency
        free = np.setdiff1d(np.arange(self.basis.N), self.fixed)
        z = (self.stiffness + 1j * w * self.damping - w * w * self.mass).tocsr()
        z = z[free][:, free]
        f = load[free].astype(complex)
        u = np.zeros(self.basis.N, dtype=complex)
        unknowns = 0
        for basis in self.parity_bases():
            t = basis[free]
            t = t[:, np.flatnonzero(np.diff(t.tocsc().indptr))].tocsr()
            rhs = t.T @ f
            if np.abs(rhs).max(initial=0.0) <= 1e-12 * np.abs(f).max(initial=0.0):
                continue  # the load has no part of this parity (round-off aside)
            reduced = (t.T @ z @ t).tocsc()
            u[free] += t @ factorize_complex(reduced, method=method).solve(rhs)
            unknowns += t.shape[1]
        probes = self.point_operator(points) if len(points) else None
        # probes rows are grouped by component: (u^1 at all points, u^2 ..., u^3 ...)
        values = (probes @ u).reshape(3, -1).T if probes is not None else np.zeros((0, 3))
        return BlockResponse(frequency, complex(head @ u), values, unknowns)
