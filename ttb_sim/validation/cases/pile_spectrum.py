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
Spectra of V20: the pile acceleration of a run and the coupled bridge's frequency response.

:func:`fourier_spectrum` is the Fourier transform of a whole passage (no window:
the record is a transient that starts at rest and has nearly died out at its
end, so the rectangular window is the transient's own transform), zero-padded
to lines :data:`SPECTRUM_STEP` apart. :func:`pile_response` solves the coupled
linear bridge of ``ttb-sim modes`` (piled piers monolithic, [P] Eq. 11: the
reduced pile-soil coordinates are structure DOFs, with their damping and the
viscous-spring boundary) in the frequency domain. Its dynamic stiffness
Z = K - w^2 M + i w C is complex symmetric, so one solve Z y = c with c the
pile-head functional gives, by reciprocity, the pile's response to a unit force
at every DOF at once: at the pier top (the coupled pier FRF H) and along the
girders (the moving-load route).
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
from typing import Sequence

import numpy as np

from ttb_sim.config import load_scenario
from ttb_sim.fe.complex_solve import factorize_complex
from ttb_sim.model.structure import Structure

log = logging.getLogger(__name__)

SPECTRUM_STEP = 0.025
"""Line spacing (Hz) of the zero-padded spectra and of the frequency response: eight lines
per half-power band of a 2 %-damped mode at 5 Hz (0.2 Hz), six per 1 / T of a 7 s passage."""
GIRDER_STEP = 0.25
"""Spacing (m) of the girder points of the moving-load route (30 per wavelength at 9 Hz,
250 km/h)."""


@dataclass(frozen=True)
class PileResponse:
    """Vertical pile-head acceleration of one pile per unit vertical force, by frequency."""

    frequencies: np.ndarray
    """(n_f,) Hz."""
    pier_top: np.ndarray
    """(n_f,) complex, m/s^2 per N at the pier top (the coupled pier FRF H)."""
    girder: np.ndarray
    """(n_f, n_x) complex, m/s^2 per N on the girder line at :attr:`positions`."""
    positions: np.ndarray
    """(n_x,) girder positions (m) from the start of the first span."""


def coupled_bridge(scenario: str, overrides: Sequence[str] = ()) -> Structure:
    """Assemble a scenario's bridge with its piled piers monolithic, as ``ttb-sim modes``."""
    from ttb_sim.sim import build_structure

    return build_structure(load_scenario(scenario, [*overrides, 'solver.coupling=monolithic',
                                                    'solver.substructure_steps=1']))


def pile_functional(structure: Structure, pile: int) -> np.ndarray:
    """Return c (n_free,) with c . u the vertical head displacement of a pile of pier 1."""
    pier = structure.piled[0]
    if pier.block is None:
        raise ValueError('the pile functional needs a monolithic structure')
    c = np.zeros(structure.n_free)
    c[pier.block] = pier.operator.pile_heads[3 * pile + 2]
    return c


def pile_response(structure: Structure, frequencies: np.ndarray, pile: int) -> PileResponse:
    """
    Solve the coupled bridge at ``frequencies`` for the pile's response to unit forces.

    One factorisation and solve per frequency (not per time step); the girder
    points are read from the solution through the girder's shape functions.
    """
    c = pile_functional(structure, pile)
    pier = structure.piled[0]
    top = structure.pier_top_dofs[structure.pier_supports.index(pier.support), 2]
    girder = structure.girder
    positions = np.arange(0.5 * GIRDER_STEP, girder.length, GIRDER_STEP)
    element, (shape,) = girder.rows(positions, (0,))
    dofs = girder.w_dofs[element]
    f = np.asarray(frequencies, dtype=float)
    at_top = np.zeros(f.size, dtype=complex)
    along = np.zeros((f.size, positions.size), dtype=complex)
    k, m, d = structure.stiffness, structure.mass, structure.damping
    for i, w in enumerate(2.0 * np.pi * f):
        y = np.append(factorize_complex(k - w * w * m + 1j * w * d).solve(c), 0.0)
        at_top[i] = -w * w * y[top]
        along[i] = -w * w * np.sum(shape * y[dofs], axis=1)
    log.info('V20: coupled bridge solved at %d frequencies (%.2f-%.2f Hz)', f.size,
             f.min() if f.size else 0.0, f.max() if f.size else 0.0)
    return PileResponse(f, at_top, along, positions)


def padded_length(size: int, rate: float, step: float = SPECTRUM_STEP) -> int:
    """Return the FFT length of a record of ``size`` samples: lines ``step`` apart, or closer."""
    return max(size, int(round(rate / step)))


def fourier_spectrum(signal: np.ndarray, rate: float, step: float = SPECTRUM_STEP
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Return (f Hz, X(f) = int x exp(-i 2 pi f t) dt) of a record, zero-padded to ``step``."""
    x = np.asarray(signal, dtype=float)
    n = padded_length(x.size, rate, step)
    return np.fft.rfftfreq(n, 1.0 / rate), np.fft.rfft(x, n) / rate


def window_lines(f: np.ndarray, window: tuple[float, float]) -> np.ndarray:
    """Return the indices of the lines strictly inside ``window`` (Hz)."""
    return np.flatnonzero((f > window[0]) & (f < window[1]))


def spectrum_energy(spectrum: np.ndarray, df: float) -> float:
    """Return 2 sum |X|^2 df: the energy int x^2 dt of the lines given (one-sided, Parseval)."""
    return float(2.0 * np.sum(np.abs(spectrum) ** 2) * df)


def moving_load_spectrum(response: PileResponse, speed: float, loads: np.ndarray,
                         head_start: float, offsets: np.ndarray) -> np.ndarray:
    """
    Return the pile acceleration spectrum of constant axle loads crossing the girders.

    A(f) = sum_k P_k (1 / V) int G(x, f) exp(-i 2 pi f (x - x_k0) / V) dx, the
    load k at x_k0 + V t and G the girder row of ``response``; the integral is
    the midpoint sum over the girder points.
    """
    w = 2.0 * np.pi * response.frequencies
    phase = np.exp(-1j * np.outer(w, response.positions) / speed)
    line = np.sum(response.girder * phase, axis=1) * GIRDER_STEP / speed
    starts = head_start - np.asarray(offsets, dtype=float)
    train = np.exp(1j * np.outer(w, starts) / speed) @ np.asarray(loads, dtype=float)
    return np.asarray(line * train, dtype=complex)
