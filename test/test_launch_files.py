# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The launch files and their parameters files.

Tested without `launch` (not installable here): the launch arguments read from each launch
description (the Python files' DeclareLaunchArgument calls, the XML's <arg> elements) and where
they go, what they name exists in the installed share/ and entry points, they use only launch API
that every Jazzy release has (launch 3.4.0 on), and each parameters file starts the node to its
end with ``--params-file``, in the namespaces it is meant for.
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
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.run.configuration import mechanism_entries
from linkage_kinematics.run.parameter_specs import PARAMETER_NAMES
from node_process import NodeProcesses, PROCESS_TIMEOUT, REPOSITORY
import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores

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
    'linkage_kinematics.run.configuration': {'NODE_NAME', 'mechanism_entries'},
}
# The arguments of robot_state_publisher's and nav2's launch files, and the bag log's: each launch
# file declares them and passes each to the node parameter named here (None: not a parameter).
COMMON_ARGUMENTS = {
    'namespace': None, 'use_sim_time': 'use_sim_time', 'params_file': None,
    'autostart': 'autostart', 'log_enabled': 'log.enabled', 'log_folder': 'log.folder',
    'log_level': None,
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


def _declared_arguments(tree: ast.AST) -> dict[str, dict[str, ast.expr]]:
    """Return the DeclareLaunchArgument calls of a Python launch file: name → keywords."""
    return {ast.literal_eval(call.args[0]): {word.arg: word.value for word in call.keywords}
            for call in _calls(tree, 'DeclareLaunchArgument')}


def _calls(tree: ast.AST, function: str) -> list[ast.Call]:
    """Return the calls of ``function`` (by its plain name) in a Python launch file."""
    return [node for node in ast.walk(tree)
            if isinstance(node, ast.Call) and getattr(node.func, 'id', None) == function]


def _configurations(tree: ast.AST) -> dict[int, str]:
    """Return the LaunchConfiguration('name') calls of a Python launch file: id → name."""
    return {id(node): ast.literal_eval(node.args[0])
            for node in _calls(tree, 'LaunchConfiguration')}


def _node_parameters(tree: ast.AST) -> dict[str, str]:
    """Return the parameters a Python launch file sets from its arguments: parameter → argument."""
    names = _configurations(tree)
    pairs = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):  # {'parameter': LaunchConfiguration('argument'), …}
            pairs += zip(node.keys, node.values)
        elif isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Subscript):
            pairs.append((node.targets[0].slice, node.value))  # parameters['…'] = …
    return {ast.literal_eval(key): names[id(value)] for key, value in pairs if id(value) in names}


@pytest.mark.parametrize('name', PYTHON_LAUNCH_FILES)
def test_each_launch_file_declares_the_common_arguments_and_passes_them_on(name: str) -> None:
    tree = ast.parse((SHARE / 'launch' / name).read_text())
    arguments = _declared_arguments(tree)
    assert set(COMMON_ARGUMENTS) <= set(arguments), sorted(arguments)
    for argument, keywords in arguments.items():
        assert ast.literal_eval(keywords['description']).strip(), argument
        # Every argument is read somewhere (beyond its own declaration).
        assert argument in _configurations(tree).values(), argument
    assert ast.literal_eval(arguments['use_sim_time']['default_value']) == 'false'
    assert ast.literal_eval(arguments['autostart']['default_value']) == 'true'
    assert ast.literal_eval(arguments['namespace']['default_value']) == ''
    parameters = _node_parameters(tree)
    assert parameters == {parameter: argument for argument, parameter in COMMON_ARGUMENTS.items()
                          if parameter is not None}
    assert set(parameters) <= {*PARAMETER_NAMES, 'use_sim_time'}
    node = next(node for node in ast.walk(tree) if isinstance(node, ast.Call)
                and getattr(node.func, 'id', None) == 'Node')
    keywords = {keyword.arg: keyword.value for keyword in node.keywords}
    assert ast.dump(keywords['ros_arguments'].elts[0]) == ast.dump(ast.Constant('--log-level'))
    assert _configurations(keywords['ros_arguments']).popitem()[1] == 'log_level'


def test_the_xml_twin_declares_the_python_files_arguments_and_sets_the_same_parameters() -> None:
    python = ast.parse((SHARE / 'launch' / 'linkage.launch.py').read_text())
    python_arguments = _declared_arguments(python)
    xml = ElementTree.parse(SHARE / 'launch' / 'linkage.launch.xml').getroot()
    xml_arguments = {argument.get('name'): argument for argument in xml.iter('arg')}
    assert list(xml_arguments) == list(python_arguments)
    for name, argument in xml_arguments.items():
        if name != 'params_file':
            assert argument.get('default') == ast.literal_eval(
                python_arguments[name]['default_value']), name
        assert argument.get('description') == ast.literal_eval(
            python_arguments[name]['description']), name
    (node,) = xml.iter('node')
    assert (node.get('pkg'), node.get('exec'), node.get('namespace'), node.get('ros_args')) == (
        'linkage_kinematics', 'linkage_node', '$(var namespace)', '--log-level $(var log_level)')
    (from_file, *values) = node.iter('param')
    assert from_file.get('from') == '$(var params_file)'
    assert {param.get('name'): param.get('value') for param in values} == {
        parameter: f'$(var {argument})' for parameter, argument in _node_parameters(python).items()
    }


