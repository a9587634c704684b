# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""linkage-check-loops, run as a process: its printout, its problem lines and exit statuses."""

from __future__ import annotations

from importlib.metadata import entry_points
import math
from pathlib import Path
import subprocess
import sys

from loop_robots import parallelogram_mimic, ROBOTS
from test_loops_model import four_bar

COMMAND = [sys.executable, '-m', 'linkage_kinematics.cli.check_loops']
PROGRAM = 'linkage-check-loops'


def run(*args: str, stdin: str | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*COMMAND, *args], input=stdin, capture_output=True, text=True,
                          timeout=60, check=False)


def write(folder: Path, text: str) -> str:
    path = folder / 'robot.urdf'
    path.write_text(text, encoding='utf-8')
    return str(path)


def test_the_console_script_is_installed() -> None:
    scripts = {entry.name: entry.value for entry in entry_points(group='console_scripts')}
    assert scripts[PROGRAM] == 'linkage_kinematics.cli.check_loops:main'


def test_a_good_four_bar_is_described(tmp_path: Path) -> None:
    completed = run(write(tmp_path, four_bar()))
    assert completed.returncode == 0, completed.stderr
    assert completed.stderr == ''
    lines = completed.stdout.splitlines()
    # B(q) = (2 − 1.5 sin q, 1.5 cos q) from O: |OB|² = 6.25 − 6 sin q, and the rocker's dead
    # points are where |OB| is coupler ± crank
    coupler = math.hypot(2.0, 0.5)
    low, high = (math.degrees(math.asin((6.25 - (coupler + sign) ** 2) / 6.0))
                 for sign in (1.0, -1.0))
    assert lines[:5] == [
        "robot 'test_four_bar': 1 loop(s) to close",
        "constraint 'pin': four-bar",
        '  joints from the cut pin: coupler_joint (revolute, sign -1), crank_joint (revolute, '
        'sign -1), rocker_joint (revolute, sign +1)',
        '  plane normal in the world: (0, 0, 1)',
        '  link lengths (pin→coupler_joint→crank_joint→rocker_joint→pin): '
        f'{coupler:.6f} m, 1.000000 m, 2.000000 m, 1.500000 m',
    ]
    assert '  closure residual at the zero pose: 0 m (in the plane 0 m)' in lines
    rocker = lines.index('  could be known: rocker_joint')
    assert lines[rocker + 1].startswith(f'    reachable: [{low:.3f}°, {high:.3f}°], ')
    assert lines[rocker + 2].startswith(f'    dead points: {low:.3f}°, {high:.3f}°, ')
    crank = lines.index('  could be known: crank_joint')
    assert lines[crank + 1:crank + 3] == ['    reachable: a full turn', '    dead points: none']


def test_a_pin_split_in_depth_closes_in_the_plane(tmp_path: Path) -> None:
    """The pin's frame on the rocker 5 mm deeper than on the coupler: 5 mm apart, 0 in plane."""
    urdf = four_bar().replace('<child_origin xyz="0 1.5 0"/>', '<child_origin xyz="0 1.5 0.005"/>')
    completed = run(write(tmp_path, urdf))
    assert completed.returncode == 0, completed.stderr
    assert ('  closure residual at the zero pose: 0.005 m (in the plane 0 m)'
            in completed.stdout.splitlines())


def test_a_zero_pose_that_is_not_assembled_is_warned_about(tmp_path: Path) -> None:
    """The rocker's pin frame 2 cm off in the plane: the zero-pose branch may be the wrong one."""
    urdf = four_bar().replace('<child_origin xyz="0 1.5 0"/>', '<child_origin xyz="0.02 1.5 0"/>')
    completed = run(write(tmp_path, urdf))
    assert completed.returncode == 0, completed.stderr  # a warning, not a problem
    assert completed.stderr.splitlines() == [
        "linkage-check-loops: warning: constraint 'pin': the zero pose is not assembled (its "
        'pin is 0.02 m open in the plane), so the assembly branch taken there may not be the '
        "robot's; check it, and give the node loops.branches if it is not"]
    assembled = run(write(tmp_path, four_bar()))
    assert (assembled.returncode, assembled.stderr) == (0, '')


def test_standard_input_and_measured_joints(tmp_path: Path) -> None:
    completed = run('-', '--measured', 'knee_front', stdin=ROBOTS['four_bar_knee'].urdf())
    assert completed.returncode == 0, completed.stderr
    lines = completed.stdout.splitlines()
    known = lines.index('  known (measured): knee_front')
    assert lines[known + 1] == '    reachable: a full turn'
    assert lines[known + 4] == '    branch at the zero pose: +1'
    assert 'could be known' not in completed.stdout


