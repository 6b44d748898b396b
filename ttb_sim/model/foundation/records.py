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

Frozen dataclasses validated on construction: a bad value raises
:class:`FoundationError` naming the argument, the value and what is allowed.
Checks that involve several records (piles inside the block, pile shorter
than the deposit, mesh fine enough for the load) are in
:func:`check_substructure`.

Geometry: x along the track, y to the left, z up; the ground surface is
z = 0 and the plan origin is the centre of the soil block. Piles are numbered
from 1, starting at the pile with the smallest x and y, x running fastest
(``cols`` piles along x, ``rows`` along y). A circular pile of diameter d is
represented by the square of equal area, side sqrt(pi)/2 d = 0.886 d.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math
from typing import Literal, Optional

from ttb_sim.errors import ModelError

GRAVITY = 9.81
#: Side of the square of equal area over the diameter of a circle, sqrt(pi) / 2.
EQUAL_AREA_SIDE = math.sqrt(math.pi) / 2.0

BoundaryType = Literal['viscoelastic', 'lysmer', 'fixed']
InterfaceModel = Literal['desai', 'bonded']
LoadType = Literal['static', 'harmonic', 'pulse']


class FoundationError(ModelError):
    """A pile-soil substructure or its load is described by invalid values."""


def _check(name: str, value: float, low: float | None = None, high: float | None = None,
           low_open: bool = False, high_open: bool = False) -> None:
    """Raise FoundationError unless low <= value <= high (open ends when asked)."""
    ok = math.isfinite(value)
    if ok and low is not None:
        ok = value > low if low_open else value >= low
    if ok and high is not None:
        ok = value < high if high_open else value <= high
    if not ok:
        lo = '(' if low_open else '['
        hi = ')' if high_open else ']'
        allowed = f'{lo}{"-inf" if low is None else f"{low:g}"}, ' \
                  f'{"inf" if high is None else f"{high:g}"}{hi}'
        message = f'{name} = {value!r} is outside the allowed range {allowed}'
        raise FoundationError(message)


