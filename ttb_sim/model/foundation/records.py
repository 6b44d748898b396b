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
Records describing a pier-cap-pile-soil substructure and its load (SI units).

Frozen dataclasses whose user-settable fields are declared once with
:func:`~ttb_sim.declarations.param` (default, unit, range, description): the
scenario sections ``soil``, ``piles``, ``cap``, ``interface`` and ``load`` are
these records, so every field is a scenario key. A bad value raises
:class:`FoundationError` naming the key, the value and what is allowed.
Checks that involve several records (piles inside the block, pile shorter
than the deposit, mesh fine enough for the load) are in
:func:`~.consistency.check_substructure`.

Geometry: x along the track, y to the left, z up; the ground surface is
z = 0 and the plan origin is the centre of the soil block. Piles are numbered
from 1, starting at the pile with the smallest x and y, x running fastest
(``cols`` piles along x, ``rows`` along y). A circular pile of diameter d is
represented by the square of equal area, side sqrt(pi)/2 d = 0.886 d.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math
from typing import Optional

from ttb_sim.declarations import check_declared, param
from ttb_sim.errors import ModelError
from ttb_sim.model.constants import GRAVITY

#: Side of the square of equal area over the diameter of a circle, sqrt(pi) / 2.
EQUAL_AREA_SIDE = math.sqrt(math.pi) / 2.0


class FoundationError(ModelError):
    """A pile-soil substructure or its load is described by invalid values."""


def _check_pair(key: str, value: tuple[float, ...], low: float, high: float) -> None:
    """Refuse a plan position / frequency pair that is not two finite numbers in [low, high]."""
    if len(value) != 2 or not all(math.isfinite(v) and low <= v <= high for v in value):
        raise FoundationError(f'{key} = {list(value)!r} is invalid; allowed: two numbers '
                              f'in [{low:g}, {high:g}]')


@dataclass(frozen=True)
class SoilLayer:
    """One horizontal soil layer (an entry of ``soil.layers``, top down)."""

    thickness: float = param(2.0, 'm', 'Layer thickness.', low=0.0, high=1000.0,
                             low_inclusive=False)
    E: float = param(5e6, 'Pa', "Young's modulus.", low=0.0, high=1e12, low_inclusive=False)
    nu: float = param(0.3, '-', "Poisson's ratio.", low=0.0, high=0.5, high_inclusive=False)
    rho: float = param(1900.0, 'kg/m^3', 'Density.', low=0.0, high=1e5, low_inclusive=False)
    c: float = param(10e3, 'Pa', 'Cohesion, the pile-soil adhesion (interface.adhesion_ratio '
                     'times it).', low=0.0, high=1e9)
    phi: float = param(30.0, 'deg', 'Friction angle, the pile-soil friction angle '
                       '(interface.friction_ratio times its tangent).', low=0.0, high=60.0)
    damping_ratio: float = param(0.05, '-', 'Rayleigh damping ratio at the two '
                                 'soil.rayleigh_frequencies.', low=0.0, high=1.0,
                                 high_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'soil.layers.', FoundationError)

    @property
    def G(self) -> float:
        """Shear modulus (Pa)."""
        return self.E / (2 * (1 + self.nu))

    @property
    def vs(self) -> float:
        """Shear-wave speed (m/s)."""
        return math.sqrt(self.G / self.rho)

    @property
    def constrained_modulus(self) -> float:
        """Constrained (oedometric) modulus E (1 - nu) / ((1 + nu) (1 - 2 nu)) (Pa)."""
        return self.E * (1 - self.nu) / ((1 + self.nu) * (1 - 2 * self.nu))

    @property
    def vp(self) -> float:
        """Compression-wave speed (m/s)."""
        return math.sqrt(self.constrained_modulus / self.rho)


#: The three layers of [P] Table 5, moduli read in Pa (PHYSICS.md 6.1), rho = gamma / g.
PAPER_LAYERS: tuple[SoilLayer, ...] = (
    SoilLayer(2.0, 4e6, 0.35, 18e3 / GRAVITY, 20e3, 5.0),
    SoilLayer(4.0, 5e6, 0.25, 19e3 / GRAVITY, 15e3, 30.0),
    SoilLayer(16.0, 6e6, 0.25, 15e3 / GRAVITY, 10e3, 30.0))


