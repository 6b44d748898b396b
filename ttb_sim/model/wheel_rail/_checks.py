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

"""Argument checks shared by the wheel-rail contact modules (package-internal)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ttb_sim.errors import ModelError


def check_positive(name: str, value: ArrayLike) -> np.ndarray:
    """
    Return ``value`` as a float array, checked to be finite and > 0 everywhere.

    Parameters
    ----------
    name : str
        Name of the argument, for the message.
    value : array_like
        The argument.

    Returns
    -------
    numpy.ndarray
        ``value`` as floats.

    Raises
    ------
    ModelError
        Naming the first value that is not finite or not > 0.

    """
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr) & (arr > 0.0)):
        bad = arr[~(np.isfinite(arr) & (arr > 0.0))].ravel()[0]
        raise ModelError(f'{name} = {bad!r} is invalid; allowed: finite and > 0')
    return arr
