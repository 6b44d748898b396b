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
The ``simulator`` console script (``ros2 run ttb_sim simulator``).

It imports the node only inside :func:`main`, so that a Ctrl-C while rclpy, numpy
and scipy are still being imported (the first second or two) ends the process
quietly with exit code 0, like a Ctrl-C at any later moment, instead of a
``KeyboardInterrupt`` traceback from the import machinery.

Once the node has shut down (bag closed, node destroyed, rclpy shut down) the
process ends with :func:`os._exit`: a worker thread of rclpy's
``MultiThreadedExecutor`` pool was seen to keep the interpreter waiting for ever
at exit after a Ctrl-C during the model build, and nothing is left to flush.
"""

import os
import sys


def main() -> int:
    """Run :func:`ttb_sim.simulator_node.main`; a Ctrl-C at any moment exits 0."""
    try:
        from ttb_sim.simulator_node import main as node_main
        code = node_main()
    except KeyboardInterrupt:
        code = 0
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):   # a closed pipe: nothing more to say
            pass
    os._exit(code)


if __name__ == '__main__':
    main()
