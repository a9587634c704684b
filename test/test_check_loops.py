# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage-check-loops, run as a process: its printout, its problem lines and exit statuses.

With ``--outputs``, each group's transmission: the lines ``loops.transmission_range`` gives for
the same group planned independently (test/transmission_robots.py), within the URDF's limits.
"""

from __future__ import annotations

from importlib.metadata import entry_points
import math
from pathlib import Path
import re
import subprocess
import sys

from linkage_kinematics.loops.command import CommandRefusal
from linkage_kinematics.loops.transmission_range import advantage_range
from loop_robots import excavator, parallelogram_mimic, ROBOTS
from test_loops_model import four_bar
import transmission_robots

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


def test_text_that_is_not_a_urdf_is_unreadable_input_and_exits_2(tmp_path: Path) -> None:
    completed = run('-', stdin='<robot name="x"><link name="a"></robot>')
    assert completed.returncode == 2
    assert len(completed.stderr.splitlines()) == 1
    assert completed.stderr.startswith(f'{PROGRAM}: the URDF is not XML: ')


# --- closure groups of the general closure -----------------------------------------------------

ANKLE = Path(__file__).resolve().parent.parent / 'urdf' / 'humanoid_ankle.urdf'
MODELS = Path(__file__).resolve().parent / 'models' / 'example_parallel_robots'


def test_the_humanoid_ankle_is_one_group_of_two_balls_solved_from_its_motors() -> None:
    completed = run(str(ANKLE), '--measured', 'motor_left', 'motor_right')
    assert (completed.returncode, completed.stderr) == (0, '')
    lines = completed.stdout.splitlines()
    assert lines[:8] == [
        "robot 'humanoid_ankle': 2 loop(s) to close",
        "group 'ball_left+ball_right': 2 balls, 2 degree(s) of freedom (0 idle)",
        "  closure 'ball_left' (ball, <constraint>): rod_left at (0, 0, -0.23) with foot at "
        '(-0.065, 0.035, 0.02)',
        "  closure 'ball_right' (ball, <constraint>): rod_right at (0, 0, -0.23) with foot at "
        '(-0.065, -0.035, 0.02)',
        '  joints: ankle_pitch, ankle_roll, motor_left, motor_right, rod_left_u1, rod_left_u2, '
        'rod_right_u1, rod_right_u2',
        '  known (measured): motor_left, motor_right',
        '  solved: ankle_pitch, ankle_roll, rod_left_u1, rod_left_u2, rod_right_u1, rod_right_u2',
        '  solved by: Newton on the closure equations with their exact Jacobian, to rounding']
    # drawn assembled: the zero pose is the assembly, its residuals rounding
    assert lines[9] == ('  assembled nearest the zero pose (from the zero pose): ankle_pitch '
                        '0.000°, ankle_roll 0.000°, motor_left 0.000°, motor_right 0.000°, '
                        'rod_left_u1 0.000°, rod_left_u2 0.000°, rod_right_u1 0.000°, '
                        'rod_right_u2 0.000°')
    for line in (lines[8], lines[10]):
        assert max(float(gap) for gap in re.findall(r'ball_\w+ ([^ ]+) m', line)) < 1e-16
    assert re.fullmatch(r'  conditioning at the assembled pose: \d\.\d+ \(orientation [+-]1\)',
                        lines[11])
    assert lines[13:] == [
        '  idle freedoms: none',
        '  overridden joints: none',
        '  reachable from the assembly, each known joint with the other known joint held at its '
        'assembled value (continued until refused):',
        '    motor_left: a full turn',
        '    motor_right: a full turn']


def test_a_closure_file_names_the_known_joints_and_its_overrides_are_warned_about() -> None:
    model = MODELS / 'battobot_6d'
    completed = run(str(model / 'robot.urdf'), '--closures', str(model / 'robot.yaml'))
    assert completed.returncode == 0, completed.stderr
    lines = completed.stdout.splitlines()
    knee = lines.index("group 'closedloop_knee_left_ACclosedloop_knee_left_B': 1 weld, 1 "
                       'degree(s) of freedom (0 idle)')
    assert lines[knee + 3] == '  known (measured): motor_knee_left'
    assert ('  overridden joints: free_knee_left (UJOINT_YZ: free_knee_left_Y, free_knee_left_Z,'
            ' solved, not published); transmission_knee_left (SPHERICAL: '
            'transmission_knee_left_X, transmission_knee_left_Y, transmission_knee_left_Z, '
            'solved, not published)') in lines
    warnings = [line for line in completed.stderr.splitlines() if ': warning: ' in line]
    assert len(warnings) == 12
    assert (f"{PROGRAM}: warning: joint 'free_knee_left' is read as UJOINT_YZ by the closure "
            'file: its coordinates free_knee_left_Y, free_knee_left_Z are solved but not '
            'published (they are no URDF joints), so robot_state_publisher cannot pose link '
            "'knee_assembly_6d_2_2' and the links below it; model it in the URDF as 2 revolute "
            'joints to publish them') in warnings


def test_a_five_bars_reach_ends_where_its_distal_links_stretch() -> None:
    model = MODELS / '5bar_linkage'
    completed = run(str(model / 'robot.urdf'), '--closures', str(model / 'robot.yaml'))
    assert completed.returncode == 0, completed.stderr
    lines = completed.stdout.splitlines()
    assert ('  idle freedoms: closedloop1_A, closedloop1_B (each held at its assembled value)'
            in lines)
    (mot1,) = [line for line in lines if line.startswith('    mot1: ')]
    low, high = (float(value) for value in re.findall(r'(-?\d+\.\d+)°', mot1))
    assert low < -90.0 < 90.0 < high
    # at both ends the known joint's next hair is out of reach, the mechanism stretched
    assert mot1.count('no assembly reaches further (conditioning ') == 2
    conditioning = [float(value) for value in re.findall(r'conditioning ([^ ]+) there', mot1)]
    assert min(conditioning) > 1e4


def test_groups_that_do_not_close_are_one_line_each_and_exit_1() -> None:
    model = MODELS / 'kangaroo_like'
    completed = run(str(model / 'robot.urdf'), '--closures', str(model / 'robot.yaml'))
    assert completed.returncode == 1
    problems = [line for line in completed.stderr.splitlines() if ': note: ' not in line]
    assert len(problems) == 1
    assert problems[0].startswith(f'{PROGRAM}: group closedloop0_BCclosedloop0_A+')
    assert problems[0].endswith(' in 25 tries: it cannot be assembled as given')
    # without measured joints a group is described, not refused for lack of them
    disney = MODELS / 'disney_like'
    text = (disney / 'robot.yaml').read_text().replace('name_mot', 'name_mot_unused')
    described = run(str(disney / 'robot.urdf'), '--closures', '-', stdin=text)
    assert described.returncode == 1  # the closure file's unknown key, and only that
    assert [line for line in described.stderr.splitlines() if ': note: ' not in line] == [
        f"{PROGRAM}: 'name_mot_unused': not a key of a closure file (closed_loop, type, "
        'name_mot, joint_name, joint_type)']
    assert "  known: none given (8 needed: --measured, or the closure file's name_mot)" in (
        described.stdout.splitlines())


def test_an_unreadable_closure_file_exits_2(tmp_path: Path) -> None:
    missing = run(str(ANKLE), '--closures', str(tmp_path / 'absent.yaml'))
    assert missing.returncode == 2
    assert missing.stderr.startswith(f'{PROGRAM}: cannot read {tmp_path / "absent.yaml"}: ')
    not_yaml = run(str(ANKLE), '--closures', '-', stdin='closed_loop: [a')
    assert not_yaml.returncode == 2
    assert not_yaml.stderr.startswith(f'{PROGRAM}: the closure file is not YAML: ')
    assert len(not_yaml.stderr.splitlines()) == 1
    assert run(str(ANKLE), '--assemblies', 'ankle_pitch').returncode == 2


def test_an_assembly_seed_picks_the_other_assembly(tmp_path: Path) -> None:
    model = MODELS / '5bar_linkage'
    urdf, closures = str(model / 'robot.urdf'), str(model / 'robot.yaml')

    def assembled(*extra: str) -> str:
        completed = run(urdf, '--closures', closures, *extra)
        assert completed.returncode == 0, completed.stderr
        (line,) = [line for line in completed.stdout.splitlines()
                   if line.startswith('  assembled nearest the zero pose')]
        return line

    drawn = assembled()
    free1 = float(re.search(r'free1 (-?\d+\.\d+)°', drawn).group(1))
    seeded = assembled('--assemblies', f'free1={-math.radians(free1) * 3:.6f}')
    assert ', seeded free1 = ' in seeded
    assert abs(float(re.search(r'free1 (-?\d+\.\d+)°', seeded).group(1)) - free1) > 1.0


# --- transmissions: --outputs ------------------------------------------------------------------

EXCAVATOR = Path(__file__).resolve().parent.parent / 'urdf' / 'excavator.urdf'
CYLINDERS = ('boom_cylinder', 'stick_cylinder', 'bucket_cylinder')
BOOM_STICK_BUCKET = ('boom_joint', 'stick_joint', 'bucket_joint')


def test_the_excavator_file_is_the_test_robots() -> None:
    """urdf/excavator.urdf is test/loop_robots.py's excavator with a comment at its head."""
    text = EXCAVATOR.read_text(encoding='utf-8')
    assert re.sub(r'<!--.*?-->\n', '', text, flags=re.DOTALL) == excavator()


