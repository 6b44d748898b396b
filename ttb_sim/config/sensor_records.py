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
The ``sensors`` list of a scenario: virtual sensors, each a record declared once.

A sensor is a name (its topic ``~/sensors/<name>``), a type, a location in the
model's own terms (``at``, see :data:`LOCATION_FORMS`), the axes it measures and
its acquisition chain: sampling rate with an anti-alias filter, noise, bias and
its random walk, quantisation, full scale, dropouts and a clock offset, with a
seed of its own. :mod:`ttb_sim.sensors.acquisition` turns the model's truth into
what the sensor records; :mod:`ttb_sim.sensors.locations` finds the truth.
"""

from __future__ import annotations

from dataclasses import dataclass
import re
import zlib

from ttb_sim.declarations import check_declared, param
from ttb_sim.errors import ModelError

__all__ = ['decimation_factor', 'DEFAULT_AXES', 'LOCATION_FORMS', 'SENSOR_TYPES',
           'SensorConfig', 'SensorError', 'UNITS']

SENSOR_TYPES = ('accelerometer', 'displacement', 'inclinometer', 'geophone', 'strain',
                'wheel_force')
"""What a sensor measures: acceleration, displacement (or the change of a distance, with
``relative_to``), rotation, velocity, fibre strain, the force of the rail on a wheel."""

UNITS = {'accelerometer': 'm/s^2', 'displacement': 'm', 'inclinometer': 'rad',
         'geophone': 'm/s', 'strain': '-', 'wheel_force': 'N'}
"""The unit of each type's values, and so of its noise parameters."""

DEFAULT_AXES = {'accelerometer': 'z', 'displacement': 'z', 'inclinometer': 'y',
                'geophone': 'z', 'strain': 'x', 'wheel_force': 'xyz'}
"""The axes a type measures when ``axes`` is not given (track axes; inclinometer: rotation
about the axis; strain: the one fibre strain, along x)."""

LOCATION_FORMS = {
    'line': re.compile(r'^(girder|rail_left|rail_right|slab|base)@(.+)$'),
    'span': re.compile(r'^span(\d+)/x=(.+)$'),
    'car': re.compile(r'^car(\d+)$'),
    'wheel': re.compile(r'^car(\d+)/axle(\d+)/(left|right)$'),
    'pile': re.compile(r'^pier(\d+)/pile(\d+)(?:/depth=(.+))?$'),
    'pier_top': re.compile(r'^pier(\d+)/top$'),
    'ground': re.compile(r'^ground/pier(\d+)/([A-Za-z0-9_]+)$'),
}
"""The forms of ``at``: a point of girder NN at x m from its left support (``span07/x=16.0``),
a point of a beam line at track position x (``girder@208.0``,
``rail_left@x``, ``slab@x``, ``base@x``), a car body (``car03``), a wheel
(``car03/axle2/left``), a pile head (``pier07/pile05``; a strain gauge also D m below it,
``pier07/pile05/depth=3.0``), a pier top (``pier07/top``) and
a ground point of a piled pier by its name in ``summary.json`` (``ground/pier07/line_01``)."""

_TYPE_TEXT = ('What it measures: accelerometer (m/s^2), displacement (m; with relative_to the '
              'change of the distance between two points: a bearing LVDT), inclinometer '
              '(rad), geophone (velocity, m/s), strain (girder or rail fibre strain; or a '
              "pile's axial strain, tension positive) or "
              'wheel_force (an instrumented wheelset, N).')
RATE_TOLERANCE = 1e-9
"""Relative tolerance of frame rate / sensor rate being an integer."""

_NAME = re.compile(r'^[A-Za-z][A-Za-z0-9_]*$')
_AXES = re.compile(r'^(?!.*(.).*\1)[xyz]{1,3}$')


class SensorError(ModelError):
    """A sensor of the ``sensors`` list is described by invalid values."""


