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
Metrics of bags, shared by ``ttb-sim analyze`` (one bag), ``compare`` (several) and ``sweep``.

:func:`bag_metrics` computes the numbers of one :class:`~ttb_sim.io.streams.Streams`
(written to ``metrics.json``); the stream pickers beside it (excitation marks, the
observer stations and their power flow, the power into the piers) are shared with
:mod:`ttb_sim.report.figures` (those of the ground points are in
:mod:`ttb_sim.report.soil`); :func:`flatten` and :func:`differences` give the table of
``compare``.  The physics lives in
:mod:`ttb_sim.analysis`; this module only picks the streams and lays them out.
"""

from __future__ import annotations

import logging
import re
from typing import Any, Sequence

import numpy as np

from ttb_sim.analysis.excitation import Excitation, excitation_frequencies
from ttb_sim.analysis.levels import band_rms
from ttb_sim.analysis.power_flow import power_flow_spectrum, velocity_from_displacement
from ttb_sim.analysis.psd import (level_change_frequency, peak_frequency,
                                  resolving_segment_seconds, welch_psd)
from ttb_sim.analysis.ride import CAR_BODY_LIMITS, sperling_grade, sperling_index
from ttb_sim.analysis.safety import (deck_acceleration, derailment_coefficient,
                                     lateral_force_limit, LIMITS, wheel_load_reduction)
from ttb_sim.analysis.weighting import weighted_rms
from ttb_sim.io.streams import Series, Streams
from ttb_sim.report.soil import soil_metrics

log = logging.getLogger(__name__)

CAR_BODY_LOWEST_HZ = 0.84
"""Lowest frequency of interest of car bodies: the vertical bounce mode of [P] Table 1 cars."""
SPERLING_LIMIT = 2.5
"""Sperling index below which a passenger car rates 'excellent'."""
_OBSERVER = re.compile(r'^\s*([^=\s]+)\s*=\s*(\w+)\s*@\s*([-+0-9.eE]+)\s*$')
_LAYERS = ('rail', 'slab', 'base', 'girder')
_VEHICLES = {'sprung_mass': 'quarter cars', 'moving_force': 'moving forces'}
"""The vehicle models without lateral dynamics, as the reason of an index they lack names them."""


# -- excitation marks ---------------------------------------------------------------------

def marks_of(s: Streams) -> list[Excitation]:
    """Return the excitation frequencies of a bag (train speed, scenario echo, harmonic load)."""
    load = s.section('load')
    if load.get('type') == 'harmonic' and load.get('frequency'):
        return [Excitation('harmonic load', float(load['frequency']), float(load['frequency']))]
    if not s.speed:
        return []
    car, train = s.section('car'), s.section('train')
    track, bridge = s.section('track'), s.section('bridge')
    spectrum = str(s.section('irregularity').get('spectrum', 'paper'))
    slab = track.get('model') == 'slab'
    slab_length = None
    if slab and track.get('fasteners_per_slab'):
        slab_length = track['fasteners_per_slab'] * track['fastener_spacing'] + \
            track.get('slab_gap', 0.0)
    return excitation_frequencies(
        s.speed, boundary_wavelength=1.0 if spectrum in ('paper', 'chinese_sato') else None,
        bogie_semi_spacing=car.get('bogie_semi_spacing'), wheelbase_semi=car.get('wheelbase_semi'),
        car_length=train.get('car_length') if train.get('vehicle') == 'car' or
        not train.get('axle_offsets') else None,
        span_length=bridge.get('span_length'), slab_length=slab_length,
        fastener_spacing=track.get('fastener_spacing') if slab else None)


# -- metrics -----------------------------------------------------------------------------

def _index(value: float, limit: float, unit: str, where: str) -> dict[str, Any]:
    within = bool(value <= limit)
    return {'value': float(value), 'limit': float(limit), 'unit': unit, 'where': where,
            'within_limit': within, 'status': 'within' if within else 'exceeded'}


def _not_available(limit: float, unit: str, reason: str) -> dict[str, Any]:
    """Return an index the bag's model cannot produce: no value, no verdict, the reason."""
    return {'value': None, 'limit': float(limit), 'unit': unit, 'where': '',
            'within_limit': None, 'status': 'n/a', 'reason': reason}