def transmissions(stdout: str) -> dict[str, list[str]]:
    """Return the printout's transmissions: each group's lines, its head line first."""
    found: dict[str, list[str]] = {}
    group = None
    for line in stdout.splitlines():
        head = re.match(r"transmission of group '([^']+)': ", line)
        if head:
            group = head.group(1)
            found[group] = [line]
        elif group is not None and line.startswith('  '):
            found[group].append(line)
        else:
            group = None
    return found


def test_each_groups_transmission_ratio_over_its_reach_within_the_cylinders_strokes() -> None:
    completed = run(str(EXCAVATOR), '--measured', *CYLINDERS, '--outputs', *BOOM_STICK_BUCKET)
    assert (completed.returncode, completed.stderr) == (0, '')
    found = transmissions(completed.stdout)
    robot = transmission_robots.build('excavator')
    assert list(found) == [transmission.name for transmission in robot.transmissions]
    for transmission, planned, command in zip(robot.transmissions, robot.planned,
                                              robot.commands):
        lines = found[transmission.name]
        (actuator,), (output,) = transmission.actuators, transmission.outputs
        assert lines[0] == (f"transmission of group '{transmission.name}': output joints "
                            f'{output}; actuators {actuator}')
        values = planned.assembly.values
        index = robot.tree.index
        now = transmission.advantage([values[index[actuator]]],
                                     [values[index[name]] for name in transmission.solved])
        assert lines[1] == f'  at the assembled pose: {now.describe()}'
        swept = advantage_range(command)
        assert lines[2:] == swept.describe()
        # every end of the boom's and stick's reach is where the cylinder's stroke ends, which
        # is where commands stop (the bucket's low end: its linkage's singular configuration)
        (sweep,) = swept.sweeps
        assert sweep.high_end == CommandRefusal.LIMIT.value
        assert f'{output}: [' in lines[3] and 'its URDF <limit>' in lines[3]
        low, high = swept.ratio
        assert low <= now.ratio[0][0] <= high


