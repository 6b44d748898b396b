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
The reports of bags: metrics, figures and the output folder of ``analyze``, ``compare``, ``sweep``.

It joins the two independent packages below it: the bag as named streams
(:mod:`ttb_sim.io.streams`) and the physics on arrays (:mod:`ttb_sim.analysis`);
it never imports the model or the stepping core.

- :mod:`~ttb_sim.report.metrics`: the numbers of one bag (``metrics.json``), the
  streams the figures share (excitation marks, the soil observation line, the
  observer stations and their power flow), and the differences between bags;
- :mod:`~ttb_sim.report.figures`: one PNG per question of [P] section 4, each bag a
  trace, skipped with the reason where no bag has the streams;
- :mod:`~ttb_sim.report.output`: staged output folders, JSON with NaN as null, the
  ``index.html`` page and the :class:`~ttb_sim.report.output.FigureNote` it lists;
- :mod:`~ttb_sim.report.sweep_figures`: peak responses against train speed of a sweep.
"""
