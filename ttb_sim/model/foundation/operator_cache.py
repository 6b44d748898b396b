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
The on-disk cache of reduced pile-soil operators.

The operator of a given set of inputs is cached (``$TTB_SIM_CACHE`` or
``~/.cache/ttb_sim``) under a hash of every input (:func:`cache_key`); the
build is deterministic, so a cache hit gives the same bits as a fresh build. A
corrupt or unwritable cache is logged and bypassed.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
from pathlib import Path
from typing import Any, Optional

import numpy as np
import scipy

from ttb_sim.fe.beam import BeamSection
from ttb_sim.fe.complex_solve import resolve_method
from ttb_sim.model.foundation.krylov import positive_definite_method
from ttb_sim.model.foundation.operator import FoundationOperator, InterfaceRows
from ttb_sim.model.foundation.records import FoundationError, ReductionParameters, Substructure

LOG = logging.getLogger(__name__)

FORMAT = 5
"""Version of the reduction and of its cache files; part of the cache key."""


def cache_directory() -> Path:
    """Return the cache directory: ``$TTB_SIM_CACHE`` or ``~/.cache/ttb_sim``."""
    env = os.environ.get('TTB_SIM_CACHE', '')
    return Path(env) if env else Path.home() / '.cache' / 'ttb_sim'


def cache_key(spec: Substructure, pier_height: float, pier_elements: int,
              pier_section: BeamSection, pier_rayleigh: tuple[float, float],
              reduction: ReductionParameters) -> str:
    """Return the SHA-256 of every input of :func:`pile_soil_operator` (and the code)."""
    digest = hashlib.sha256()
    text = repr((FORMAT, positive_definite_method(), np.__version__, scipy.__version__, spec,
                 float(pier_height), int(pier_elements),
                 tuple(float(v) for v in pier_rayleigh), reduction))
    if reduction.shift_axis == 'imaginary':   # the complex pencils' solver (PARDISO or not)
        text += repr(resolve_method('auto'))
    digest.update(text.encode())
    for name in ('ea', 'gj', 'ei_y', 'ei_z', 'mass', 'inertia_x'):
        digest.update(np.ascontiguousarray(getattr(pier_section, name), dtype=float).tobytes())
    return digest.hexdigest()


_ARRAYS = ('mass', 'damping', 'stiffness', 'pile_heads', 'pile_positions', 'soil_points',
           'soil_point_positions', 'pile_rotations')
_INTERFACE = ('normal', 'shear', 'sigma_n0', 'cohesion', 'tan_delta')
_OPTIONAL = ('pile_strain', 'pile_layer_depths')


def save_operator(path: Path, op: FoundationOperator) -> None:
    """Write ``op`` to ``path`` (atomically); an unwritable cache is logged and bypassed."""
    arrays: dict[str, Any] = {name: getattr(op, name) for name in _ARRAYS}
    arrays['soil_point_names'] = np.array(op.soil_point_names, dtype=str)
    arrays['depth'] = np.array(op.depth)
    arrays['summary'] = np.array(json.dumps(op.summary))
    arrays.update({n: getattr(op, n) for n in _OPTIONAL if getattr(op, n) is not None})
    if op.interface is not None:
        arrays.update({f'interface_{n}': getattr(op.interface, n) for n in _INTERFACE})
    tmp = path.with_name(f'.{path.name}.{os.getpid()}.tmp')
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(tmp, 'wb') as handle:
            np.savez(handle, **arrays)
        os.replace(tmp, path)
        LOG.info('reduced pile-soil substructure cached in %s', path)
    except OSError as err:
        LOG.warning('could not write the cache %s (%s); continuing without it', path, err)
        with contextlib.suppress(OSError):
            tmp.unlink()


def load_operator(path: Path) -> Optional[FoundationOperator]:
    """Return the operator cached in ``path``, or None (logged) if it is unreadable."""
    try:
        with np.load(path, allow_pickle=False) as data:
            got = {name: data[name] for name in data.files}
        n = got['mass'].shape[0]
        iface = None
        if 'interface_normal' in got:
            iface = InterfaceRows(**{name: got[f'interface_{name}'] for name in _INTERFACE})
            if iface.normal.shape[1] != n or iface.shear.shape != (2 * iface.n_points, n):
                raise FoundationError('interface rows of the wrong shape')
        op = FoundationOperator(**{name: got[name] for name in _ARRAYS},
                                soil_point_names=tuple(str(s) for s in got['soil_point_names']),
                                depth=float(got['depth']),
                                summary=json.loads(str(got['summary'])), interface=iface,
                                pile_strain=got.get('pile_strain'),
                                pile_layer_depths=got.get('pile_layer_depths'))
        square = all(getattr(op, a).shape == (n, n) for a in ('mass', 'damping', 'stiffness'))
        if (not square or op.pile_heads.shape != (3 * op.n_piles, n)
                or op.soil_points.shape != (3 * len(op.soil_point_names), n)
                or (op.pile_strain is not None and op.pile_strain.shape[1] != n)):
            raise FoundationError('arrays of inconsistent shapes')
        return op
    except Exception as err:  # noqa: B902 - any unreadable cache file means: rebuild
        LOG.warning('the cache file %s is unreadable (%s); rebuilding', path,
                    f'{type(err).__name__}: {err}')
        return None
