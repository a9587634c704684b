# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Every relative link of the documents reaches its file, and its anchor a heading there.

README.md, CONTRIBUTING.md and docs/*.md; anchors as GitHub makes them from headings, so that
moving a section breaks no link unseen.
"""

from __future__ import annotations

from pathlib import Path
import re

import pytest

REPOSITORY = Path(__file__).resolve().parent.parent
DOCUMENTS = [REPOSITORY / 'README.md', REPOSITORY / 'CONTRIBUTING.md',
             *sorted((REPOSITORY / 'docs').glob('*.md'))]
LINK = re.compile(r'\]\(([^)\s]+)\)')
HEADING = re.compile(r'^#{1,6} (.+?)\s*$')
FENCE = re.compile(r'^\s*```')


def prose(text: str) -> list[str]:
    """Return the lines of ``text`` outside its code blocks."""
    lines, inside = [], False
    for line in text.splitlines():
        if FENCE.match(line):
            inside = not inside
        elif not inside:
            lines.append(line)
    return lines


def anchor(heading: str) -> str:
    """Return GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r'[^\w\- ]', '', heading.lower()).replace(' ', '-')


def anchors(document: Path) -> set[str]:
    return {anchor(match[1]) for line in prose(document.read_text(encoding='utf-8'))
            if (match := HEADING.match(line))}


def broken_links(document: Path) -> list[str]:
    """Return each relative link of ``document`` whose file or anchor is not there."""
    broken = []
    for line in prose(document.read_text(encoding='utf-8')):
        for target in LINK.findall(line):
            if re.match(r'[a-z]+:', target):
                continue  # another site's page
            path, _, fragment = target.partition('#')
            linked = (document.parent / path).resolve() if path else document
            if not linked.exists():
                broken.append(f'{target}: no {linked}')
            elif fragment and linked.suffix == '.md' and fragment not in anchors(linked):
                broken.append(f'{target}: no heading #{fragment} in {linked.name}')
    return broken


@pytest.mark.parametrize('document', DOCUMENTS, ids=lambda path: path.name)
def test_every_relative_link_reaches_its_file_and_heading(document: Path) -> None:
    assert broken_links(document) == []


@pytest.mark.parametrize(('heading', 'expected'), [
    ('Giving the node the description', 'giving-the-node-the-description'),
    ('With `loops:=robot_description`', 'with-loopsrobot_description'),
    ("Mapping to a lab's URDF", 'mapping-to-a-labs-urdf'),
    ('Checking a URDF: linkage-check-loops', 'checking-a-urdf-linkage-check-loops'),
    ('Rates: what is measured, exact or estimated', 'rates-what-is-measured-exact-or-estimated'),
])
def test_anchors_are_githubs(heading: str, expected: str) -> None:
    assert anchor(heading) == expected


def test_a_missing_heading_and_a_missing_file_are_reported(tmp_path: Path) -> None:
    document = tmp_path / 'doc.md'
    document.write_text('# Title\n\n[a](#title) [b](#other) [c](doc.md#title) [d](none.md)\n'
                        '```\n[e](#in-code)\n```\n[f](https://example.org/#x)\n')
    problems = broken_links(document)
    assert len(problems) == 2 and '#other' in problems[0] and 'none.md' in problems[1]