@dataclass(frozen=True)
class BlockSize:
    """Plan size of the soil block, centred on the origin (its depth is the layers' sum)."""

    lx: float = param(40.0, 'm', 'Plan size of the soil block along x (the track).', low=0.0,
                      high=10000.0, low_inclusive=False)
    ly: float = param(34.0, 'm', 'Plan size of the soil block along y (across the track).',
                      low=0.0, high=10000.0, low_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'soil.block.', FoundationError)


@dataclass(frozen=True)
class MeshSize:
    """Element sizes of the structured brick mesh (``soil.mesh``)."""

    h: float = param(0.5, 'm', 'Element size in and around the pile group (and along the '
                     'piles up to soil.mesh.h_shaft).', low=0.0, high=1000.0,
                     low_inclusive=False)
    growth: float = param(1.25, '-', 'Size ratio of neighbouring elements away from the '
                          'group.', low=1.0, high=2.0)
    h_max: float = param(2.0, 'm', 'Largest element size, far from the group; sets the '
                         'highest frequency the mesh carries, f_max = Vs_min / '
                         '(points_per_wavelength h_max).', low=0.0, high=1000.0,
                         low_inclusive=False)
    h_shaft: float = param(0.0, 'm', 'Largest vertical element size along the piles; 0 = '
                           'min(h_max, 4 h).', low=0.0, high=1000.0)
    max_aspect: float = param(12.0, '-', 'Largest allowed element aspect ratio (longest / '
                              'shortest edge).', low=1.0, high=1000.0)
    points_per_wavelength: float = param(8.0, '-', 'Elements per shear wavelength that '
                                         'define the highest frequency a mesh size carries.',
                                         low=2.0, high=100.0)
    incompatible_modes: str = param(
        'none', '-', "Wilson's incompatible modes in the bricks, condensed out (the same "
        'DOFs; exact in pure bending, so no shear locking): '
        "'none'; 'structure' = in the piles and the cap (where the plain brick locks: the "
        "piled pier's master stiffness then moves 0.7-2.5 % under halving, not 0.8-8.6 %); "
        "'all' = in the soil too.", choices=('none', 'structure', 'all'))

    def __post_init__(self) -> None:
        """Check every field against its declaration, and h <= h_max."""
        check_declared(self, 'soil.mesh.', FoundationError)
        if self.h_max < self.h:
            raise FoundationError(f'soil.mesh.h_max = {self.h_max!r} is below soil.mesh.h = '
                                  f'{self.h!r}; allowed: h_max >= h')

    @property
    def shaft(self) -> float:
        """Largest vertical element size along the piles (m)."""
        return self.h_shaft if self.h_shaft > 0 else min(self.h_max, 4 * self.h)

    def enriches(self, soil: bool) -> bool:
        """Tell whether soil bricks (True) or pile and cap bricks (False) get the modes."""
        return self.incompatible_modes == 'all' or (
            not soil and self.incompatible_modes == 'structure')


