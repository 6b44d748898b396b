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
A bag of ours with known signals: real topic table and recorder, frames built from sines.

Every topic family analysis reads is present (car body, wheel-rail forces,
mid-spans, bearings, observers at one station, piles, soil points), with
amplitudes and frequencies chosen so that the metrics have closed forms, and
a ``summary.json`` with the scenario echo the analysis needs.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ttb_sim.io.bag import BagRecorder
from ttb_sim.io.topics import topic_table
from ttb_sim.sim import Frame, Layout

RATE = 500.0
SAMPLES = 1000          # 2 s: 0.5 Hz bins, every tone a whole number of periods
SPEED = 300 / 3.6
CAR_Z = (0.5, 2.0)      # car-body vertical amplitude (m/s^2), frequency (Hz)
CAR_Y = (0.2, 1.0)
WHEEL = (70e3, 5e3, 10.0, 8e3)  # static load, amplitude, frequency, lateral force (N)
MID = (1e-3, 4.0)       # mid-span displacement amplitude (m), frequency
PILE_A = (0.3, 20.0)
PILE_ROT = (0.01, 1.0)  # rotation amplitude (rad), frequency
PILE_Z = (-2e-3, -1e-3)  # constant pile-head settlements of piers 1 and 2 (m)
SOIL = (0.01, 6.5)
STATION = 16.0
OBS = {'rail': (2e-4, 0.0), 'slab': (1e-4, 0.4), 'base': (6e-5, 0.6), 'girder': (5e-5, 0.8)}
OBS_F = 5.0
TRACK = {'model': 'slab', 'fastener_vertical_stiffness': 5e7, 'fastener_vertical_damping': 3.6e4,
         'fastener_spacing': 0.63, 'layer_stiffness': 1.5e9, 'layer_damping': 8.3e4,
         'fasteners_per_slab': 9, 'slab_gap': 0.07}
LAYOUT = Layout(n_spans=2, n_supports=3, n_bodies=1, n_axles=4,
                observers=tuple(f'{k}_1' for k in OBS), piles=((1, 3), (2, 3)), soil_points=7)


def sine(amplitude: float, frequency: float, t: np.ndarray | float,
         phase: float = 0.0) -> np.ndarray:
    return amplitude * np.sin(2 * math.pi * frequency * np.asarray(t) + phase)


def frame(k: int, scale: float = 1.0) -> Frame:
    t = k / RATE
    body = np.array([[0.0, sine(*CAR_Y, t) * scale, sine(*CAR_Z, t) * scale]])
    static, amp, f, lateral = WHEEL
    wheel = np.zeros((1, 4, 2, 3))
    wheel[..., 2] = static
    wheel[0, :, 0, 2] += sine(amp, f, t)
    wheel[0, :, 1, 2] -= sine(amp, f, t)
    wheel[0, :, :, 1] = lateral
    mid = np.zeros((2, 3))
    mid[:, 2] = sine(*MID, t)
    obs = np.zeros((4, 3))
    for i, (a, phase) in enumerate(OBS.values()):
        obs[i, 2] = sine(a, OBS_F, t, -phase)
    n_piles = 6
    pile_u = np.zeros((n_piles, 3))
    pile_u[:3, 2], pile_u[3:, 2] = PILE_Z
    pile_a = np.zeros((n_piles, 3))
    pile_a[:, 2] = sine(*PILE_A, t)
    rot = np.zeros((n_piles, 3))
    rot[:, 0] = PILE_ROT[0] * 2 * math.pi * PILE_ROT[1] * math.cos(2 * math.pi * PILE_ROT[1] * t)
    soil = np.zeros((7, 12))      # a line of five points at y = 3 m, then two VAL points
    soil[:, 0] = [0.0, 1.0, 2.0, 3.0, 4.0, 1.0, 3.0]
    soil[:, 1] = [3.0, 3.0, 3.0, 3.0, 3.0, 5.0, 5.0]
    soil[:, 8] = sine(*SOIL, t) * np.array([1.0, 2.0, 3.0, 4.0, 5.0, 1.0, 5.0])
    return Frame(step=k, time=t, head_position=SPEED * t, speed=SPEED, midspan=mid,
                 bearings=np.zeros((3, 2, 3)), body_acceleration=body,
                 body_angular_velocity=np.zeros((1, 3)), wheel_rail=wheel, observers=obs,
                 pile_displacement=pile_u, pile_acceleration=pile_a, pile_rotation_rate=rot,
                 soil_points=soil)


def write_bag(path: Path, storage: str = 'mcap', scale: float = 1.0,
              summary: bool = True, layout: Layout = LAYOUT,
              namespace: str = '/ttb_sim') -> Path:
    """Write the synthetic bag (and its summary.json) at ``path``; return it."""
    with BagRecorder(path, topic_table(layout), storage, namespace=namespace) as bag:
        for k in range(SAMPLES):
            bag.write(frame(k, scale))
    if summary:
        scenario = {
            'name': 'synthetic', 'train': {'vehicle': 'car', 'speed_kmh': 300.0,
                                           'car_length': 25.0, 'axle_offsets': []},
            'car': {'bogie_semi_spacing': 7.85, 'wheelbase_semi': 1.25},
            'bridge': {'span_length': 32.0}, 'track': TRACK,
            'irregularity': {'spectrum': 'paper'},
            'output': {'observers': [f'{k}_1={"rail_left" if k == "rail" else k}@{STATION}'
                                     for k in OBS]}}
        (path / 'summary.json').write_text(json.dumps({'status': 'ok', 'scenario': scenario}))
    return path


def interface_power() -> dict[str, float]:
    """Closed-form mean power per metre at the station (complex amplitudes, Eq. 18)."""
    w = 2 * math.pi * OBS_F
    u = {k: a * np.exp(-1j * (phase + math.pi / 2)) for k, (a, phase) in OBS.items()}
    v = {k: 1j * w * x for k, x in u.items()}
    kf = 2 * (TRACK['fastener_vertical_stiffness'] + 1j * w * TRACK['fastener_vertical_damping']) \
        / TRACK['fastener_spacing']
    kl = TRACK['layer_stiffness'] + 1j * w * TRACK['layer_damping']
    f_fast = kf * (u['rail'] - u['slab'])
    f_ca = kl * (u['slab'] - u['base'])
    f_bg = kl * (u['base'] - u['girder'])
    return {'rail': 0.5 * (f_fast * np.conj(v['rail'])).real,
            'slab': 0.5 * (f_fast * np.conj(v['slab'])).real,
            'base': 0.5 * (f_ca * np.conj(v['base'])).real,
            'girder': 0.5 * (f_bg * np.conj(v['girder'])).real}
