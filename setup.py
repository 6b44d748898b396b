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

"""Install ttb_sim with pip (`pip install .`) or colcon (ament_python)."""

from glob import glob

from setuptools import find_packages, setup

package_name = 'ttb_sim'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test', 'test.*']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*.yaml') + glob('config/*.rviz')),
        ('share/' + package_name + '/launch', glob('launch/*.py')),
    ],
    python_requires='>=3.10',
    install_requires=['setuptools', 'numpy>=1.24', 'scipy>=1.10', 'rosbags>=0.10',
                      'PyYAML>=6', 'tqdm>=4.60',
                      # ttb-sim analyze / compare / sweep figures (Agg back-end, no display)
                      'matplotlib>=3.6',
                      # solver.variant (docs/performance.md); each is optional at run time:
                      # without it the variants fall back to scipy / leave BLAS threads as
                      # they are.
                      'cholespy>=2.0', 'qdldl>=0.1.7', 'threadpoolctl>=3',
                      # compiled kernels of the lean step (ttb_sim/sim/kernel_registry.py); without
                      # it the numpy twins run.
                      'numba>=0.59',
                      # `ttb-sim validate V15`'s independent 3-D FE (BSD-3-Clause, pure
                      # Python: its own hexahedra, quadrature and facet integration)
                      'scikit-fem>=10'],
    extras_require={
        # ttb-sim sweep --scheduler ADDRESS (a Dask distributed cluster)
        'dask': ['dask[distributed]>=2023.1'],
        # `ttb-sim frf`'s complex sparse solves by MKL PARDISO (else scipy's SuperLU, ~17x
        # slower on a 47 520-DOF block); sparse_dot_mkl is MIT, the mkl wheel Intel's ISSL
        'pardiso': ['sparse_dot_mkl>=0.9', 'mkl'],
        # the documentation site, `mkdocs build --strict` (mkdocs.yml; .ci/run builds it):
        # mkdocs 1.6 for the README hook and anchor checks, mkdocstrings-python 2 for
        # `filters: public`
        'docs': ['mkdocs>=1.6', 'mkdocs-material>=9', 'mkdocstrings[python]>=1.0',
                 'mkdocstrings-python>=2.0'],
        # the twin workflows: dataset's table (Parquet, pyarrow), identify's sampler (emcee,
        # MIT), its surrogate (scikit-learn's Gaussian process, BSD), its corner plot (corner,
        # BSD)
        'twin': ['pyarrow>=14', 'emcee>=3.1', 'scikit-learn>=1.3', 'corner>=2.2'],
        # operational modal analysis in analyze: SSI of strid (MIT)
        'oma': ['strid>=0.4'],
        'test': ['dask[distributed]>=2023.1', 'pyarrow>=14', 'pandas>=2', 'emcee>=3.1',
                 'scikit-learn>=1.3', 'corner>=2.2', 'strid>=0.4',
                 'pytest>=7', 'mcap>=1.1', 'mcap-ros2-support>=0.5', 'flake8>=6',
                 'flake8-quotes', 'flake8-import-order', 'flake8-builtins',
                 'flake8-comprehensions', 'flake8-class-newline', 'flake8-blind-except',
                 'flake8-deprecated', 'flake8-docstrings', 'pydocstyle>=6',
                 'import-linter>=2', 'mypy>=1.10', 'types-PyYAML', 'hypothesis>=6.100'],
    },
    package_data={'ttb_sim': ['py.typed']},
    zip_safe=True,
    maintainer='ttb_sim maintainers',
    maintainer_email='maintainers@ttb-sim.invalid',
    description='Train-track-bridge-pier-cap-pile-soil dynamics with rosbag2 output.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'ttb-sim = ttb_sim.cli:entry',
            'simulator = ttb_sim.simulator:main',
        ],
    },
)