@dataclass(frozen=True)
class ReductionParameters:
    """
    Reduced-order model of a piled pier for the coupled run (``soil.reduction``).

    The soil-pile-cap interior is replaced by the static modes of the cap-top
    master plus second-order block Krylov vectors of the master loads at shifts
    s = 2 pi f (or i 2 pi f) (see :mod:`.reduction`): up to 6 vectors per level
    and real shift, 12 per imaginary one.
    """

    shifts: tuple[float, ...] = param(
        (0.0, 5.0, 10.0, 20.0, 30.0), 'Hz', 'Expansion points f of the Krylov vectors '
        '(shift s = 2 pi f, or i 2 pi f, see soil.reduction.shift_axis); 0 = about the '
        'static solution.', low=0.0, high=1000.0)
    shift_axis: str = param('real', '-', "Where the shifts lie: 'imaginary' = s = i 2 pi "
                            'f, the complex pencil K - w^2 M + i w C factorised by MKL PARDISO '
                            '(the pardiso extra) or else by LDL^T of its real 2n form; '
                            "'real' = s = 2 pi f, the positive definite K + s C + s^2 M "
                            '(Cholesky).', choices=('imaginary', 'real'))
    levels: int = param(8, '-', 'Krylov levels per shift (each adds up to 6 vectors).',
                        low=1, high=100)
    tolerance: float = param(1e-9, '-', 'Deflation: a new direction is dropped when its '
                             'part outside the basis is below this fraction of its norm.',
                             low=0.0, high=0.1, low_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration, and one shift at least, all distinct."""
        check_declared(self, 'soil.reduction.', FoundationError)
        if not self.shifts or len(set(self.shifts)) != len(self.shifts):
            raise FoundationError(f'soil.reduction.shifts = {list(self.shifts)!r}; allowed: '
                                  'one or more distinct frequencies in [0, 1000] Hz')
        if not all(math.isfinite(f) and 0.0 <= f <= 1000.0 for f in self.shifts):
            raise FoundationError(f'soil.reduction.shifts = {list(self.shifts)!r}; allowed: '
                                  'one or more distinct frequencies in [0, 1000] Hz')


@dataclass(frozen=True)
class SoilParameters:
    """The layered soil block: layers, plan size, mesh and boundary (``soil``)."""

    layers: tuple[SoilLayer, ...] = param(
        PAPER_LAYERS, '-', 'Soil layers, top down, each {thickness, E, nu, rho, c, phi, '
        'damping_ratio} (c, phi and damping_ratio may be left out: 10e3 Pa, 30 deg, 0.05); '
        "default: [P] Table 5's three layers.")
    block: BlockSize = field(default_factory=BlockSize)
    mesh: MeshSize = field(default_factory=MeshSize)
    reduction: ReductionParameters = field(default_factory=ReductionParameters)
    boundary: str = param('viscoelastic', '-', "Sides and base: 'viscoelastic' = springs "
                          'alpha G / R and dashpots rho Vs, rho Vp per unit area ([P] Eq. 3, R '
                          "from the group centre); 'lysmer' = the dashpots only; 'fixed' = "
                          "base fixed, sides on rollers; 'rigid_base' = base fixed under "
                          'viscous-spring sides (a stratum on bedrock).',
                          choices=('viscoelastic', 'lysmer', 'fixed', 'rigid_base'))
    alpha_t: float = param(0.67, '-', 'Tangential coefficient of the viscous-spring boundary '
                           '(3-D value of Liu et al.).', low=0.0, high=100.0,
                           low_inclusive=False)
    alpha_n: float = param(1.33, '-', 'Normal coefficient of the viscous-spring boundary.',
                           low=0.0, high=100.0, low_inclusive=False)
    boundary_lumping: str = param('lumped', '-', 'Boundary matrices: tributary-area lumped or '
                                  'consistent.', choices=('lumped', 'consistent'))
    periodic: bool = param(False, '-', 'Lateral faces tied periodically (a site-response '
                           'column without piles; the boundary acts on the base only).')
    rayleigh_frequencies: tuple[float, ...] = param(
        (1.0, 20.0), 'Hz', 'The two frequencies at which every material (soil, piles, cap) '
        'has its damping ratio (Rayleigh damping).', low=0.0, high=1e4, low_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration, and the frequency pair."""
        check_declared(self, 'soil.', FoundationError)
        if not self.layers:
            raise FoundationError('soil.layers = [] must list at least one layer')
        _check_pair('soil.rayleigh_frequencies', self.rayleigh_frequencies, 1e-6, 1e4)
        f1, f2 = self.rayleigh_frequencies
        if f2 <= f1:
            raise FoundationError(f'soil.rayleigh_frequencies = {[f1, f2]!r}: the second must '
                                  'be above the first')

    @property
    def lx(self) -> float:
        """Plan size along x (m)."""
        return self.block.lx

    @property
    def ly(self) -> float:
        """Plan size along y (m)."""
        return self.block.ly

    @property
    def depth(self) -> float:
        """Depth of the block (m)."""
        return float(sum(layer.thickness for layer in self.layers))

    def layer_tops(self) -> list[float]:
        """Return the z of each layer's top (m, 0 at the surface, negative below)."""
        tops = [0.0]
        for layer in self.layers[:-1]:
            tops.append(tops[-1] - layer.thickness)
        return tops

    @property
    def vs_min(self) -> float:
        """Smallest shear-wave speed of the layers (m/s)."""
        return min(layer.vs for layer in self.layers)


@dataclass(frozen=True)
class PileGroup:
    """
    A rectangular group of identical vertical piles with heads at the ground surface.

    ``cols`` piles along x and ``rows`` along y; numbered from 1 at the smallest
    x and y, x running fastest. A circular pile is the square of equal area.
    """

    rows: int = param(3, '-', 'Number of pile rows (piles along y).', low=1, high=50)
    cols: int = param(5, '-', 'Number of pile columns (piles along x, the track).', low=1,
                      high=50)
    spacing: float = param(3.0, 'm', 'Centre-to-centre spacing in both directions.', low=0.0,
                           high=1000.0, low_inclusive=False)
    side: float = param(0.0, 'm', 'Side of a square pile; 0 = the square of equal area of '
                        'piles.diameter (side 0.886 d).', low=0.0, high=100.0)
    diameter: float = param(1.0, 'm', 'Diameter of a circular pile (used when piles.side '
                            'is 0).', low=0.0, high=100.0, low_inclusive=False)
    length: float = param(12.0, 'm', 'Pile length below the ground surface.', low=0.0,
                          high=1000.0, low_inclusive=False)
    E: float = param(1e11, 'Pa', "Young's modulus of the piles.", low=0.0, high=1e13,
                     low_inclusive=False)
    nu: float = param(0.2, '-', "Poisson's ratio of the piles.", low=0.0, high=0.5,
                      high_inclusive=False)
    rho: float = param(25e3 / GRAVITY, 'kg/m^3', 'Density of the piles (25 kN/m^3).', low=0.0,
                       high=1e5, low_inclusive=False)
    damping_ratio: float = param(0.02, '-', 'Rayleigh damping ratio of the piles.', low=0.0,
                                 high=1.0, high_inclusive=False)
    centre: tuple[float, ...] = param((0.0, 0.0), 'm', 'Plan position (x, y) of the group '
                                      'centre in the soil block.', low=-5000.0, high=5000.0)

    def __post_init__(self) -> None:
        """Check every field against its declaration, the centre and the spacing."""
        check_declared(self, 'piles.', FoundationError)
        _check_pair('piles.centre', self.centre, -5000.0, 5000.0)
        if self.count > 1 and self.spacing <= self.width:
            message = (f'piles.spacing = {self.spacing!r} m makes the piles (width '
                       f'{self.width:.4g} m) overlap or touch; allowed: > {self.width:.4g} m')
            raise FoundationError(message)

    @property
    def width(self) -> float:
        """Side of the (equivalent) square pile (m)."""
        return float(self.side) if self.side > 0 else EQUAL_AREA_SIDE * float(self.diameter)

    @property
    def count(self) -> int:
        """Number of piles."""
        return self.rows * self.cols

    def centres(self) -> list[tuple[float, float]]:
        """Return the plan position of each pile (m), in pile-number order (x fastest)."""
        x0 = self.centre[0] - 0.5 * (self.cols - 1) * self.spacing
        y0 = self.centre[1] - 0.5 * (self.rows - 1) * self.spacing
        return [(x0 + c * self.spacing, y0 + r * self.spacing)
                for r in range(self.rows) for c in range(self.cols)]


@dataclass(frozen=True)
class Cap:
    """The pile cap: solid elements on the ground surface, bonded to the pile heads."""

    enabled: bool = param(False, '-', 'Model the cap (for the coupled model; the '
                          'substructure scenarios leave the pile heads free).')
    lx: float = param(15.0, 'm', 'Cap size along x ([P] Table 6).', low=0.0, high=1000.0,
                      low_inclusive=False)
    ly: float = param(9.0, 'm', 'Cap size along y ([P] Table 6).', low=0.0, high=1000.0,
                      low_inclusive=False)
    thickness: float = param(2.5, 'm', 'Cap thickness ([P] Table 6).', low=0.0, high=100.0,
                             low_inclusive=False)
    E: float = param(3.25e10, 'Pa', "Young's modulus of the cap.", low=0.0, high=1e13,
                     low_inclusive=False)
    nu: float = param(0.2, '-', "Poisson's ratio of the cap.", low=0.0, high=0.5,
                      high_inclusive=False)
    rho: float = param(2500.0, 'kg/m^3', 'Density of the cap.', low=0.0, high=1e5,
                       low_inclusive=False)
    damping_ratio: float = param(0.02, '-', 'Rayleigh damping ratio of the cap.', low=0.0,
                                 high=1.0, high_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'cap.', FoundationError)


@dataclass(frozen=True)
class Interface:
    """The pile-soil interface (see :mod:`.desai`)."""

    model: str = param('desai', '-', "'desai': Desai thin-layer elements between duplicated "
                       "nodes on the pile shafts and tips ([P] Eqs. 4-10); 'bonded': shared "
                       'nodes.', choices=('desai', 'bonded'))
    thickness: float = param(0.02, 'm', 'Notional thickness t of the thin layer ([P]: 0.01 to '
                             '0.1 of the element size).', low=0.0, high=10.0,
                             low_inclusive=False)
    failure_ratio: float = param(0.9, '-', 'Clough-Duncan failure ratio R_f.', low=0.0,
                                 high=1.0, low_inclusive=False, high_inclusive=False)
    friction_ratio: float = param(1.0, '-', 'tan(delta) / tan(phi) of the adjacent layer.',
                                  low=0.0, high=1.0)
    adhesion_ratio: float = param(1.0, '-', 'Adhesion over the cohesion c of the adjacent '
                                  'layer.', low=0.0, high=1.0)
    shear_modulus: str = param('G', '-', 'Initial shear modulus of the thin layer: the '
                               "layer's G, or Lame's lambda as [P] Eq. 9 reads.",
                               choices=('G', 'lame'))
    k0: float = param(0.0, '-', 'Earth pressure coefficient on the shafts; 0 = Jaky, '
                      '1 - sin(phi).', low=0.0, high=3.0)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'interface.', FoundationError)