def test_the_ankles_ratio_is_swept_in_slices_within_its_limits() -> None:
    completed = run(str(ANKLE), '--measured', 'motor_left', 'motor_right', '--outputs',
                    'ankle_pitch', 'ankle_roll')
    assert (completed.returncode, completed.stderr) == (0, '')
    lines = transmissions(completed.stdout)['ball_left+ball_right']
    assert lines[0] == ("transmission of group 'ball_left+ball_right': output joints "
                        'ankle_pitch, ankle_roll; actuators motor_left, motor_right')
    assert lines[1].startswith('  at the assembled pose: singular values of '
                               'd(actuators)/d(outputs) ')
    assert lines[2].startswith("  output joints ['ankle_pitch', 'ankle_roll'] -> actuators "
                               "['motor_left', 'motor_right'] (slices: ")
    # pitch up to its URDF limit, down to where a motor would leave its own; roll to its limits
    assert lines[3].startswith('    ankle_pitch: [')
    assert lines[3].endswith(', 0.5] (low end: an actuator would leave its URDF <limit>; high '
                             'end: its URDF <limit>)')
    assert lines[4].startswith('    ankle_roll: [-0.35, 0.35] ')
    smallest, largest = (float(value) for value in re.findall(
        r'from ([^ ]+) \(at .*\) to ([^ ]+)$', lines[5])[0])
    assert 0.5 < smallest < largest < 10.0
    assert lines[6].startswith('    actuator effort per unit output effort, at worst: '
                               'motor_left ')


def test_output_joints_that_are_no_groups_are_one_line_and_exit_1() -> None:
    completed = run(str(EXCAVATOR), '--measured', *CYLINDERS, '--outputs', 'boom_cylinder',
                    'tooth')
    assert completed.returncode == 1
    assert completed.stderr.splitlines() == [
        f"{PROGRAM}: --outputs: output joint 'tooth' is not a joint of the robot; group "
        "boom_cylinder_pin: output joints ['boom_cylinder']: ['boom_cylinder'] are measured; an "
        "output joint is one the actuators ['boom_cylinder'] move"]
    assert 'transmission of group' not in completed.stdout
    unmeasured = run(str(EXCAVATOR), '--outputs', 'boom_joint')
    assert unmeasured.returncode == 1
    assert unmeasured.stderr.splitlines() == [
        f'{PROGRAM}: --outputs: the output joints are those of closure groups the measured '
        "joints close (--measured, or the closure file's name_mot)"]