def test_the_excavator_says_which_loop_solves_the_bucket_link(tmp_path: Path) -> None:
    robot = ROBOTS['excavator']
    completed = run(write(tmp_path, robot.urdf()), '--measured', *robot.measured_joints)
    assert completed.returncode == 0, completed.stderr
    lines = completed.stdout.splitlines()
    assert "constraint 'boom_cylinder_pin': one prismatic joint (boom_cylinder)" in lines
    assert "  known (solved by constraint 'bucket_cylinder_pin'): bucket_link_joint" in lines
    assert '  known (measured): bucket_cylinder' in lines
    # the cylinders' lines run through their pivots; the plane's normal is the pins' ±y
    assert sum(line.startswith('  slide: along ') and line.endswith(', offset 0.000000 m')
               for line in lines) == 3
    assert sum(line in ('  plane normal in the world: (0, 1, 0)',
                        '  plane normal in the world: (0, -1, 0)') for line in lines) == 4


def test_the_slider_crank_offset_is_found(tmp_path: Path) -> None:
    """loop_robots' slide line passes 2 cm below the crank pivot, tilted −0.15 rad."""
    completed = run(write(tmp_path, ROBOTS['slider_crank'].urdf()))
    assert completed.returncode == 0, completed.stderr
    assert (f'  slide: along ({math.cos(-0.15):.6g}, {math.sin(-0.15):.6g}, 0) in the world, '
            f'offset {0.02 * math.cos(0.15):.6f} m') in completed.stdout.splitlines()


def test_each_problem_is_one_line_and_exit_1(tmp_path: Path) -> None:
    urdf = four_bar(child_axis='1 0 0', extra="""
  <constraint name="pin2" type="universal">
    <parent link="crank"/><child link="rocker"/>
  </constraint>""")
    completed = run(write(tmp_path, urdf))
    assert completed.returncode == 1
    # what cannot be read first (the encodings' readers), then what cannot be closed
    assert completed.stderr.splitlines() == [
        f"{PROGRAM}: constraint 'pin2': type 'universal' is not supported: a constraint is "
        "'revolute' (a pin), 'spherical' (a ball) or 'fixed' (a weld)",
        f"{PROGRAM}: constraint 'pin': its child_axis is not parallel to the loop normal "
        '(0, 0, 1) at the zero pose (90° off): the loop is not planar',
    ]
    assert completed.stdout.splitlines() == [
        "robot 'test_four_bar': 0 loop(s) to close, 2 constraint(s) refused"]


def test_measured_joints_that_do_not_fit_are_problems(tmp_path: Path) -> None:
    completed = run(write(tmp_path, four_bar()), '--measured', 'crank_joint', 'rocker_joint',
                    'elbow')
    assert completed.returncode == 1
    assert completed.stderr.splitlines() == [
        f"{PROGRAM}: measured joint 'elbow' is not a joint of the robot",
        f"{PROGRAM}: constraint 'pin': 2 of its joints ['crank_joint', 'rocker_joint'] are known "
        '(measured or solved by another loop); exactly one must be',
    ]


def test_a_passive_mimic_joint_is_a_warning(tmp_path: Path) -> None:
    coupler_axis = '<origin xyz="0 1 0"/><axis xyz="0 0 1"/>'
    urdf = four_bar().replace(coupler_axis, coupler_axis + '<mimic joint="crank_joint"/>')
    completed = run(write(tmp_path, urdf), '--measured', 'crank_joint')
    assert completed.returncode == 0
    assert completed.stderr.splitlines() == [
        f"{PROGRAM}: warning: joint 'coupler_joint' (constraint 'pin') is solved by its loop but "
        "also mimics 'crank_joint': robot_state_publisher would pose it from two sources"]


def test_the_parsers_other_notes_are_shown_but_are_no_problem(tmp_path: Path) -> None:
    completed = run(write(tmp_path, four_bar(extra='\n  <lab_extension/>')))
    assert completed.returncode == 0
    assert completed.stderr == (f'{PROGRAM}: note: urdf_parser_py: Unknown tag "lab_extension" '
                                "in /robot[@name='test_four_bar']\n")


def test_a_urdf_without_constraints_is_fine(tmp_path: Path) -> None:
    completed = run(write(tmp_path, parallelogram_mimic()))
    assert completed.returncode == 0
    assert completed.stdout == (
        "robot 'parallelogram_mimic': no <constraint> elements, no loops to close\n")


def test_unreadable_files_and_bad_usage_exit_2(tmp_path: Path) -> None:
    missing = run(str(tmp_path / 'absent.urdf'))
    assert missing.returncode == 2
    assert missing.stderr.startswith(f'{PROGRAM}: cannot read {tmp_path / "absent.urdf"}: ')
    assert len(missing.stderr.splitlines()) == 1
    assert run().returncode == 2
    assert run('robot.urdf', '--measured').returncode == 2


def test_text_that_is_not_a_urdf_exits_1(tmp_path: Path) -> None:
    completed = run('-', stdin='<robot name="x"><link name="a"></robot>')
    assert completed.returncode == 1
    assert len(completed.stderr.splitlines()) == 1
    assert completed.stderr.startswith(f'{PROGRAM}: the URDF is not XML: ')