_LOAD_TYPES = ("'static' (one frame at t = 0 with the static solution), 'harmonic' "
               "(A sin(2 pi f t) from rest at t = 0), 'pulse' (one half sine of duration "
               "1 / (2 f)); 'none' = no substructure load (a train run).")


@dataclass(frozen=True)
class PileLoad:
    """
    A load on the pile-soil substructure alone (``load``).

    ``type`` 'none' (the default) means no substructure load: the scenario is a
    train run. Any other type makes the scenario a substructure-only run.
    """

    type: str = param('none', '-', _LOAD_TYPES,  # noqa: A003 - the contract key is load.type
                      choices=('none', 'static', 'harmonic', 'pulse'))
    amplitude: float = param(10e3, 'N', 'Force amplitude.', low=-1e10, high=1e10)
    frequency: float = param(20.0, 'Hz', 'Frequency of a harmonic load or pulse.', low=0.0,
                             high=1e4, low_inclusive=False)
    pile: int = param(5, '-', 'Loaded pile, 1-based (from the smallest x and y, x running '
                      'fastest).', low=1, high=2500)
    direction: str = param('z', '-', 'Direction of the force.', choices=('x', 'y', 'z'))
    target: str = param('pile', '-', "'pile': a uniform pressure on the pile head; "
                        "'surface': on the whole ground surface; 'cap': on the cap top "
                        '(load.pile is then the pile whose head is reported).',
                        choices=('pile', 'surface', 'cap'))

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'load.', FoundationError)

    @property
    def kind(self) -> str:
        """The load type (``type``)."""
        return self.type

    def history(self, t: float) -> float:
        """Return the load factor at time t (s)."""
        if self.type in ('static', 'none'):
            return 1.0
        w = 2 * math.pi * self.frequency
        if self.type == 'harmonic':
            return math.sin(w * t)
        return math.sin(w * t) if 0.0 <= t <= 0.5 / self.frequency else 0.0


