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

"""The layer rules of ARCHITECTURE.md as import-linter contracts (setup.cfg [importlinter])."""

import logging
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_import_contracts_hold(monkeypatch):
    """Imports only point downward; analysis never imports model, sim or fe."""
    cli = pytest.importorskip('importlinter.cli', reason='import-linter is a test extra')
    monkeypatch.chdir(ROOT)
    monkeypatch.syspath_prepend(str(ROOT))
    # lint_imports configures logging with disable_existing_loggers: without this, every
    # logger made before it stays disabled for the rest of the session (later caplog tests
    # would see nothing).
    existing = [logger for logger in logging.root.manager.loggerDict.values()
                if isinstance(logger, logging.Logger) and not logger.disabled]
    try:
        assert cli.lint_imports(config_filename=str(ROOT / 'setup.cfg'), no_cache=True) == 0
    finally:
        for logger in existing:
            logger.disabled = False