def unavailable_indices(s: Streams) -> dict[str, str]:
    """
    Return the wheel-rail indices the bag's vehicle model cannot produce, with the reason.

    Quarter cars and moving forces (``train.vehicle`` in the scenario echo) have
    no lateral dynamics, so no derailment coefficient or lateral wheelset force,
    and no roll, so no left-right wheel-load reduction (GB 5599 form); only the
    42-DOF car has both.  Without the echo the bag itself decides: no lateral
    force anywhere, or left and right wheel loads equal throughout.
    """
    vehicle = s.section('train').get('vehicle')
    if vehicle == 'car':
        return {}
    if vehicle is not None:
        model = f'{_VEHICLES.get(str(vehicle), "the vehicle model")} (train.vehicle = {vehicle})'
        lateral: str | None = f'{model} have no lateral dynamics'
        roll: str | None = f'{model} have no roll: left and right wheel loads are equal'
    else:
        pairs = [(v, s.wheel_rail[(car, axle, 'right')]) for (car, axle, side), v
                 in s.wheel_rail.items()
                 if side == 'left' and (car, axle, 'right') in s.wheel_rail]
        lateral = None if any(np.any(v.values[:, 1]) for v in s.wheel_rail.values()) else \
            'the bag has no lateral wheel-rail force'
        roll = 'left and right wheel loads are equal in the bag' if pairs and all(
            np.array_equal(a.values[:, 2], b.values[:, 2]) for a, b in pairs) else None
    out = {}
    if lateral is not None:
        out['derailment_coefficient'] = out['lateral_wheelset_force'] = lateral
    if roll is not None:
        out['wheel_load_reduction'] = roll
    return out


def _psd(series: Series, column: int, lowest_hz: float) -> tuple[np.ndarray, np.ndarray]:
    x = series.values[:, column]
    seconds = resolving_segment_seconds(lowest_hz, series.t.size / series.rate)
    return welch_psd(x, series.rate, segment_seconds=min(seconds, x.size / series.rate))


def _body_peak(series: Series) -> float | None:
    """Return the car-body vertical PSD peak in 0.3-3 Hz (None: record too short, or no peak)."""
    if series.t.size / series.rate < 4.0 or not np.any(series.values[:, 2]):
        return None   # bins coarser than 0.25 Hz cannot place the 0.84 Hz mode
    f, p = _psd(series, 2, CAR_BODY_LOWEST_HZ)
    band = np.flatnonzero((f >= 0.3) & (f <= 3.0))
    if band.size < 3:
        return None
    i = band[np.argmax(p[band])]
    if i in (band[0], band[-1]):
        return None   # the maximum is on an edge: no peak inside the band
    return peak_frequency(f, p, (0.3, 3.0))