def test_the_scenario_picks_an_existing_parameters_file_in_both_twins() -> None:
    python_tree = ast.parse((SHARE / 'launch' / 'linkage.launch.py').read_text())
    arguments = _declared_arguments(python_tree)
    choices = ast.literal_eval(arguments['scenario']['choices'])
    assert ast.literal_eval(arguments['scenario']['default_value']) in choices
    for scenario in choices:
        assert (SHARE / 'config' / f'seed_{scenario}.yaml').is_file()
    # params_file defaults to <share>/config/seed_ + the scenario + .yaml.
    (folder, scenario_name, suffix) = arguments['params_file']['default_value'].elts
    assert ast.dump(folder) == ast.dump(ast.parse("os.path.join(config, 'seed_')").body[0].value)
    assert _configurations(scenario_name).popitem()[1] == 'scenario'
    assert ast.literal_eval(suffix) == '.yaml'

    xml = ElementTree.parse(SHARE / 'launch' / 'linkage.launch.xml').getroot()
    xml_arguments = {argument.get('name'): argument for argument in xml.iter('arg')}
    # A misspelt scenario fails at launch, as in the Python file, instead of running defaults.
    assert [choice.get('value') for choice in xml_arguments['scenario'].iter('choice')] == choices
    default_file = xml_arguments['params_file'].get('default')
    assert not re.search(r'\$\((?!find-pkg-share |var )', default_file)
    for scenario in choices:
        path = default_file.replace('$(find-pkg-share linkage_kinematics)', str(SHARE)).replace(
            '$(var scenario)', scenario)
        assert Path(path) == SHARE / 'config' / f'seed_{scenario}.yaml'


def test_mechanism_entries_come_from_the_parameters_file(tmp_path: Path) -> None:
    entries = mechanism_entries(SHARE / 'config' / 'two_mechanisms.yaml')
    assert list(entries) == ['/left', '/right']
    assert (entries['/left']['frame_prefix'], entries['/right']['log.folder']) == (
        'left/', 'bags/right')
    for text, problem in (('/**/linkage_node:\n  ros__parameters: {}\n', '/**/linkage_node'),
                          ('/left/other_node:\n  ros__parameters: {}\n', '/left/other_node'),
                          ('/left/linkage_node:\n  gain: 1\n', 'no ros__parameters'),
                          ('', 'has no'), ('[unclosed', 'cannot read')):
        bad = tmp_path / 'bad.yaml'
        bad.write_text(text)
        with pytest.raises(ValueError, match=re.escape(problem)):
            mechanism_entries(bad)


def _run_to_end(
    nodes: NodeProcesses, tmp_path: Path, parameters_file: Path, namespace: str, **overrides
) -> Path:
    """Run the node with ``--params-file`` in ``namespace`` from ``tmp_path``; its bag."""
    output = tmp_path / 'node.log'
    arguments = ['--params-file', str(parameters_file)]
    for name, value in overrides.items():
        arguments += ['-p', f'{name}:={value}']
    if namespace:
        arguments += ['-r', f'__ns:={namespace}']
    process = nodes.start({}, output, cwd=tmp_path, ros_arguments=arguments)
    assert process.wait(timeout=PROCESS_TIMEOUT) == 0, output.read_text()
    (bag,) = re.findall(r'bag finalized: (\S+),', output.read_text())
    return tmp_path / bag


@pytest.mark.parametrize(('scenario', 'drive'), [
    ('constant', DriveLaw(2.0)), ('variable', DriveLaw(0.1, 2.3))])
@pytest.mark.parametrize('namespace', ['', '/lab'])
def test_each_seed_parameters_file_runs_the_node_to_its_end(
    nodes: NodeProcesses, tmp_path: Path, scenario: str, drive: DriveLaw, namespace: str
) -> None:
    bag = _run_to_end(nodes, tmp_path, SHARE / 'config' / f'seed_{scenario}.yaml', namespace)
    _, states = read_states(bag)
    assert states.alpha[0] == 0.0 and states.alpha[-1] == math.pi / 2
    assert list(states.omega) == [drive.angular_velocity(alpha) for alpha in states.alpha]


@pytest.mark.parametrize('namespace', ['/left', '/right'])
def test_each_mechanism_of_the_two_mechanisms_file_takes_its_own_entry(
    nodes: NodeProcesses, tmp_path: Path, namespace: str
) -> None:
    # Its own entry loops or bounces for ever; 'stop' after it ends the run at alpha_end.
    bag = _run_to_end(nodes, tmp_path, SHARE / 'config' / 'two_mechanisms.yaml', namespace,
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
