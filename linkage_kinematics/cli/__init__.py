# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The command-line tools over the library, one module each.

``sweep`` (``linkage-sweep``), ``demo`` (``linkage-demo``), ``replay`` (``linkage-replay``) and
``check_loops`` (``linkage-check-loops``); ``arguments`` holds the argument types they share.
"""