def bag_metrics(s: Streams) -> dict[str, Any]:
    """Return the metrics of one bag (JSON-ready): peaks, spectra features, ride and safety."""
    out: dict[str, Any] = {
        'bag': str(s.path), 'label': s.label,
        'scenario': s.scenario.get('name') if s.scenario else None,
        'speed_kmh': None if s.speed is None else round(s.speed * 3.6, 6),
        'duration_s': s.duration, 'sample_rate_hz': s.rate,
        'excitation_hz': {m.label: [m.low, m.high] for m in marks_of(s)},
    }
    indices: dict[str, Any] = {}
    if s.car_body:
        cars: dict[str, Any] = {}
        for car, series in s.car_body.items():
            a, fs = series.values, series.rate
            entry: dict[str, Any] = {'vertical_peak_m_s2': float(np.max(np.abs(a[:, 2]))),
                                     'lateral_peak_m_s2': float(np.max(np.abs(a[:, 1]))),
                                     'sperling_vertical': sperling_index(a[:, 2], fs),
                                     'sperling_lateral': sperling_index(a[:, 1], fs, 'lateral'),
                                     'wk_weighted_rms_m_s2': weighted_rms(a[:, 2], fs, 'Wk'),
                                     'wd_weighted_rms_m_s2': weighted_rms(a[:, 1], fs, 'Wd')}
            entry['vertical_psd_peak_hz'] = _body_peak(series)
            entry['sperling_vertical_grade'] = sperling_grade(entry['sperling_vertical'])
            cars[f'car{car:02d}'] = entry
        out['car_body'] = cars
        worst = max(cars, key=lambda c: cars[c]['sperling_vertical'])
        indices['sperling_vertical'] = _index(cars[worst]['sperling_vertical'], SPERLING_LIMIT,
                                              '-', worst)
        worst_l = max(cars, key=lambda c: cars[c]['sperling_lateral'])
        if cars[worst_l]['sperling_lateral'] > 0:
            indices['sperling_lateral'] = _index(cars[worst_l]['sperling_lateral'],
                                                 SPERLING_LIMIT, '-', worst_l)
        for direction, key in (('vertical', 'vertical_peak_m_s2'),
                               ('lateral', 'lateral_peak_m_s2')):
            worst = max(cars, key=lambda c: cars[c][key])
            if cars[worst][key] > 0:
                indices[f'car_body_{direction}_acceleration'] = _index(
                    cars[worst][key], CAR_BODY_LIMITS[direction], 'm/s^2', worst)
    if s.wheel_rail:
        out['wheel_rail'], wheel_indices = _wheel_rail_metrics(s)
        indices.update(wheel_indices)
    if s.midspan:
        girders = {}
        for span, series in s.midspan.items():
            acc = deck_acceleration(series.values[:, 2], series.rate)
            girders[f'span{span:02d}'] = {
                'displacement_min_m': float(series.values[:, 2].min()),
                'displacement_max_m': float(series.values[:, 2].max()),
                'deck_acceleration_peak_m_s2': float(np.max(np.abs(acc)))}
        out['girder'] = girders
        worst = max(girders, key=lambda g: girders[g]['deck_acceleration_peak_m_s2'])
        indices['deck_acceleration'] = _index(
            girders[worst]['deck_acceleration_peak_m_s2'],
            LIMITS['deck_acceleration_ballastless'], 'm/s^2', worst)
    if s.bearing:
        out['bearings'] = {f'pier{p:02d}_{side}': {'vertical_max_N': float(v.values[:, 2].max()),
                                                   'vertical_min_N': float(v.values[:, 2].min())}
                           for (p, side), v in s.bearing.items()}
    if s.pile_acceleration or s.pile_displacement:
        out['piles'] = _pile_metrics(s)
    if s.soil is not None:
        out['soil'] = soil_metrics(s)
    flows = power_flows(s)
    if flows:
        out['power_flow_mean_W_per_m'] = {
            station: {layer: float(np.sum(p)) for layer, (_, p) in layers.items()}
            for station, layers in flows.items()}
    into_piers = pier_power_flows(s)
    if into_piers:
        out['power_into_piers'] = {f'pier{p:02d}': _pier_power_metrics(f, pw)
                                   for p, (f, pw) in into_piers.items()}
    out['indices'] = indices
    return out