@dataclass(frozen=True)
class Observation:
    """
    Soil observation points besides the pile heads.

    Attributes
    ----------
    line_points : int
        Points on [P]'s observation line (ground surface, midway between the
        first two pile rows, across the group extent plus one spacing); 0: none.
    val_points : bool
        [P] section 4.2.2's three points: 1 m outside the faces of piles 5 and
        14 along -y and +y, and midway between them (at the ground surface).
    points : tuple of (x, y, z)
        User points (m).
    grid_spacing : float
        Spacing (m) of a ground-surface grid over the cap's footprint (the pile
        group's extent without a cap) plus ``grid_margin`` on every side; 0: none.
    grid_margin : float
        Margin of that grid beyond the footprint (m).

    """

    line_points: int = 21
    val_points: bool = True
    points: tuple[tuple[float, ...], ...] = ()
    grid_spacing: float = 0.0
    grid_margin: float = 0.0


@dataclass(frozen=True)
class Substructure:
    """
    A pile-soil substructure: soil, piles (or none), cap, interface, observation.

    Attributes
    ----------
    name : str
        Group name (``pier01`` for a substructure-only scenario).
    soil, piles, cap, interface, observation : records
        The parts; ``piles=None`` is a soil block without piles.

    """

    name: str = 'pier01'
    soil: SoilParameters = field(default_factory=SoilParameters)
    piles: Optional[PileGroup] = field(default_factory=PileGroup)
    cap: Cap = field(default_factory=Cap)
    interface: Interface = field(default_factory=Interface)
    observation: Observation = field(default_factory=Observation)

    @property
    def mesh(self) -> MeshSize:
        """Element sizes (``soil.mesh``)."""
        return self.soil.mesh

    @property
    def rayleigh_frequencies(self) -> tuple[float, float]:
        """The two Rayleigh reference frequencies (Hz)."""
        f1, f2 = self.soil.rayleigh_frequencies
        return float(f1), float(f2)
