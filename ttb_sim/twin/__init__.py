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
Digital-twin workflows: priors over scenario keys, designs, and the features of a passage.

- :mod:`ttb_sim.twin.priors` — uniform, normal, lognormal and discrete priors, and the
  Sobol' / Latin-hypercube / random designs that draw cases from them;
- :mod:`ttb_sim.twin.spec` — the spec of ``ttb-sim dataset``;
- :mod:`ttb_sim.twin.features` — per-sensor mean, RMS, peak and PSD on a common grid;
- :mod:`ttb_sim.twin.forward` — a scenario as a function of some keys: ``model(theta)``.
"""

from ttb_sim.twin.features import channel_features, Features, FeatureSpec, sensor_features
from ttb_sim.twin.forward import FeatureVector, ForwardModel
from ttb_sim.twin.priors import draw_cases, parse_prior, Prior, SAMPLERS
from ttb_sim.twin.spec import DatasetSpec, read_spec

__all__ = ['channel_features', 'DatasetSpec', 'draw_cases', 'Features', 'FeatureSpec',
           'FeatureVector', 'ForwardModel',
           'parse_prior', 'Prior', 'read_spec', 'SAMPLERS', 'sensor_features']