def _wheel_rail_metrics(s: Streams) -> tuple[dict[str, Any], dict[str, Any]]:
    qp_max, qp_where = 0.0, ''
    gb_max, dyn_max, red_where = 0.0, 0.0, ''
    h_max, h_where, axle_loads = 0.0, '', []
    fz_max = max(float(v.values[:, 2].max()) for v in s.wheel_rail.values())
    fz_min = min(float(v.values[:, 2].min()) for v in s.wheel_rail.values())
    for (car, axle, side), series in s.wheel_rail.items():
        qp = derailment_coefficient(series.values[:, 1], series.values[:, 2])
        if np.any(np.isfinite(qp)) and np.nanmax(qp) > qp_max:
            qp_max, qp_where = float(np.nanmax(qp)), f'car{car:02d} axle{axle} {side}'
        if side != 'left' or (car, axle, 'right') not in s.wheel_rail:
            continue
        right = s.wheel_rail[(car, axle, 'right')]
        n = min(series.t.size, right.t.size)
        gb, dyn = wheel_load_reduction(series.values[:n, 2], right.values[:n, 2])
        if gb.max() > gb_max:
            red_where = f'car{car:02d} axle{axle}'
        gb_max, dyn_max = max(gb_max, float(gb.max())), max(dyn_max, float(dyn.max()))
        h = np.abs(series.values[:n, 1] + right.values[:n, 1])
        axle_loads.append(float(np.mean(series.values[:n, 2] + right.values[:n, 2])))
        if h.max() > h_max:
            h_max, h_where = float(h.max()), f'car{car:02d} axle{axle}'
    metrics: dict[str, Any] = {'vertical_max_N': fz_max, 'vertical_min_N': fz_min,
                               'derailment_coefficient_max': qp_max,
                               'wheel_load_reduction_max': gb_max,
                               'wheel_load_reduction_dynamic_max': dyn_max,
                               'lateral_wheelset_force_max_N': h_max}
    found = {'derailment_coefficient': (qp_max, LIMITS['derailment_coefficient'], '-', qp_where),
             'wheel_load_reduction': (gb_max, LIMITS['wheel_load_reduction'], '-', red_where)}
    if axle_loads:
        limit = lateral_force_limit(float(np.mean(axle_loads)))
        metrics['lateral_wheelset_force_limit_N'] = limit
        found['lateral_wheelset_force'] = (h_max / 1e3, limit / 1e3, 'kN', h_where)
    missing = unavailable_indices(s)
    indices = {name: _not_available(limit, unit, missing[name]) if name in missing
               else _index(value, limit, unit, where)
               for name, (value, limit, unit, where) in found.items()}
    if missing:   # null, not 0, for what the model cannot produce
        columns = {'derailment_coefficient': 'derailment_coefficient_max',
                   'wheel_load_reduction': 'wheel_load_reduction_max',
                   'lateral_wheelset_force': 'lateral_wheelset_force_max_N'}
        metrics['not_available'] = {columns[name]: reason for name, reason in missing.items()}
        metrics.update(dict.fromkeys(metrics['not_available']))
    first = s.wheel_rail[min(s.wheel_rail)]
    metrics.update(_first_wheel_rms(first))
    junction = next((m.low for m in marks_of(s) if m.label.startswith('V/')), None)
    if junction and first.rate > 4.0 * junction and first.t.size / first.rate >= 2.0:
        # as V19: 0.5 s Welch segments, the step searched within an octave of V / lambda
        f, p = welch_psd(first.values[:, 2], first.rate, segment_seconds=0.5)
        try:
            metrics['vertical_psd_level_change_hz'] = level_change_frequency(
                f, p, (0.5 * junction, 2.0 * junction))
        except ValueError as exc:
            log.info('no level change frequency of the wheel-rail PSD: %s', exc)
    return metrics, indices


FORCE_BANDS_HZ = ((0.0, 20.0), (20.0, 100.0), (100.0, 500.0))
"""Bands of the first wheel's force r.m.s. in ``metrics.json`` (Hz; up to Nyquist)."""


