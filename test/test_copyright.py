# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""Every source file names its copyright and its licence (ament_copyright is not on PyPI)."""

from pathlib import Path
import re

from lint_scope import EXCLUDED
import pytest

REPOSITORY = Path(__file__).resolve().parent.parent
LICENCE = 'Apache-2.0'
# One header for Python and shell, one for XML; the year is the file's first.
HASH_HEADER = re.compile(
    r'(#![^\n]*\n)?# Copyright (20\d\d) linkage_kinematics maintainers\n'
    rf'# SPDX-License-Identifier: {re.escape(LICENCE)}\n')
XML_HEADER = re.compile(
    r'(<\?xml[^\n]*\n)?<!-- Copyright (20\d\d) linkage_kinematics maintainers\n'
    rf' +SPDX-License-Identifier: {re.escape(LICENCE)} -->\n')
SHELL_SCRIPTS = ['dev', '.ci/run']


def source_files() -> list[Path]:
    def kept(path: Path) -> bool:
        parts = path.relative_to(REPOSITORY).parts
        return not any(part in EXCLUDED or part.startswith('.') for part in parts[:-1])
    python = [p for p in REPOSITORY.rglob('*.py') if kept(p)]
    launch_xml = sorted((REPOSITORY / 'launch').glob('*.xml'))
    return sorted(python) + launch_xml + [REPOSITORY / name for name in SHELL_SCRIPTS]


def test_the_licence_file_is_the_one_package_xml_names() -> None:
    assert f'<license>{LICENCE}</license>' in (REPOSITORY / 'package.xml').read_text()
    text = (REPOSITORY / 'LICENSE').read_text()
    assert 'Apache License' in text and 'Version 2.0, January 2004' in text
    assert 'END OF TERMS AND CONDITIONS' in text


@pytest.mark.parametrize('path', source_files(), ids=lambda p: str(p.relative_to(REPOSITORY)))
def test_source_file_has_the_copyright_and_licence_header(path: Path) -> None:
    header = XML_HEADER if path.suffix == '.xml' else HASH_HEADER
    assert header.match(path.read_text(encoding='utf-8')), (
        f'{path.relative_to(REPOSITORY)} does not start with the copyright and SPDX header')
