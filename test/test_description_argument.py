# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
When ``-p robot_description:=TEXT`` on the command line reaches a node: rcl's rule, checked on rcl.

rcl reads the text after ``:=`` as one YAML value (rcl/src/rcl/arguments.c
``_rcl_parse_param_rule`` → rcl_yaml_param_parser ``rcl_parse_yaml_value``, libyaml): a URDF
given as it is must be a YAML plain scalar, and one given single-quoted may hold anything but a
line that starts a YAML document marker. docs/following_loops.md states the rule; these tests
hold rcl (the rclpy the package runs on) and the package's own URDFs to it.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
import rclpy
from rclpy.node import Node

REPOSITORY = Path(__file__).resolve().parent.parent
URDFS = sorted((REPOSITORY / 'urdf').glob('*.urdf'))


class Refused(Exception):
    """rcl refused the argument (rclpy.init raised: "Couldn't parse parameter override rule")."""


@pytest.fixture
def passed(domain_id: int) -> Iterator:
    """Return a function: the value a node gets from ``-p robot_description:=TEXT``."""
    contexts = []

    def through_rcl(text: str) -> str:
        context = rclpy.Context()
        try:
            rclpy.init(args=['probe', '--ros-args', '-p', f'robot_description:={text}'],
                       context=context, domain_id=domain_id)
        except Exception as error:
            assert "Couldn't parse parameter override rule" in str(error)
            raise Refused(str(error)) from None
        contexts.append(context)
        node = Node('probe', context=context,
                    automatically_declare_parameters_from_overrides=True)
        try:
            return node.get_parameter('robot_description').value
        finally:
            node.destroy_node()

    yield through_rcl
    for context in contexts:
        context.try_shutdown()


def single_quoted(text: str) -> str:
    """Return ``text`` as the documented command quotes it: "'$(sed "s/'/''/g" FILE)'"."""
    return "'" + text.replace("'", "''") + "'"


def words(text: str) -> list[str]:
    return text.split()


@pytest.mark.parametrize('path', URDFS, ids=lambda path: path.name)
def test_each_urdf_of_the_package_passes_as_it_is(passed, path: Path) -> None:
    # "$(cat FILE)": the shell drops the file's last line break
    text = path.read_text(encoding='utf-8').rstrip('\n')
    value = passed(text)
    # YAML folds each line break (and the next line's indentation) into one space: the same XML
    assert value != text and words(value) == words(text)


# A URDF with a line of each kind, and where rcl stops.
BODY = '<robot name="r">\n  <link name="a"/>\n  {}\n  <link name="b"/>\n</robot>'
REFUSED_AS_IT_IS = {
    'a colon before a space': '<!-- Note: the rod is 0.3 m -->',
    'a colon ending a line': '<!-- the rod, measured:\n       0.3 m -->',
    'a hash sign after a space': '<!-- urdfdom PR #264 -->',
    'a hash sign starting a line': '<!--\n# exported -->',
}


@pytest.mark.parametrize('line', REFUSED_AS_IT_IS.values(), ids=REFUSED_AS_IT_IS.keys())
def test_yaml_syntax_in_a_urdf_given_as_it_is_is_refused_and_single_quoted_passes(
        passed, line: str) -> None:
    text = BODY.format(line)
    with pytest.raises(Refused):
        passed(text)
    assert words(passed(single_quoted(text))) == words(text)


def test_a_colon_without_a_space_and_a_hash_sign_inside_a_word_pass_as_they_are(passed) -> None:
    text = BODY.format('<link name="c#1"><visual><geometry><mesh '
                       'filename="package://robot/meshes/c.stl"/></geometry></visual></link>')
    assert words(passed(text)) == words(text)


def test_a_quote_is_doubled_inside_single_quotes(passed) -> None:
    text = BODY.format("<!-- the foot's end: here -->")
    assert words(passed(single_quoted(text))) == words(text)


def test_a_line_starting_with_a_document_marker_is_refused_or_cuts_the_text(passed) -> None:
    ended = BODY.format('<!--\n... more -->')
    for text in (ended, single_quoted(ended)):
        with pytest.raises(Refused):
            passed(text)
    started = BODY.format('<!--\n--- -->')
    # as it is, rcl keeps only what follows the marker, without a word
    assert passed(started) == '--> <link name="b"/> </robot>'
    with pytest.raises(Refused):
        passed(single_quoted(started))