def _first_wheel_rms(first: Series) -> dict[str, Any]:
    """Return the first wheel's r.m.s. forces: vertical dynamic part, lateral, by band."""
    fz, fy = first.values[:, 2], first.values[:, 1]
    out: dict[str, Any] = {'first_wheel_vertical_dynamic_rms_N': float(np.std(fz)),
                           'first_wheel_lateral_rms_N': float(np.sqrt(np.mean(fy ** 2)))}
    if first.t.size >= 2 and first.rate > 0:
        lower = [lo for lo, _ in FORCE_BANDS_HZ]
        upper = [hi for _, hi in FORCE_BANDS_HZ]
        for name, values in (('vertical', fz), ('lateral', fy)):
            rms = band_rms(values, first.rate, lower, upper)
            out[f'first_wheel_{name}_band_rms_N'] = {
                f'{lo:g}-{hi:g} Hz': float(r) for (lo, hi), r in zip(FORCE_BANDS_HZ, rms)}
    return out


def _pile_metrics(s: Streams) -> dict[str, Any]:
    piles: dict[str, Any] = {}
    for key in sorted(set(s.pile_acceleration) | set(s.pile_displacement)):
        entry: dict[str, Any] = {}
        if key in s.pile_acceleration:
            az = s.pile_acceleration[key].values[:, 2]
            entry['vertical_acceleration_peak_m_s2'] = float(np.max(np.abs(az)))
            entry['vertical_acceleration_rms_m_s2'] = float(np.sqrt(np.mean(az ** 2)))
            rate = s.pile_rotation_rate[key]
            angle = np.cumsum(rate.values, axis=0) / rate.rate
            entry['rotation_peak_rad'] = float(np.max(np.abs(angle[:, :2])))
        if key in s.pile_displacement:
            d = s.pile_displacement[key].values
            entry['vertical_displacement_min_m'] = float(d[:, 2].min())
            entry['horizontal_displacement_peak_m'] = float(np.max(np.hypot(d[:, 0], d[:, 1])))
        piles[f'pier{key[0]:02d}_pile{key[1]:02d}'] = entry
    return piles


# -- power flow --------------------------------------------------------------------------

def observer_stations(s: Streams) -> dict[float, dict[str, Series]]:
    """Return {x: {layer: displacement series}} of the bag's observers, from the scenario echo."""
    specs = s.section('output').get('observers', []) if s.scenario else []
    stations: dict[float, dict[str, Series]] = {}
    for spec in specs if isinstance(specs, list) else []:
        match = _OBSERVER.match(str(spec))
        if not match or match.group(1) not in s.observers:
            continue
        name, component, x = match.group(1), match.group(2), float(match.group(3))
        layer = 'rail' if component.startswith('rail') else component
        stations.setdefault(x, {}).setdefault(layer, s.observers[name])
    return stations


def power_flows(s: Streams) -> dict[str, dict[str, tuple[np.ndarray, np.ndarray]]]:
    """
    Return the power flow spectra per observer station and layer (W per metre of track).

    At a station where the rail, slab, base and girder displacements are all
    observed, the interface forces per metre of track are those of the model's
    connections (scenario echo): fasteners ``2 (k_f du + c_f dv) / spacing``
    (two rails, both assumed to move as the observed one), and the slab-base
    and base-girder layers ``k_l du + c_l dv``.  The power flow of a layer is
    its interface force (Eq. 18) against its velocity: for the rail the force
    of the fasteners below it (power it passes down), for slab, base and girder
    the force of the connection above (power they receive).
    """
    track = s.section('track')
    if track.get('model') != 'slab':
        return {}
    out: dict[str, dict[str, tuple[np.ndarray, np.ndarray]]] = {}
    for x, layers in observer_stations(s).items():
        if not all(k in layers for k in _LAYERS):
            continue
        n = min(layers[k].t.size for k in _LAYERS)
        fs = layers['rail'].rate
        u = {k: layers[k].values[:n, 2] for k in _LAYERS}
        v = {k: velocity_from_displacement(u[k], fs) for k in _LAYERS}
        kf = 2.0 * track['fastener_vertical_stiffness'] / track['fastener_spacing']
        cf = 2.0 * track['fastener_vertical_damping'] / track['fastener_spacing']
        kl, cl = track['layer_stiffness'], track['layer_damping']
        q_fast = kf * (u['rail'] - u['slab']) + cf * (v['rail'] - v['slab'])
        q_ca = kl * (u['slab'] - u['base']) + cl * (v['slab'] - v['base'])
        q_bg = kl * (u['base'] - u['girder']) + cl * (v['base'] - v['girder'])
        out[f'x={x:g} m'] = {
            'rail': power_flow_spectrum(q_fast, v['rail'], fs),
            'slab': power_flow_spectrum(q_fast, v['slab'], fs),
            'base': power_flow_spectrum(q_ca, v['base'], fs),
            'girder': power_flow_spectrum(q_bg, v['girder'], fs)}
    return out