@dataclass(frozen=True)
class SensorConfig:
    """One virtual sensor (an entry of ``sensors``)."""

    name: str = param('sensor', '-', 'Name of the sensor: letters, digits and _, starting with '
                      'a letter; published on ~/sensors/<name>.')
    type: str = param('accelerometer', '-', _TYPE_TEXT,  # noqa: A003 - the key is type
                      choices=SENSOR_TYPES)
    at: str = param('', '-', "Where: 'girder@x' (also rail_left, rail_right, slab, base; x "
                    "along the track, m), 'carNN' (car body), 'carNN/axleK/left|right' "
                    "(wheel), 'pierNN/pileMM' (pile head), 'pierNN/pileMM/depth=D' (strain: "
                    "the pile's axial strain D m below its head, tension positive; "
                    "without depth at the head), 'pierNN/top' (pier top: displacement, "
                    "accelerometer) or 'ground/pierNN/<point>' (a ground point by its "
                    'summary.json name).')
    relative_to: str = param('', '-', "displacement: a second point in the forms of 'at'; "
                             'the sensor reads at minus relative_to.')
    axes: tuple[str, ...] = param((), '-', 'Axes measured, a list of x, y, z in track axes '
                                  '(x along the track, y left, z up), e.g. [z] or [x, z]; '
                                  "[] = the type's default (z; inclinometer y, the rotation of "
                                  'bending; strain x; wheel_force x, y, z).')
    fibre: tuple[float, ...] = param((0.0, 0.0), 'm', 'strain: the fibre [y, z] from the beam '
                                     'axis (z < 0 below it: a gauge on the soffit).',
                                     low=-100.0, high=100.0)
    rate_hz: float = param(100.0, 'Hz', 'Sampling rate. The frame rate (output.rate_hz) must '
                           'be an integer multiple of it, at least 2, so that the anti-alias '
                           'filter has a band to work in.', low=0.0, high=1e6,
                           low_inclusive=False)
    passband: float = param(0.8, '-', 'Anti-alias filter: edge of its flat band as a fraction '
                            'of the Nyquist frequency (rate_hz / 2), where its stop band '
                            'begins.', low=0.05, high=0.95)
    stopband_attenuation: float = param(80.0, 'dB', 'Anti-alias filter: attenuation at and '
                                        'above the Nyquist frequency.', low=20.0, high=160.0)
    noise_density: float = param(0.0, 'unit/sqrt(Hz)', 'White noise density (one-sided), in '
                                 "the type's unit; e.g. 2.2e-4 m/s^2/sqrt(Hz) for a MEMS "
                                 'accelerometer of 22.5 micro-g/sqrt(Hz).', low=0.0, high=1e9)
    bias: float = param(0.0, 'unit', 'Constant bias added to every axis.', low=-1e9, high=1e9)
    bias_walk: float = param(0.0, 'unit/sqrt(s)', 'Bias random walk: the bias drifts by this '
                             'times sqrt(t) (one standard deviation).', low=0.0, high=1e9)
    resolution: float = param(0.0, 'unit', 'Quantisation step (one least significant bit); '
                              '0 = none.', low=0.0, high=1e9)
    full_scale: float = param(0.0, 'unit', 'Values beyond +-full_scale are clipped to it; '
                              '0 = no clipping.', low=0.0, high=1e12)
    dropout_probability: float = param(0.0, '-', 'Long-run fraction of samples lost in '
                                       'dropouts (no message is published for them).',
                                       low=0.0, high=0.99)
    dropout_mean_length: float = param(0.1, 's', 'Mean length of one dropout.', low=0.0,
                                       high=1e4, low_inclusive=False)
    clock_offset: float = param(0.0, 's', "Offset of the sensor's clock: its stamps are the "
                                'true sample times plus this (samples stamped before 0 are '
                                'not published).', low=-10.0, high=10.0)
    clock_drift: float = param(0.0, 'ppm', "Rate error of the sensor's clock: its stamps are "
                               'the true sample times times (1 + clock_drift * 1e-6), plus '
                               'clock_offset (a crystal: 1-50 ppm).', low=-1e4, high=1e4)
    seed: int = param(-1, '-', "Seed of the sensor's noise and dropouts, independent of "
                      'irregularity.seed; -1 = derived from the name.', low=-1, high=2**63 - 1)

    def __post_init__(self) -> None:
        """Check every field against its declaration, then the forms of name, at and axes."""
        check_declared(self, 'sensors.', SensorError)
        if not _NAME.match(self.name):
            raise SensorError(f'name = {self.name!r}: letters, digits and _, starting with a '
                              'letter')
        if not self.at:
            raise SensorError(f'{self.name}: at is empty; allowed forms: girder@x, carNN, '
                              'carNN/axleK/left|right, pierNN/pileMM, pierNN/top, '
                              'ground/pierNN/<point>')
        joined = ''.join(self.axes)
        if joined and not _AXES.match(joined):
            raise SensorError(f'{self.name}: axes = {list(self.axes)!r}; allowed: one to three of '
                              'x, y, z, each once')
        if self.type == 'strain' and joined not in ('', 'x'):
            raise SensorError(f'{self.name}: axes = {list(self.axes)!r}; a strain gauge '
                              'measures the fibre strain along the beam (or the axial strain '
                              'of a pile) only (axes [x] or [])')
        if len(self.fibre) != 2:
            raise SensorError(f'{self.name}: fibre = {list(self.fibre)!r}; expected [y, z] (m)')
        if self.relative_to and self.type != 'displacement':
            raise SensorError(f'{self.name}: relative_to is for type displacement only, not '
                              f'{self.type!r}')

    @property
    def measured_axes(self) -> str:
        """Return the axes measured (``axes`` or the type's default)."""
        return ''.join(self.axes) or DEFAULT_AXES[self.type]

    @property
    def unit(self) -> str:
        """Return the unit of the values (and of the noise parameters)."""
        return UNITS[self.type]

    @property
    def rng_seed(self) -> int:
        """Return the seed of the noise: ``seed``, or the CRC-32 of the name when it is -1."""
        return self.seed if self.seed >= 0 else zlib.crc32(self.name.encode('utf-8'))


def decimation_factor(frame_rate: float, config: SensorConfig) -> int:
    """
    Return q = frame rate / sensor rate, an integer of at least 2.

    Raises
    ------
    SensorError
        Naming ``rate_hz`` and the frame rate when q is not an integer >= 2.

    """
    ratio = frame_rate / config.rate_hz
    q = round(ratio)
    if q < 2 or abs(ratio - q) > RATE_TOLERANCE * ratio:
        allowed = ', '.join(f'{frame_rate / k:g}' for k in range(2, 6))
        raise SensorError(f'{config.name}: rate_hz = {config.rate_hz:g} does not divide the '
                          f'frame rate {frame_rate:g} Hz (output.rate_hz) by an integer of at '
                          f'least 2; allowed e.g. {allowed} Hz, or raise output.rate_hz')
    return q
