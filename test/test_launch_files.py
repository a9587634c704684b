# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The launch files and their parameters files.

Tested without `launch` (not installable here): what they name exists in the installed share/ and
entry points, they use only launch API that every Jazzy release has (launch 3.4.0 on), and each
parameters file starts the node to its end with ``--params-file``, in the namespaces it is meant
for.
"""

from __future__ import annotations

import ast
from importlib.metadata import entry_points
import math
from pathlib import Path
import re
import xml.etree.ElementTree as ElementTree

from ament_index_python.packages import get_package_share_directory
from linkage_kinematics.bag.reader import read_states
from linkage_kinematics.drive import DriveLaw
from linkage_kinematics.parameters import mechanism_namespaces
from node_process import PROCESS_TIMEOUT, REPOSITORY, start_node, stop_process
import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores

DOMAIN_ID = 78
SHARE = Path(get_package_share_directory('linkage_kinematics'))
TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
PYTHON_LAUNCH_FILES = ('linkage.launch.py', 'mechanisms.launch.py')
# What the launch files may import: present, with these signatures, since launch 3.4.0 and
# launch_ros 0.26.0 (the first Jazzy releases).
LAUNCH_API = {
    'launch': {'LaunchDescription'},
    'launch.actions': {'DeclareLaunchArgument', 'OpaqueFunction'},
    'launch.substitutions': {'LaunchConfiguration'},
    'launch_ros.actions': {'Node'},
    'ament_index_python.packages': {'get_package_share_directory'},
    'linkage_kinematics.parameters': {'NODE_NAME', 'mechanism_namespaces'},
}


def test_the_launch_and_parameters_files_are_installed_as_in_the_source_tree() -> None:
    for folder, pattern in (('launch', '*.launch.*'), ('config', '*.yaml')):
        source = {path.name: path.read_bytes() for path in (REPOSITORY / folder).glob(pattern)}
        installed = {path.name: path.read_bytes() for path in (SHARE / folder).glob(pattern)}
        assert source and installed == source


@pytest.mark.parametrize('name', PYTHON_LAUNCH_FILES)
def test_python_launch_files_use_only_launch_api_every_jazzy_release_has(name: str) -> None:
    tree = ast.parse((SHARE / 'launch' / name).read_text())
    imported = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            imported.setdefault(node.module, set()).update(alias.name for alias in node.names)
    for module, names in imported.items():
        assert names <= LAUNCH_API.get(module, set()), (module, names)
    # No substitution list nested in another (launch before 3.4.5 cannot normalize them).
    for node in ast.walk(tree):
        if isinstance(node, ast.List):
            assert not any(isinstance(item, ast.List) for item in node.elts)
    calls = {node.func.id: node for node in ast.walk(tree)
             if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)}
    keywords = {keyword.arg: keyword.value for keyword in calls['Node'].keywords}
    assert ast.literal_eval(keywords['package']) == 'linkage_kinematics'
    executable = ast.literal_eval(keywords['executable'])
    assert executable in {entry.name for entry in entry_points(group='console_scripts')}
    assert 'generate_launch_description' in {
        node.name for node in tree.body if isinstance(node, ast.FunctionDef)}


def test_the_scenario_launch_files_name_existing_parameters_files() -> None:
    python_tree = ast.parse((SHARE / 'launch' / 'linkage.launch.py').read_text())
    (argument,) = [node for node in ast.walk(python_tree) if isinstance(node, ast.Call)
                   and getattr(node.func, 'id', None) == 'DeclareLaunchArgument']
    keywords = {keyword.arg: keyword.value for keyword in argument.keywords}
    choices = ast.literal_eval(keywords['choices'])
    assert ast.literal_eval(keywords['default_value']) in choices
    for scenario in choices:
        assert (SHARE / 'config' / f'seed_{scenario}.yaml').is_file()

    xml = ElementTree.parse(SHARE / 'launch' / 'linkage.launch.xml').getroot()
    (node,) = xml.iter('node')
    assert (node.get('pkg'), node.get('exec')) == ('linkage_kinematics', 'linkage_node')
    (argument,) = xml.iter('arg')
    # A misspelt scenario fails at launch, as in the Python file, instead of running defaults.
    assert [choice.get('value') for choice in argument.iter('choice')] == choices
    assert argument.get('default') in choices
    (parameters,) = node.iter('param')
    for scenario in choices:
        path = parameters.get('from').replace(
            '$(find-pkg-share linkage_kinematics)', str(SHARE)
        ).replace('$(var scenario)', scenario)
        assert Path(path).is_file()
    assert not re.search(r'\$\((?!find-pkg-share |var )', parameters.get('from'))


def test_mechanism_namespaces_come_from_the_parameters_file(tmp_path: Path) -> None:
    assert mechanism_namespaces(SHARE / 'config' / 'two_mechanisms.yaml') == ['/left', '/right']
    for text, problem in (('/**/linkage_node:\n  ros__parameters: {}\n', '/**/linkage_node'),
                          ('/left/other_node:\n  ros__parameters: {}\n', '/left/other_node'),
                          ('', 'has no'), ('[unclosed', 'cannot read')):
        bad = tmp_path / 'bad.yaml'
        bad.write_text(text)
        with pytest.raises(ValueError, match=re.escape(problem)):
            mechanism_namespaces(bad)


def _run_to_end(tmp_path: Path, parameters_file: Path, namespace: str, **overrides) -> Path:
    """Run the node with ``--params-file`` in ``namespace`` from ``tmp_path``; its bag."""
    output = tmp_path / 'node.log'
    arguments = ['--params-file', str(parameters_file)]
    for name, value in overrides.items():
        arguments += ['-p', f'{name}:={value}']
    if namespace:
        arguments += ['-r', f'__ns:={namespace}']
    process = start_node({}, DOMAIN_ID, output, cwd=tmp_path, ros_arguments=arguments)
    try:
        assert process.wait(timeout=PROCESS_TIMEOUT) == 0, output.read_text()
    finally:
        stop_process(process)
    (bag,) = re.findall(r'bag finalized: (\S+),', output.read_text())
    return tmp_path / bag


@pytest.mark.parametrize(('scenario', 'drive'), [
    ('constant', DriveLaw(2.0)), ('variable', DriveLaw(0.1, 2.3))])
@pytest.mark.parametrize('namespace', ['', '/lab'])
def test_each_seed_parameters_file_runs_the_node_to_its_end(
    tmp_path: Path, scenario: str, drive: DriveLaw, namespace: str
) -> None:
    bag = _run_to_end(tmp_path, SHARE / 'config' / f'seed_{scenario}.yaml', namespace)
    _, states = read_states(bag)
    assert states.alpha[0] == 0.0 and states.alpha[-1] == math.pi / 2
    assert list(states.omega) == [drive.angular_velocity(alpha) for alpha in states.alpha]


@pytest.mark.parametrize('namespace', ['/left', '/right'])
def test_each_mechanism_of_the_two_mechanisms_file_takes_its_own_entry(
    tmp_path: Path, namespace: str
) -> None:
    # Its own entry loops or bounces for ever; 'stop' after it ends the run at alpha_end.
    bag = _run_to_end(tmp_path, SHARE / 'config' / 'two_mechanisms.yaml', namespace,
                      end_behavior='stop')
    assert bag.parent == tmp_path / 'bags' / namespace.strip('/')
    with Reader(bag) as reader:
        topics = {connection.topic for connection in reader.connections}
        frames = {
            TYPESTORE.deserialize_cdr(raw, connection.msgtype).header.frame_id
            for connection, _, raw in reader.messages()
            if connection.topic == f'{namespace}/linkage/state'
        }
    assert f'{namespace}/linkage/state' in topics
    assert frames == {f"{namespace.strip('/')}/linkage_base"}