def pier_power_flows(s: Streams) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """
    Return the power flow spectrum into each pier through its bearings (W), by pier number.

    Eq. 18 with the force the two bearings put on the pier top (their sum, x,
    y, z) against the pier top's velocity (differentiated from its recorded
    displacement): the vibration power the girders pass into the pier, its
    foundation and the ground. The pier top's rotation is not recorded, so the
    power of the bearing pair's moment (their force difference times half
    their spacing, against the rocking rate) is left out: zero where the load
    is symmetric about the centreline (quarter cars, moving forces).
    """
    out: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    for pier, top in sorted(s.pier_top.items()):
        left, right = s.bearing.get((pier, 'left')), s.bearing.get((pier, 'right'))
        if left is None or right is None:
            continue
        n = min(top.t.size, left.t.size, right.t.size)
        force = left.values[:n] + right.values[:n]
        velocity = np.column_stack([velocity_from_displacement(top.values[:n, c], top.rate)
                                    for c in range(3)])
        spectra = [power_flow_spectrum(force[:, c], velocity[:, c], top.rate) for c in range(3)]
        out[pier] = (spectra[0][0], spectra[0][1] + spectra[1][1] + spectra[2][1])
    return out


def _pier_power_metrics(f: np.ndarray, p: np.ndarray) -> dict[str, float]:
    """Return the mean power into a pier, in total and at 0-1 Hz ([P] Figs. 18-19's band)."""
    return {'mean_W': float(np.sum(p)), 'mean_0_1_Hz_W': float(np.sum(p[f <= 1.0]))}


# -- comparing bags ----------------------------------------------------------------------

def flatten(metrics: dict[str, Any], prefix: str = '') -> dict[str, float]:
    """Return the numeric leaves of a metrics tree as {'a.b.c': value} (lists left out)."""
    out: dict[str, float] = {}
    for key, value in metrics.items():
        name = f'{prefix}{key}'
        if isinstance(value, dict):
            out.update(flatten(value, name + '.'))
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            out[name] = float(value)
    return out


def differences(labels: Sequence[str], metrics: Sequence[dict[str, Any]]) -> list[list[Any]]:
    """
    Return rows (metric, value per bag, then per other bag: difference and relative difference).

    Differences are against the first bag; the relative one is None where the
    first bag's value is 0. Bookkeeping numbers (durations, rates, times) are left out.
    """
    flat = [flatten({k: v for k, v in m.items()
                     if k not in ('analysis_time_s', 'duration_s', 'sample_rate_hz',
                                  'excitation_hz')}) for m in metrics]
    keys: list[str] = []
    for f in flat:
        keys.extend(k for k in f if k not in keys and not k.endswith('.limit'))
    rows = []
    for key in keys:
        values = [f.get(key) for f in flat]
        row: list[Any] = [key, *values]
        base = values[0]
        for v in values[1:]:
            if base is None or v is None:
                row.extend([None, None])
            else:
                row.extend([v - base, (v - base) / abs(base) if base else None])
        rows.append(row)
    return rows