def _choice(name: str, value: str, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        message = f'{name} = {value!r} is not one of {", ".join(allowed)}'
        raise FoundationError(message)


@dataclass(frozen=True)
class SoilLayer:
    """
    One horizontal soil layer.

    Attributes
    ----------
    thickness : float
        Layer thickness (m), > 0.
    E : float
        Young's modulus (Pa), > 0.
    nu : float
        Poisson's ratio, in [0, 0.5).
    rho : float
        Density (kg/m^3), > 0.
    c : float
        Cohesion, used as the interface adhesion (Pa), >= 0.
    phi : float
        Friction angle (degrees), in [0, 60].
    damping_ratio : float
        Rayleigh damping ratio at the two reference frequencies, in [0, 1).

    """

    thickness: float
    E: float
    nu: float
    rho: float
    c: float = 10e3
    phi: float = 30.0
    damping_ratio: float = 0.05

    def __post_init__(self) -> None:
        _check('soil.layers.thickness', self.thickness, 0.0, low_open=True)
        _check('soil.layers.E', self.E, 0.0, low_open=True)
        _check('soil.layers.nu', self.nu, 0.0, 0.5, high_open=True)
        _check('soil.layers.rho', self.rho, 0.0, low_open=True)
        _check('soil.layers.c', self.c, 0.0)
        _check('soil.layers.phi', self.phi, 0.0, 60.0)
        _check('soil.layers.damping_ratio', self.damping_ratio, 0.0, 1.0, high_open=True)

    @property
    def G(self) -> float:
        """Shear modulus (Pa)."""
        return self.E / (2 * (1 + self.nu))

    @property
    def vs(self) -> float:
        """Shear-wave speed (m/s)."""
        return math.sqrt(self.G / self.rho)

    @property
    def vp(self) -> float:
        """Compression-wave speed (m/s)."""
        return math.sqrt(self.E * (1 - self.nu) / ((1 + self.nu) * (1 - 2 * self.nu) * self.rho))


#: The three layers of [P] Table 5, moduli read in Pa (PHYSICS.md 6.1), rho = gamma / g.
PAPER_LAYERS: tuple[SoilLayer, ...] = (
    SoilLayer(2.0, 4e6, 0.35, 18e3 / GRAVITY, 20e3, 5.0),
    SoilLayer(4.0, 5e6, 0.25, 19e3 / GRAVITY, 15e3, 30.0),
    SoilLayer(16.0, 6e6, 0.25, 15e3 / GRAVITY, 10e3, 30.0))


@dataclass(frozen=True)
class SoilBlock:
    """
    The layered soil block.

    Attributes
    ----------
    layers : tuple of SoilLayer
        Top down; the block depth is the sum of the thicknesses.
    lx, ly : float
        Plan size (m), > 0.
    boundary : {'viscoelastic', 'lysmer', 'fixed'}
        Viscous-spring boundary ([P] Eq. 3) on the sides and base; dashpots
        only; or base fixed with the sides on rollers.
    alpha_t, alpha_n : float
        Viscous-spring coefficients (Liu et al. 3-D values 0.67 and 1.33).
    boundary_lumping : {'lumped', 'consistent'}
        Tributary-area or consistent boundary matrices.
    periodic : bool
        Lateral faces tied periodically (a site-response column; no piles), with
        ``boundary`` then acting on the base only.

    """

    layers: tuple[SoilLayer, ...] = PAPER_LAYERS
    lx: float = 40.0
    ly: float = 34.0
    boundary: BoundaryType = 'viscoelastic'
    alpha_t: float = 0.67
    alpha_n: float = 1.33
    boundary_lumping: Literal['lumped', 'consistent'] = 'lumped'
    periodic: bool = False

    def __post_init__(self) -> None:
        if not self.layers:
            raise FoundationError('soil.layers = [] must list at least one layer')
        _check('soil.block.lx', self.lx, 0.0, low_open=True)
        _check('soil.block.ly', self.ly, 0.0, low_open=True)
        _choice('soil.boundary', self.boundary, ('viscoelastic', 'lysmer', 'fixed'))
        _check('soil.alpha_t', self.alpha_t, 0.0, low_open=True)
        _check('soil.alpha_n', self.alpha_n, 0.0, low_open=True)
        _choice('soil.boundary_lumping', self.boundary_lumping, ('lumped', 'consistent'))

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

    Attributes
    ----------
    rows, cols : int
        Number of piles along y and along x, >= 1.
    spacing : float
        Centre-to-centre spacing in both directions (m).
    side, diameter : float or None
        Square side (m), or a diameter replaced by the equal-area square (0.886 d).
    length : float
        Pile length below the ground surface (m).
    E, nu, rho : float
        Pile material (Pa, -, kg/m^3).
    damping_ratio : float
        Rayleigh damping ratio of the piles.
    centre : (float, float)
        Plan position of the group centre (m).

    """

    rows: int = 3
    cols: int = 5
    spacing: float = 3.0
    side: Optional[float] = None
    diameter: Optional[float] = 1.0
    length: float = 12.0
    E: float = 1e11
    nu: float = 0.2
    rho: float = 25e3 / GRAVITY
    damping_ratio: float = 0.02
    centre: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        _check('piles.rows', self.rows, 1)
        _check('piles.cols', self.cols, 1)
        if self.side is None and self.diameter is None:
            raise FoundationError('piles.side and piles.diameter are both unset; give one')
        if self.side is not None:
            _check('piles.side', self.side, 0.0, low_open=True)
        if self.diameter is not None and self.side is None:
            _check('piles.diameter', self.diameter, 0.0, low_open=True)
        _check('piles.length', self.length, 0.0, low_open=True)
        _check('piles.E', self.E, 0.0, low_open=True)
        _check('piles.nu', self.nu, 0.0, 0.5, high_open=True)
        _check('piles.rho', self.rho, 0.0, low_open=True)
        _check('piles.damping_ratio', self.damping_ratio, 0.0, 1.0, high_open=True)
        if self.rows * self.cols > 1 and self.spacing <= self.width:
            message = (f'piles.spacing = {self.spacing!r} m makes the piles (width '
                       f'{self.width:.4g} m) overlap or touch; allowed: > {self.width:.4g} m')
            raise FoundationError(message)

    @property
    def width(self) -> float:
        """Side of the (equivalent) square pile (m)."""
        if self.side is not None:
            return float(self.side)
        assert self.diameter is not None
        return EQUAL_AREA_SIDE * float(self.diameter)

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
    """
    The pile cap: solid elements on the ground surface, bonded to the pile heads.

    Attributes
    ----------
    enabled : bool
        Whether the cap is modelled.
    lx, ly, thickness : float
        Plan size and thickness (m) ([P] Table 6: 15 x 9 x 2.5 m).
    E, nu, rho, damping_ratio : float
        Material (Pa, -, kg/m^3, -).

    """

    enabled: bool = False
    lx: float = 15.0
    ly: float = 9.0
    thickness: float = 2.5
    E: float = 3.25e10
    nu: float = 0.2
    rho: float = 2500.0
    damping_ratio: float = 0.02

    def __post_init__(self) -> None:
        _check('cap.lx', self.lx, 0.0, low_open=True)
        _check('cap.ly', self.ly, 0.0, low_open=True)
        _check('cap.thickness', self.thickness, 0.0, low_open=True)
        _check('cap.E', self.E, 0.0, low_open=True)
        _check('cap.nu', self.nu, 0.0, 0.5, high_open=True)
        _check('cap.rho', self.rho, 0.0, low_open=True)
        _check('cap.damping_ratio', self.damping_ratio, 0.0, 1.0, high_open=True)


@dataclass(frozen=True)
class Interface:
    """
    The pile-soil interface.

    Attributes
    ----------
    model : {'desai', 'bonded'}
        Desai thin-layer elements between duplicated nodes, or shared nodes.
    thickness : float
        Notional layer thickness t (m); [P] takes 0.01-0.1 of the element size.
    failure_ratio : float
        Clough-Duncan R_f, in (0, 1).
    friction_ratio, adhesion_ratio : float
        tan(delta) / tan(phi) and adhesion / cohesion of the adjacent layer.
    shear_modulus : {'G', 'lame'}
        Initial shear modulus of the layer (see :mod:`.desai`).
    k0 : float or None
        Earth pressure coefficient on the shafts; None takes Jaky's 1 - sin(phi).

    """

    model: InterfaceModel = 'desai'
    thickness: float = 0.02
    failure_ratio: float = 0.9
    friction_ratio: float = 1.0
    adhesion_ratio: float = 1.0
    shear_modulus: Literal['G', 'lame'] = 'G'
    k0: Optional[float] = None

    def __post_init__(self) -> None:
        _choice('interface.model', self.model, ('desai', 'bonded'))
        _check('interface.thickness', self.thickness, 0.0, low_open=True)
        _check('interface.failure_ratio', self.failure_ratio, 0.0, 1.0, True, True)
        _check('interface.friction_ratio', self.friction_ratio, 0.0, 1.0)
        _check('interface.adhesion_ratio', self.adhesion_ratio, 0.0, 1.0)
        _choice('interface.shear_modulus', self.shear_modulus, ('G', 'lame'))
        if self.k0 is not None:
            _check('interface.k0', self.k0, 0.0, 3.0)


@dataclass(frozen=True)
class MeshSize:
    """
    Element sizes of the structured mesh.

    Attributes
    ----------
    h : float
        Element size in and around the pile group (m).
    growth : float
        Size ratio of neighbouring elements away from the group, in [1, 2].
    h_max : float
        Largest element size (m).
    h_shaft : float or None
        Largest vertical size along the piles (m); None takes min(h_max, 4 h).
    max_aspect : float
        Largest allowed element aspect ratio (longest / shortest edge).
    points_per_wavelength : float
        Elements per shear wavelength that define the highest frequency carried.

    """

    h: float = 0.5
    growth: float = 1.25
    h_max: float = 2.0
    h_shaft: Optional[float] = None
    max_aspect: float = 12.0
    points_per_wavelength: float = 8.0

    def __post_init__(self) -> None:
        _check('soil.mesh.h', self.h, 0.0, low_open=True)
        _check('soil.mesh.growth', self.growth, 1.0, 2.0)
        _check('soil.mesh.h_max', self.h_max, self.h)
        if self.h_shaft is not None:
            _check('soil.mesh.h_shaft', self.h_shaft, 0.0, low_open=True)
        _check('soil.mesh.max_aspect', self.max_aspect, 1.0)
        _check('soil.mesh.points_per_wavelength', self.points_per_wavelength, 2.0)

    @property
    def shaft(self) -> float:
        """Largest vertical element size along the piles (m)."""
        return self.h_shaft if self.h_shaft is not None else min(self.h_max, 4 * self.h)


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

    """

    line_points: int = 21
    val_points: bool = True
    points: tuple[tuple[float, float, float], ...] = ()


@dataclass(frozen=True)
class Substructure:
    """
    A pile-soil substructure: soil, piles (or none), cap, interface, mesh.

    Attributes
    ----------
    name : str
        Group name (``pier01`` for a substructure-only scenario).
    soil, piles, cap, interface, mesh, observation : records
        The parts; ``piles=None`` is a soil block without piles.
    rayleigh_frequencies : (float, float)
        The two frequencies (Hz) at which every material has its damping ratio.

    """

    name: str = 'pier01'
    soil: SoilBlock = field(default_factory=SoilBlock)
    piles: Optional[PileGroup] = field(default_factory=PileGroup)
    cap: Cap = field(default_factory=Cap)
    interface: Interface = field(default_factory=Interface)
    mesh: MeshSize = field(default_factory=MeshSize)
    observation: Observation = field(default_factory=Observation)
    rayleigh_frequencies: tuple[float, float] = (1.0, 20.0)

    def __post_init__(self) -> None:
        f1, f2 = self.rayleigh_frequencies
        _check('soil.rayleigh_frequencies[0]', f1, 0.0, low_open=True)
        _check('soil.rayleigh_frequencies[1]', f2, f1, low_open=True)


@dataclass(frozen=True)
class PileLoad:
    """
    A load on the substructure.

    Attributes
    ----------
    kind : {'static', 'harmonic', 'pulse'}
        (scenario key ``load.type``)
        Constant; A sin(2 pi f t) from t = 0; one half sine of duration 1 / (2 f).
    amplitude : float
        Force (N).
    frequency : float
        Hz (harmonic, pulse).
    pile : int
        Loaded pile, 1-based (target 'pile').
    direction : {'x', 'y', 'z'}
        Direction of the force.
    target : {'pile', 'surface'}
        A uniform pressure on the pile's head, or on the whole ground surface.

    """

    kind: LoadType = 'harmonic'
    amplitude: float = 10e3
    frequency: float = 20.0
    pile: int = 5
    direction: Literal['x', 'y', 'z'] = 'z'
    target: Literal['pile', 'surface'] = 'pile'

    def __post_init__(self) -> None:
        _choice('load.type', self.kind, ('static', 'harmonic', 'pulse'))
        _check('load.amplitude', self.amplitude)
        if self.kind != 'static':
            _check('load.frequency', self.frequency, 0.0, low_open=True)
        _check('load.pile', self.pile, 1)
        _choice('load.direction', self.direction, ('x', 'y', 'z'))
        _choice('load.target', self.target, ('pile', 'surface'))

    def history(self, t: float) -> float:
        """Return the load factor at time t (s)."""
        if self.kind == 'static':
            return 1.0
        w = 2 * math.pi * self.frequency
        if self.kind == 'harmonic':
            return math.sin(w * t)
        return math.sin(w * t) if 0.0 <= t <= 0.5 / self.frequency else 0.0


def check_substructure(spec: Substructure, load: Optional[PileLoad] = None) -> None:
    """
    Check what the single records cannot: geometry fits and mesh carries the load.

    Raises
    ------
    FoundationError
        Piles outside the block or the cap, a pile as long as the deposit or
        longer, a periodic block with piles, a load on a pile that does not
        exist, or a mesh whose near-pile size ``h`` cannot carry the load
        frequency (f > Vs_min / (points_per_wavelength h)).

    """
    soil, piles = spec.soil, spec.piles
    if piles is not None:
        if soil.periodic:
            raise FoundationError('soil.periodic = True is for soil columns; it cannot '
                                  'carry piles (set piles to none)')
        if piles.length >= soil.depth:
            message = (f'piles.length = {piles.length!r} m reaches the base of the '
                       f'{soil.depth:g} m deposit; allowed: < {soil.depth:g} m')
            raise FoundationError(message)
        half = 0.5 * piles.width
        xs = [c[0] for c in piles.centres()]
        ys = [c[1] for c in piles.centres()]
        margin = spec.mesh.h
        if (min(xs) - half < -0.5 * soil.lx + margin or max(xs) + half > 0.5 * soil.lx - margin
                or min(ys) - half < -0.5 * soil.ly + margin
                or max(ys) + half > 0.5 * soil.ly - margin):
            message = (f'piles extend over x [{min(xs) - half:g}, {max(xs) + half:g}] m, '
                       f'y [{min(ys) - half:g}, {max(ys) + half:g}] m: outside the soil block '
                       f'(soil.block.lx = {soil.lx:g}, ly = {soil.ly:g} m, centred at 0, '
                       f'less one element of {margin:g} m)')
            raise FoundationError(message)
        if spec.cap.enabled:
            if (max(abs(x) for x in xs) + half > 0.5 * spec.cap.lx + 1e-9
                    or max(abs(y) for y in ys) + half > 0.5 * spec.cap.ly + 1e-9):
                raise FoundationError(f'the cap ({spec.cap.lx:g} x {spec.cap.ly:g} m) does '
                                      'not cover the pile heads')
    if load is not None:
        if load.target == 'pile':
            count = piles.count if piles is not None else 0
            if load.pile > count:
                message = f'load.pile = {load.pile!r}; allowed: 1 .. {count} (piles in group)'
                raise FoundationError(message)
        if load.kind != 'static':
            carried = soil.vs_min / (spec.mesh.points_per_wavelength * spec.mesh.h)
            largest = soil.vs_min / (spec.mesh.points_per_wavelength * load.frequency)
            if load.frequency > carried:
                message = (f'load.frequency = {load.frequency:g} Hz is above the '
                           f'{carried:.3g} Hz that soil.mesh.h = {spec.mesh.h:g} m carries '
                           f'(Vs_min / ({spec.mesh.points_per_wavelength:g} h)); '
                           f'allowed: soil.mesh.h <= {largest:.3g} m for this load')
                raise FoundationError(message)
