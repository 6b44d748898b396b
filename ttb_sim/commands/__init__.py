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
The ROS-free verbs of ``ttb-sim``: run, validate, scenarios, bench, modes, analyze, compare, sweep.

Each verb is a function that takes plain arguments, calls the libraries, prints
what a user reads and returns the exit code; ``cli.py`` only parses arguments and
maps errors to exit codes, and tests call the verbs directly.  Beside the verbs:
``signals`` (SIGINT / SIGTERM for the command line and the verbs), ``bench_runs``
(one measured run of ``bench``) and ``sweep_case`` (one case of ``sweep``).  The
reports of bags are the library :mod:`ttb_sim.report`.
"""
