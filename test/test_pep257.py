# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

from ament_pep257.main import main
from lint_scope import EXCLUDED
import pytest


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257():
    rc = main(argv=['.', '--exclude', *EXCLUDED])
    assert rc == 0, 'Found code style errors / warnings'
