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
Train-track-bridge interaction: multibody cars on the rails, solved in each step.

Both subsystems use Newmark's average-acceleration method with constant
effective matrices: the track-bridge matrix K + 2/dt C + 4/dt^2 M (sparse,
factorised once) and, per car, A = K + 2/dt (C + G(V)) + 4/dt^2 M (42 x 42,
inverted once per speed). At the end of a step both states are affine in the
contact forces g = (Fx, Fy, Fz, Mz) of the 8 wheels of every car (force of the
rail on the wheel, track axes):

* wheel contact points: w = w* + H A^-1 H^T g (exact, per car);
* rail head under each wheel: r = r* - R K^-1 R^T g. The effective track matrix
  is dominated by 4/dt^2 M, so its inverse is local: the rail's compliance at a
  wheel is the 12 x 12 block of K^-1 over the rail element under it (computed
  once by probing), and wheels (>= 2.5 m apart) do not see each other inside
  one step. The rail element under a wheel also deflects within itself, beyond
  what its nodes' cubic interpolation carries: r gets - C_i g, C_i the
  element's interior flexibility at the wheel (the element clamped at its
  nodes, :func:`ttb_sim.fe.beam.interior_compliance`; its velocity follows by
  the trapezoidal rule). Without it the rail would be too stiff under a wheel
  between its nodes, and the wheel would feel that at the element-passing
  frequency V / L_e: mainly in the lateral force, through the rail's twist,
  which the elements interpolate linearly. With it the static rail-head motion
  under a wheel is the same on any rail mesh.

The contact laws close the system, all at the end of the step: Hertz's normal
force on the vertical compression, the contact geometry (rolling radius,
contact angle and rigid-contact wheel height from the profile table at the
wheelset's lateral position relative to the rail; the compression is measured
from that height, which stays continuous when the contact jumps to the flange)
and Kalker's linear creep forces on the creepages, which are affine in the
end-of-step velocities, saturated by the Shen-Hedrick-Elkins law. A Newton
iteration solves them (with the derivatives of the geometry and of the
saturation); only the load scaling of the creep coefficients is taken from the
previous step (an explicit lag of O(dt)).
After the Newton iteration the track is solved exactly with those forces and
the rail displacement under every wheel is compared with the local prediction;
any mismatch above ``contact.tolerance`` is fed back and the iteration
repeated, so each step's contact forces satisfy the contact laws on the exact
track response to that tolerance.

