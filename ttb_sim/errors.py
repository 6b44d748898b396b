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

"""Exceptions raised by ttb_sim; the CLI maps them to exit codes."""


class TtbSimError(Exception):
    """Base class of every error ttb_sim raises on purpose."""


class ScenarioError(TtbSimError, ValueError):
    """A scenario, argument or input file is invalid (CLI exit code 2)."""


class ModelError(TtbSimError, ValueError):
    """
    A physical argument given to the model layer is invalid (CLI exit code 2).

    Raised by ``model/`` and ``fe/`` code, which knows arguments but not scenario
    keys; the configuration layer re-raises it as :class:`ScenarioError` naming
    the key path.
    """


class FEError(ModelError):
    """An argument given to the finite-element layer (``fe/``) is invalid (CLI exit code 2)."""


class SimulationError(TtbSimError, RuntimeError):
    """The simulation could not be carried out (CLI exit code 1)."""


class DivergenceError(SimulationError):
    """The solution became non-finite or exceeded its divergence limit (exit code 1)."""


class BagError(ScenarioError):
    """A bag to read is missing, not a bag, truncated or lacks a topic (exit code 2)."""
