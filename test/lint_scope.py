# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""What the lint tests read: the package's sources, not what builds and runs leave beside them."""

# pip's and colcon's build trees hold copies of the sources; bags/ and .venv hold no sources.
EXCLUDED = ['build', 'install', 'log', 'bags', '.venv', '.bench-peers']