Every variant takes the step compiled (:mod:`contact_step`, its kernels in
:mod:`rail_kernels` and :mod:`contact_kernels`). The lean ones solve the track
once per step instead of twice: the predictor's rail motion under the wheels
comes from each rail node's K^-1 columns on the DOFs near it (probed once, with
the compliance blocks, :mod:`rail_compliance`), the contact is iterated on it
and the track solved for predictor and contact loads together; the exact rail
motion then corrects the offsets as above, and the step is accepted when all
three components agree to the tolerance. ``reference`` solves the track twice.
The static start is :mod:`equilibrium`.
"""

from __future__ import annotations

import math

import numpy as np

from ttb_sim.errors import DivergenceError, ModelError
from ttb_sim.model.irregularity import TrackIrregularity
from ttb_sim.model.structure import Structure
from ttb_sim.model.vehicle.car import CarParameters
from ttb_sim.model.vehicle.matrices import gyroscopic_matrix, train_matrices, TrainMatrices
import ttb_sim.model.wheel_rail as ct
from ttb_sim.model.wheel_rail.contact_parameters import ContactParameters
from ttb_sim.model.wheel_rail.contact_table import contact_geometry_table, ContactGeometryTable
from ttb_sim.sim.coupling.base import FreeDofState, VehicleOutputs
from ttb_sim.sim.coupling.train_track.contact_step import (COMPONENTS, ContactKernels, ContactStep,
                                                           Predictor, RailUnderWheels, Solution)
from ttb_sim.sim.coupling.train_track.equilibrium import static_equilibrium
from ttb_sim.sim.coupling.train_track.rail_compliance import (INFLUENCE_HOPS, rail_section_columns,
                                                              RailCompliance)
from ttb_sim.sim.integrators.protocol import Integrator


class TrainTrackCoupling(FreeDofState):
    """
    State and coupled step of multibody cars running on the slab track.

    Parameters
    ----------
    car : CarParameters
        The car record (every car of the train alike).
    contact : ContactParameters
        Wheel-rail contact settings.
    n_cars, car_length
        Cars in the train and their length over couplers (m).
    structure : Structure
        The assembled track and bridge (with ``structure.track``).
    integrator : Integrator
        The track-bridge integrator (its dt is the step).
    irregularity : TrackIrregularity or None
        The track's irregularity (None = smooth).

    """

    n_axles = 4

    def __init__(self, car: CarParameters, contact: ContactParameters, n_cars: int,
                 car_length: float, structure: Structure, integrator: Integrator,
                 irregularity: TrackIrregularity | None) -> None:
        self.contact = contact
        self.structure = structure
        self.nm = integrator
        self.irregularity = irregularity
        self.params = car
        self._set_train(train_matrices(car, n_cars, car_length))
        self._set_contact_constants(car, contact)
        self._set_track(structure)
        self.contact_step = ContactStep(ContactKernels.load(
            irregular=irregularity is not None, single=bool(getattr(integrator, 'lean', False))))
        """The compiled step (:mod:`contact_step`), owner of its work arrays."""
        self.influence_hops = INFLUENCE_HOPS if getattr(integrator, 'lean', False) else None
        """Reach of the local K^-1 columns of the single-solve step; None: two solves."""
        self.compliance = self._rail_compliance(integrator, structure.full_to_free)
        self._set_state(structure.n_free)

    def _set_train(self, tm: TrainMatrices) -> None:
        """Take one car's matrices, its contact rows H and the wheels' positions."""
        n = self.n_cars = tm.n_cars
        self.n_bodies = self.n_cars
        self.mass = tm.mass[:42, :42].toarray()
        self.damping = tm.damping[:42, :42].toarray()
        self.stiffness = tm.stiffness[:42, :42].toarray()
        self.gravity = tm.gravity[:42].copy()
        h = np.zeros((8, COMPONENTS, 42))
        h[:, 0] = tm.hx[:8, :42].toarray()
        h[:, 1] = tm.hy[:8, :42].toarray()
        h[:, 2] = tm.hz[:8, :42].toarray()
        h[:, 3] = tm.hyaw[:8, :42].toarray()
        self.h = h.reshape(8 * COMPONENTS, 42)
        self.contact_x = tm.contact_x.reshape(n, 8)
        self.side = tm.contact_side.reshape(n, 8)
        self.wheelset_y = 6 * np.repeat(np.arange(3, 7), 2) + 1
        """Each wheel's wheelset lateral DOF."""
        self._speed = math.nan

    def _set_contact_constants(self, car: CarParameters, contact: ContactParameters) -> None:
        """Take the contact laws' constants: Hertz, creep, friction, the profile table."""
        self.r0 = car.wheel_radius
        self.g_hertz = float(ct.hertz_constant(car.wheel_radius, contact.tread))
        self.friction = contact.friction
        self.p0 = car.static_wheel_load
        ellipse = ct.hertz_ellipse(self.p0, car.wheel_radius)
        self.creep0 = ct.creep_coefficients(ellipse.a, ellipse.b)
        self.creep0_array = np.array(self.creep0, dtype=float)
        self.table: ContactGeometryTable | None = (
            contact_geometry_table() if contact.geometry == 'profiles' else None)
        self.geometry_columns = self._geometry_columns()
        """The profile table's columns for the compiled step (constant)."""
        self.tol = contact.tolerance
        self.max_iter = contact.max_iterations

    def _set_track(self, structure: Structure) -> None:
        """Take the rails, their sections and DOFs."""
        track = structure.track
        if track is None:
            raise ModelError('multibody cars need the slab track: the structure has none')
        self.rails = track.rails
        self.head_arm = np.array([0.0, 0.0, track.rail_head])
        self.rail_sections = tuple(rail_section_columns(r) for r in self.rails)
        """Each rail's (n_el, 4) EA, GJ, EI_y, EI_z, for the interior flexibility."""
        ftf = structure.full_to_free
        self.rail_dofs = tuple(ftf[r.dofs] for r in self.rails)
        self._no_load = np.zeros(structure.n_full)   # read-only, shared by every frame
        self.static_stiffness = structure.stiffness
        """Stiffness of the solved state, for the static equilibrium."""

    def _set_state(self, n_free: int) -> None:
        """Set the state of track, cars and contact to zero."""
        n = self.n_cars
        self.n_free = n_free
        """Size of the solved track-bridge state (all free DOFs here)."""
        self.u = np.zeros(n_free)
        self.v = np.zeros(n_free)
        self.a = np.zeros(n_free)
        self.q = np.zeros((n, 42))
        self.qv = np.zeros((n, 42))
        self.qa = np.zeros((n, 42))
        self.force = np.zeros((n, 8, COMPONENTS))
        self.compression = np.zeros((n, 8))
        self.saturation = np.ones((n, 8))
        self.iterations = 0
        self.rail_y = np.zeros((n, 8))
        """Lateral rail-head motion under each wheel at the end of the last step (m)."""
        self.rail_offset = np.zeros((n, 8, COMPONENTS))
        """The last step's correction of the local rail model under each wheel."""
        self.slope_offset = np.zeros((n, 8, 3))
        """The same of the rail's slope (the single-solve step)."""
        self.interior_deflection = np.zeros((n, 8, 3))
        """Interior deflection of the rail element under each wheel (m)."""
        self.interior_velocity = np.zeros((n, 8, 3))
        """Its velocity by the trapezoidal rule (m/s)."""
        self.solves = 0
        """Track solves of the last step."""
        self._zero = np.zeros(n_free)

    def _rail_compliance(self, integrator: Integrator,
                         full_to_free: np.ndarray) -> RailCompliance:
        """Return the local rail compliance blocks of the solved system."""
        return RailCompliance(integrator, self.rails, full_to_free, self.influence_hops)

    def _geometry_columns(self) -> tuple[np.ndarray, ...]:
        """Return the profile table's columns for the compiled step (empty: the cone)."""
        table = self.table
        if table is None:
            return np.zeros(0), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros(0)
        return tuple(np.ascontiguousarray(c, dtype=float) for c in (
            table.lateral, table.rolling_radius, table.contact_angle, table.rise, table.roll))

    def zero_load(self) -> np.ndarray:
        """Return a zero track load of the solved size (read-only)."""
        return self._zero if self._zero.shape[0] == self.n_free else np.zeros(self.n_free)

    # -- train matrices -----------------------------------------------------------------
    def update_speed(self, speed: float) -> None:
        """Set the train's speed-dependent matrices (gyroscopic damping, A^-1) for ``speed``."""
        if speed == self._speed:
            return
        nm = self.nm
        damping = self.damping + gyroscopic_matrix(self.params, speed)
        self.train_damping = damping
        eff = self.stiffness + nm.a1 * damping + nm.a0 * self.mass
        self.a_inv = np.linalg.inv(eff)
        self.dw = self.h @ self.a_inv @ self.h.T
        self.ey = (self.a_inv @ self.h.T)[self.wheelset_y]
        self._speed = speed

    # -- the step -------------------------------------------------------------------------
    def equilibrium(self, head: float) -> None:
        """Put train and track in static equilibrium under gravity (:mod:`equilibrium`)."""
        static_equilibrium(self, head)

    def step(self, head: float, speed: float) -> None:
        """Advance train, track and bridge together to the head position ``head``."""
        self.contact_step(self, head, speed)

    def check_flange(self, lateral: np.ndarray) -> None:
        """Raise DivergenceError when a wheelset runs beyond the contact-geometry table."""
        if self.table is None:
            return
        limit = float(self.table.lateral[-1])
        beyond = np.abs(lateral) > limit
        if np.any(beyond):
            car, wheel = np.argwhere(beyond)[0]
            shift = lateral[car, wheel] * 1e3
            raise DivergenceError(
                f'wheelset {wheel // 2 + 1} of car {car + 1} shifted {shift:.1f} mm relative '
                f'to the rail, beyond the {limit * 1e3:.0f} mm of the contact-geometry '
                'table: the flange is climbing the rail (derailment). Usually the '
                'car hunts at this speed; check car.yaw_dampers and car.yaw_damping')

    def accept_interior(self, interior: np.ndarray, force: np.ndarray, a1: float) -> None:
        """Take the end-of-step interior deflection under the wheels and its velocity."""
        now = -np.einsum('cwij,cwj->cwi', interior, force[..., :3])
        self.interior_velocity = a1 * (now - self.interior_deflection) - self.interior_velocity
        self.interior_deflection = now

    def accept_compiled(self, pred: Predictor, rail: RailUnderWheels, sol: Solution) -> None:
        """Take the end of the compiled step (:class:`ContactStep`) as the new state."""
        a0, a1 = self.nm.a0, self.nm.a1
        n = self.n_cars
        self.rail_offset = sol.offset
        self.rail_offset[..., :3] += sol.mismatch
        self.slope_offset = sol.slope_offset + sol.slope_mismatch
        q_new = pred.q_star + (sol.g @ self.h) @ self.a_inv.T
        self.qv = a1 * q_new + pred.qh_v
        self.qa = a0 * q_new + pred.qh_a
        self.q = q_new
        self.v, self.a = self.nm.finish(sol.u_new, pred.h_v, pred.h_a)
        self.u = sol.u_new
        self.force = sol.g.reshape(n, 8, COMPONENTS)
        self.accept_interior(rail.interior, self.force, a1)
        self.compression = sol.delta
        self.rail_y = sol.r_exact[..., 1] + self.interior_deflection[..., 1]
        self.saturation = sol.eps
        self.iterations = sol.iterations

    # -- the Coupling protocol ------------------------------------------------------------
    def start(self, head: float) -> None:
        """Start from the static equilibrium of train and track under gravity."""
        self.equilibrium(head)

    def structure_load(self, head: float) -> np.ndarray:
        """Return zero: the wheel loads act through the rails, not on the girder DOFs."""
        return self._no_load

    def monitored(self) -> tuple[np.ndarray, ...]:
        """Return the track-bridge and car displacements."""
        return self.u, self.q

    def vehicle_outputs(self) -> VehicleOutputs:
        """Return car-body accelerations, angular velocities and the wheel-rail forces."""
        n = self.n_cars
        return VehicleOutputs(self.qa[:, 0:3].copy(), self.qv[:, 3:6].copy(),
                              self.force[..., :3].reshape(n, 4, 2, 3).copy())
