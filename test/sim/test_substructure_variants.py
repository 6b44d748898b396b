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
``solver.variant`` in a pile-soil substructure run: the reference against the default.

The fully implicit reference against the mixed scheme of the other variants, and the
reference refused for a mesh too large for it.

On the coarse single pile (h = 0.8 m, 12 x 12 m block, 6 120 DOFs) each run takes a second.

Why the harmonic tolerance is what it is. Both schemes are Newmark's average acceleration at
the same step; they differ only in the soil and boundary, which the mixed scheme integrates
explicitly from the predictor (u~ = u_n + dt v_n + dt^2/4 a_n, v~ = v_n + dt/2 a_n). Against
the implicit update that leaves out dt^2/4 K a_{n+1} of the soil's elastic force and
dt/2 C a_{n+1} of its damping force. Relative to the inertia force at the response's circular
frequency omega (K ~ omega^2 M, C = 2 zeta omega M) these are (omega dt)^2 / 4 and
zeta omega dt: the damping term makes the difference first order in dt (the explicit
predictor-corrector is second order only without damping). At the
4 Hz load, dt = 5 ms and zeta = 5 % (the Rayleigh anchors; between 1 and 20 Hz the ratio is
lower) the estimate is 0.05 * 0.126 + 0.126^2 / 4 = 1.0 %, the bound on the RMS difference
of the pile head. That it is a time-discretisation difference and nothing else (the two
schemes step the same model) is checked by halving the step: the difference must fall at
least as first order does (ratio <= 0.6; 0.5 for first order, 0.25 for second).
"""

import math

import numpy as np
import pytest
from ttb_sim.cli import main
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.sim.substructure.standalone import reference_refusal, SubstructureRun

COARSE = ['soil.block.lx=12', 'soil.block.ly=12', 'soil.mesh.h=0.8', 'soil.mesh.growth=1.5',
          'soil.mesh.h_max=2.5', 'piles.side=0.8', 'piles.length=6',
          'output.soil_points=[[2.0, 0.0, 0.0]]']
HARMONIC = ['load.type=harmonic', 'load.frequency=4', 'output.rate_hz=200',
            'solver.duration=0.5']


def _run(variant: str, *sets: str) -> SubstructureRun:
    return SubstructureRun(load_scenario('single_pile',
                                         [*COARSE, *sets, f'solver.variant={variant}']))


def _heads(variant: str, *sets: str) -> tuple[SubstructureRun, np.ndarray]:
    run = _run(variant, *sets)
    return run, np.array([f.pile_displacement[0, 2] for f in run.frames()])


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x**2)))


def test_reference_is_implicit_and_the_default_mixed_with_its_factorisation() -> None:
    ref = _run('reference', *HARMONIC)
    fast = _run('superlu_sym', *HARMONIC)
    assert ref.scheme == 'implicit' and fast.scheme == 'mixed'
    assert fast.factorization == 'superlu_sym'
    assert ref.dt == fast.dt == pytest.approx(5e-3, rel=1e-12)  # the same steps
    assert ref.describe()['variant'] == 'reference'
    assert ref.integrator is not None and fast.integrator is not None
    assert len(ref.integrator.implicit) == ref.n_free > len(fast.integrator.implicit) > 0


def test_harmonic_reference_and_default_agree_to_the_time_discretisation_difference() -> None:
    """RMS difference within zeta omega dt + (omega dt)^2 / 4, falling as dt is halved."""
    differences = []
    for dt in (5e-3, 2.5e-3):
        ref_run, ref = _heads('reference', *HARMONIC, f'solver.dt={dt}')
        fast_run, fast = _heads('qdldl', *HARMONIC, f'solver.dt={dt}')
        assert ref_run.dt == fast_run.dt == pytest.approx(dt, rel=1e-12)
        assert len(ref) == len(fast) == 101 and np.abs(ref).max() > 0
        differences.append(_rms(fast - ref) / _rms(ref))
    omega_dt = 2 * math.pi * 4.0 * 5e-3
    zeta = max(layer.damping_ratio for layer in load_scenario('single_pile').soil.layers)
    assert 0 < differences[0] <= zeta * omega_dt + omega_dt**2 / 4
    assert differences[1] <= 0.6 * differences[0]


@pytest.mark.parametrize('amplitude', [1e3, 3e5])
def test_static_direct_reference_and_preconditioned_default_agree(amplitude: float) -> None:
    """
    Both solve the same equations to a relative residual of 1e-6 (Newton; CG to 1e-10 inside).

    At 1 kN the interface stays elastic; 300 kN drives it into slip, where the increments
    and the committed slip must match too. The head displacement, the load's work conjugate,
    then agrees to the residual tolerance: 1e-6 relative.
    """
    _, ref = _heads('reference', f'load.amplitude={amplitude}')
    _, fast = _heads('qdldl', f'load.amplitude={amplitude}')
    assert len(ref) == len(fast) == 1 and ref[0] > 0
    assert fast[0] == pytest.approx(ref[0], rel=1e-6)


def test_reference_on_pile_harmonic_is_refused_before_the_build() -> None:
    scenario = load_scenario('pile_harmonic', ['solver.variant=reference'])
    message = reference_refusal(scenario)
    assert message is not None
    assert message.startswith("solver.variant = 'reference': ") and "'qdldl'" in message
    assert 'soil.mesh.h' in message and 'GiB' in message
    with pytest.raises(ScenarioError, match='fully implicit'):
        SubstructureRun(scenario)
    assert reference_refusal(load_scenario('pile_harmonic')) is None  # the default runs
    assert reference_refusal(load_scenario('single_pile', ['solver.variant=reference'])) is None


def test_run_refuses_the_reference_on_pile_harmonic_with_exit_2(tmp_path, capsys) -> None:
    out = tmp_path / 'bag'
    assert main(['run', 'pile_harmonic', '--out', str(out),
                 '--set', 'solver.variant=reference']) == 2
    err = capsys.readouterr().err
    assert err.startswith("ttb-sim: error: solver.variant = 'reference'") and err.count('\n') == 1
    assert not out.exists()
