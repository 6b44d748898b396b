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
The piers' foundations: springs or piled, and the 3-D pile-soil substructure of a piled pier.

:mod:`.pier_foundations` (the foundation record, springs, piled piers in the structure),
:mod:`.records` and :mod:`.consistency` (soil, piles, cap, interface, load, and their
cross-checks), :mod:`.desai` (the interface law), :mod:`.soil_mesh`, :mod:`.substructure`
and :mod:`.observation` (the finite-element substructure), :mod:`.operator` (what the
bridge sees of it), :mod:`.tied`, :mod:`.krylov`, :mod:`.reduction` and
:mod:`.operator_cache` (its reduced operator and the cache of it), :mod:`.frequency_response`
(its harmonic response in the frequency domain, with a perfectly matched layer: the reference
of mesh convergence).
"""
