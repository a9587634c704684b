# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
bench/document.py, which writes docs/benchmarks.md from a run's figures, and the document itself.

The document must be what the writer makes of its own sections: text typed into it by hand
outside a run's section would be lost at the next run, and a section must come from a run.
"""

from __future__ import annotations

import datetime
import importlib
from pathlib import Path
import sys

import pytest

REPOSITORY = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPOSITORY / 'bench'))
document = importlib.import_module('document')

RUN = document.Run('`abc1234`', 'a machine; Python 3.11.7', './dev bench --only drive')
WHEN = datetime.datetime(2026, 11, 28, 12, 0, tzinfo=datetime.timezone.utc)
NODE_LIKE = """Cost per tick (one process):

| part | time |
|---|---|
| tick | 1 µs |

- whole tick / bare publish = 2×

Logging one message (three per tick):

| part | CPU |
|---|---|
| record | 1 µs |

Log at the default settings: 1 kB/s."""


def test_a_sections_markdown_splits_into_one_table_each_with_its_caption() -> None:
    parts = document.split_tables(NODE_LIKE)
    assert len(parts) == 2
    assert parts[0].startswith('Cost per tick') and parts[0].endswith('= 2×')
    assert parts[1].startswith('Logging one message') and parts[1].endswith('1 kB/s.')


def test_text_before_the_first_caption_joins_the_first_table() -> None:
    parts = document.split_tables('intro\n\n**robot a**\n\n| x |\n|---|\n\n**robot b**\n\n'
                                  '| y |\n|---|\n\nafter')
    assert parts == ['intro\n\n**robot a**\n\n| x |\n|---|',
                     '**robot b**\n\n| y |\n|---|\n\nafter']


def test_a_run_rewrites_its_sections_and_keeps_the_others(tmp_path: Path) -> None:
    path = tmp_path / 'benchmarks.md'
    document.write(path, RUN, {'drive': document.Measured(('| a |\n|---|\n| 1 |',), WHEN)})
    first = path.read_text()
    assert 'Not measured yet: `./dev bench --only tf`.' in first
    assert '*Measured 2026-11-28 12:00 UTC at commit `abc1234`' in first
    later = document.Run('`def5678`', 'a machine; Python 3.12.1', './dev bench --only tf')
    document.write(path, later, {'tf': document.Measured(('| b |\n|---|\n| 2 |',), WHEN)})
    second = path.read_text()
    drive = second[second.index('<!-- bench section: drive -->'):
                   second.index('<!-- end of bench section: drive -->')]
    assert drive in first and '| 1 |' in drive and '`abc1234`' in drive
    assert '| 2 |' in second and '`def5678`' in second
    assert 'Not measured yet: `./dev bench --only tf`.' not in second


def test_a_section_with_a_table_per_heading_gets_the_sections_headings() -> None:
    text = document.render('node', RUN, document.Measured(
        (NODE_LIKE + '\n\nSustained rate:\n\n| r |\n|---|\n\nTimer jitter:\n\n| j |\n|---|',),
        WHEN))
    assert [line for line in text.splitlines() if line.startswith('### ')] == [
        f'### {title}' for title in document.SECTIONS['node'].tables]


def test_the_committed_document_is_the_writers_own(tmp_path: Path) -> None:
    text = (REPOSITORY / 'docs' / 'benchmarks.md').read_text(encoding='utf-8')
    kept = dict(document.SECTION_TEXT.findall(text))
    assert set(kept) == set(document.SECTIONS)
    # every section comes from a run, with its run's line
    assert all(part.split('\n')[2].startswith('*Measured ') for part in kept.values()), [
        key for key, part in kept.items() if not part.split('\n')[2].startswith('*Measured ')]
    # written again with no new figures, it is the same to the byte
    rewritten = tmp_path / 'benchmarks.md'
    rewritten.write_text(text, encoding='utf-8')
    document.write(rewritten, RUN, {})
    assert rewritten.read_text(encoding='utf-8') == text


@pytest.mark.parametrize('key', list(document.SECTIONS))
def test_each_plot_the_document_shows_is_there(key: str) -> None:
    for file, _ in document.SECTIONS[key].plots:
        assert (REPOSITORY / 'docs' / file).is_file()
