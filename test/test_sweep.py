# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""linkage-sweep, run as a subprocess and in-process: CSV, tables, plot, bags and bad input."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
import subprocess
import sys

from linkage_kinematics.cli.sweep import CSV_COLUMNS, format_tables, main
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import FourBar, preset
from linkage_kinematics.kinematics.solver import continued_branch, LinkageState, solve_many
from matplotlib.colors import to_rgb
from matplotlib.image import imread
import numpy as np
import pytest
from test_bag_reader import write_bag_folder, write_mcap

REPO = Path(__file__).resolve().parents[1]
HEADER = ('alpha_deg,beta_deg,gamma_deg,omega,omega_dot,v_a,v_b,omega_ab,omega_bc,'
          'omega_dot_ab,omega_dot_bc')
PAPER = preset('paper').geometry
PNG_SIGNATURE = b'\x89PNG\r\n\x1a\n'


def run_sweep(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, '-m', 'linkage_kinematics.cli.sweep', *args],
        cwd=REPO, capture_output=True, text=True, timeout=60,
    )


def run_in_process(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    status = main(list(args))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def parse_csv(text: str) -> dict[str, np.ndarray]:
    lines = text.splitlines()
    assert lines[0] == HEADER
    rows = list(csv.reader(io.StringIO('\n'.join(lines[1:]))))
    values = np.array([[float(cell) for cell in row] for row in rows])
    return {name: values[:, index] for index, name in enumerate(CSV_COLUMNS)}


def expected_columns(state: LinkageState, alpha_deg: np.ndarray) -> dict[str, np.ndarray]:
    """
    Return the CSV's columns computed here from solve_many's state.

    As the header defines them.
    """
    return {
        'alpha_deg': alpha_deg,
        'beta_deg': np.degrees(np.unwrap(state.beta)),
        'gamma_deg': np.degrees(np.unwrap(state.gamma)),
        'omega': state.omega,
        'omega_dot': state.omega_dot,
        'v_a': np.hypot(state.velocity_a_x, state.velocity_a_y),
        'v_b': np.hypot(state.velocity_b_x, state.velocity_b_y),
        'omega_ab': state.omega_ab,
        'omega_bc': state.omega_bc,
        'omega_dot_ab': state.omega_dot_ab,
        'omega_dot_bc': state.omega_dot_bc,
    }


def assert_columns_equal(
    actual: dict[str, np.ndarray], state: LinkageState, alpha_deg: np.ndarray
) -> None:
    """``actual`` holds ``state`` computed on the crank angles ``alpha_deg`` (degrees)."""
    np.testing.assert_array_equal(np.radians(alpha_deg), state.alpha)
    for name, column in expected_columns(state, alpha_deg).items():
        np.testing.assert_array_equal(actual[name], column, err_msg=name)


def assert_four_panels_of_two_curves(image: np.ndarray) -> None:
    """Return a 1200×800 PNG whose four quadrants each hold a blue and an orange curve."""
    assert image.shape == (800, 1200, 4)
    for colour in ('tab:blue', 'tab:orange'):
        drawn = np.all(np.abs(image[:, :, :3] - to_rgb(colour)) < 0.05, axis=2)
        for rows in (slice(0, 400), slice(400, 800)):
            for columns in (slice(0, 600), slice(600, 1200)):
                assert drawn[rows, columns].sum() > 300, (colour, rows, columns)


def assert_clean_failure(
    status: int, out: str, err: str, expected_status: int, message: str
) -> None:
    assert status == expected_status, err
    assert out == ''
    assert err.startswith('linkage-sweep: error:') or '\nlinkage-sweep: error:' in err, err
    assert message in err
    assert 'Traceback' not in err


def test_default_csv_is_the_seeds_constant_omega_turn() -> None:
    result = run_sweep()
    assert result.returncode == 0, result.stderr
    assert result.stderr == ''
    columns = parse_csv(result.stdout)
    assert len(columns['alpha_deg']) == 181
    alpha_deg = np.arange(181) * 0.5
    state = solve_many(PAPER, np.radians(alpha_deg), DriveLaw(2.0))
    assert_columns_equal(columns, state, alpha_deg)
    first = {name: column[0] for name, column in columns.items()}
    last = {name: column[-1] for name, column in columns.items()}
    # The seed's Tables 1 and 2, both rows (the exact solution agrees with them at 0° and 90°).
    assert first['beta_deg'] == pytest.approx(0.0, abs=1e-9)
    assert first['gamma_deg'] == pytest.approx(16.70, abs=5e-3)
    assert (first['v_a'], first['v_b'], first['omega'], first['omega_ab']) == pytest.approx(
        (0.6, 2.0, 2.0, 2.0))
    assert first['omega_bc'] == pytest.approx(-6.6667, abs=1e-4)
    assert first['omega_dot_ab'] == pytest.approx(-57.778, abs=1e-3)
    assert first['omega_dot_bc'] == pytest.approx(192.593, abs=1e-3)
    assert (last['alpha_deg'], last['beta_deg']) == pytest.approx((90.0, 90.0))
    assert last['gamma_deg'] == pytest.approx(16.70, abs=5e-3)
    assert (last['v_a'], last['v_b'], last['omega'], last['omega_ab'], last['omega_bc']) == (
        pytest.approx((0.6, 0.18, 2.0, -0.6, -0.6)))
    assert last['omega_dot_ab'] == pytest.approx(0.0, abs=1e-12)
    assert last['omega_dot_bc'] == pytest.approx(5.2)


def test_variable_law_in_process_matches_solve_many(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, err = run_in_process(capsys, '--omega0', '0.1', '--k', '2.3')
    assert (status, err) == (0, '')
    columns = parse_csv(out)
    alpha_deg = np.arange(181) * 0.5
    state = solve_many(PAPER, np.radians(alpha_deg), DriveLaw(0.1, 2.3))
    assert_columns_equal(columns, state, alpha_deg)
    # ω = 0.1 + 2.3·π/2 at 90° (the seed's text; its Table 3 says 7.0) and α̈ = 2.3·ω exactly.
    assert columns['omega'][-1] == pytest.approx(3.7128315516)
    np.testing.assert_array_equal(columns['omega_dot'], 2.3 * columns['omega'])


def test_explicit_geometry_overrides_the_preset(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run_in_process(
        capsys, '--crank-length', '0.25', '--ground-y', '0.1', '--branch', '-1',
        '--alpha-start', '10', '--alpha-end', '20', '--alpha-step', '2.5')
    assert status == 0
    linkage = preset('paper').geometry
    modified = type(linkage)(0.25, linkage.coupler_length, linkage.rocker_length, 1.3, 0.1)
    alpha_deg = np.array([10.0, 12.5, 15.0, 17.5, 20.0])
    state = solve_many(modified, np.radians(alpha_deg), DriveLaw(2.0), branch=-1)
    assert_columns_equal(parse_csv(out), state, alpha_deg)


def test_negative_step_sweeps_clockwise(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run_in_process(capsys, '--alpha-start', '90', '--alpha-end', '0',
                                    '--alpha-step', '-0.5')
    assert status == 0
    clockwise = parse_csv(out)
    np.testing.assert_array_equal(clockwise['alpha_deg'], 90.0 - 0.5 * np.arange(181))
    status, out, _ = run_in_process(capsys)
    counterclockwise = parse_csv(out)
    for name in CSV_COLUMNS:
        np.testing.assert_array_equal(clockwise[name], counterclockwise[name][::-1], err_msg=name)


def test_clockwise_preset_sweeps_clockwise_by_default(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run_in_process(capsys, '--preset', 'paper_full_turn')
    assert status == 0
    columns = parse_csv(out)
    alpha_deg = -0.5 * np.arange(181)
    np.testing.assert_array_equal(columns['alpha_deg'], alpha_deg)
    full_turn = preset('paper_full_turn')
    state = solve_many(full_turn.geometry, np.radians(alpha_deg), DriveLaw(-2.0))
    assert_columns_equal(columns, state, alpha_deg)
    assert np.all(columns['omega'] == -2.0)


def test_end_is_included_only_when_on_the_grid(capsys: pytest.CaptureFixture[str]) -> None:
    _, out, _ = run_in_process(capsys, '--alpha-end', '1', '--alpha-step', '0.3')
    assert [line.split(',')[0] for line in out.splitlines()[1:]] == [
        '0.0', '0.3', '0.6', '0.9']
    _, out, _ = run_in_process(capsys, '--alpha-end', '1', '--alpha-step', '0.1')
    # Counted in decimal: exactly 1.0 at the end and 0.3, not 0.30000000000000004, on the way.
    assert [line.split(',')[0] for line in out.splitlines()[1:]] == [
        repr(tenths / 10) for tenths in range(11)]
    _, out, _ = run_in_process(capsys, '--alpha-start', '45', '--alpha-end', '45')
    assert parse_csv(out)['alpha_deg'].tolist() == [45.0]


def test_beta_and_gamma_are_unwrapped(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run_in_process(capsys, '--preset', 'paper_full_turn',
                                    '--alpha-end', '-210', '--alpha-step', '-1')
    assert status == 0
    columns = parse_csv(out)
    alpha_deg = -np.arange(211.0)
    state = solve_many(preset('paper_full_turn').geometry, np.radians(alpha_deg), DriveLaw(-2.0))
    assert np.max(np.abs(np.diff(state.beta))) > np.radians(300)  # β crosses ±180° here
    assert np.max(np.abs(np.diff(columns['beta_deg']))) < 10.0
    assert columns['beta_deg'][-1] == pytest.approx(185.846, abs=1e-3)  # past +180°, not wrapped
    assert_columns_equal(columns, state, alpha_deg)


def test_full_rotation_for_two_turns(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run_in_process(capsys, '--preset', 'grashof_crank_rocker',
                                    '--alpha-end', '720', '--alpha-step', '5')
    assert status == 0
    columns = parse_csv(out)
    alpha_deg = np.arange(0.0, 721.0, 5.0)
    state = solve_many(preset('grashof_crank_rocker').geometry, np.radians(alpha_deg),
                       DriveLaw(2.0))
    assert_columns_equal(columns, state, alpha_deg)
    assert columns['beta_deg'][-1] == pytest.approx(columns['beta_deg'][0], abs=1e-9)


PARALLELOGRAM_ARGS = ('--crank-length', '0.3', '--coupler-length', '1.0', '--rocker-length',
                      '0.3', '--ground-x', '1.0', '--ground-y', '0')


def test_parallelogram_turns_through_its_change_points() -> None:
    """
    Return the issue's command.

    A parallelogram turns fully, through its change points at 90° and 270°, on the smooth branch
    the start names (here the crossed one), as one process.
    """
    result = run_sweep(*PARALLELOGRAM_ARGS, '--alpha-start', '0', '--alpha-end', '360')
    assert result.returncode == 0, result.stderr
    assert result.stderr == ''
    columns = parse_csv(result.stdout)
    np.testing.assert_array_equal(columns['alpha_deg'], np.arange(0.0, 360.5, 0.5))
    linkage = FourBar(0.3, 1.0, 0.3, 1.0, 0.0)
    alpha = np.radians(columns['alpha_deg'])
    state = solve_many(linkage, alpha, DriveLaw(2.0), continued_branch(linkage, 0.0, 1, alpha))
    assert_columns_equal(columns, state, columns['alpha_deg'])
    # the crossed (anti-)parallelogram: the coupler turns back and forth, never constant
    assert np.ptp(columns['gamma_deg']) > 10.0


@pytest.mark.parametrize(('start', 'end', 'step'), [('0', '1800', '0.5'), ('0', '-1800', '-0.5')])
def test_parallelogram_stays_one_over_many_turns_both_ways(
    capsys: pytest.CaptureFixture[str], start: str, end: str, step: str
) -> None:
    status, out, err = run_in_process(capsys, *PARALLELOGRAM_ARGS, '--branch', '-1',
                                      '--alpha-start', start, '--alpha-end', end,
                                      '--alpha-step', step)
    assert status == 0, err
    columns = parse_csv(out)
    assert columns['alpha_deg'].size == 3601
    assert np.max(np.abs(columns['gamma_deg'])) <= 1e-12
    assert np.max(np.abs(columns['omega_ab'])) <= 1e-14
    np.testing.assert_allclose(columns['omega_bc'], 2.0, rtol=1e-14)
    assert np.max(np.abs(columns['omega_dot_ab'])) <= 1e-13


def test_table_shows_the_seeds_head_and_tail(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, err = run_in_process(capsys, '--table')
    assert (status, err) == (0, '')
    assert 'alpha_deg' not in out
    title, velocities, accelerations = out.split('\n\n')
    assert title.startswith("Four-bar 'paper': OA = 0.3 m, AB = 1.044 m, BC = 0.3 m")
    assert 'constant ω = 2 rad/s' in title
    caption, header, rule, *rows = velocities.splitlines()
    assert caption == 'Velocities'
    assert [cell.strip() for cell in header.split('  ') if cell.strip()] == [
        'α (°)', 'β (°)', 'γ (°)', 'V_A (m/s)', 'V_B (m/s)', 'ω (rad/s)', 'ω_AB (rad/s)',
        'ω_BC (rad/s)']
    assert set(rule) == {'-', ' '}
    assert [row.split() for row in rows] == [
        ['0.00', '0.00', '16.70', '0.6000', '2.000', '2.000', '2.000', '-6.667'],
        ['⋮'] * 8,
        ['90.00', '90.00', '16.70', '0.6000', '0.1800', '2.000', '-0.6000', '-0.6000'],
    ]
    # Right-aligned: every line of the table ends in the same column.
    assert len({len(line) for line in (header, rule, *rows)}) == 1
    caption, header, rule, *rows = accelerations.rstrip('\n').splitlines()
    assert caption == 'Accelerations'
    assert [cell.strip() for cell in header.split('  ') if cell.strip()] == [
        'α (°)', 'β (°)', 'γ (°)', 'ω̇_AB (rad/s²)', 'ω̇_BC (rad/s²)']
    assert [row.split() for row in rows] == [
        ['0.00', '0.00', '16.70', '-57.78', '192.6'],
        ['⋮'] * 5,
        ['90.00', '90.00', '16.70', '0.0000', '5.200'],
    ]


def test_format_tables_for_the_variable_law_with_more_rows() -> None:
    state = solve_many(PAPER, np.radians(np.arange(181) * 0.5), DriveLaw(0.1, 2.3))
    text = format_tables(state, rows=2, title='seed, variable law')
    assert text.startswith('seed, variable law\n\nVelocities\n')
    rows = [line.split() for line in text.split('\nAccelerations\n')[0].splitlines()[-5:]]
    assert rows == [
        ['0.00', '0.00', '16.70', '0.0300', '0.1000', '0.1000', '0.1000', '-0.3333'],
        ['0.50', '1.57', '17.17', '0.0360', '0.1074', '0.1201', '0.1073', '-0.3579'],
        ['⋮'] * 8,
        ['89.50', '89.85', '16.85', '1.108', '0.3449', '3.693', '-1.108', '-1.150'],
        ['90.00', '90.00', '16.70', '1.114', '0.3342', '3.713', '-1.114', '-1.114'],
    ]
    short = format_tables(solve_many(PAPER, np.radians([0.0, 90.0]), DriveLaw(2.0)), rows=1)
    assert '⋮' not in short
    assert [line.split()[0] for line in short.splitlines() if line[-1:].isdigit()] == [
        '0.00', '90.00', '0.00', '90.00']


def test_plot_writes_a_png_and_nothing_on_stdout(tmp_path: Path) -> None:
    target = tmp_path / 'figure.png'
    result = run_sweep('--omega0', '0.1', '--k', '2.3', '--plot', str(target))
    assert result.returncode == 0, result.stderr
    assert (result.stdout, result.stderr) == ('', '')
    assert target.read_bytes()[:8] == PNG_SIGNATURE
    assert_four_panels_of_two_curves(imread(target))


def test_plot_with_table_prints_the_tables(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / 'figure.png'
    status, out, _ = run_in_process(capsys, '--plot', str(target), '--table')
    assert status == 0
    assert out.startswith("Four-bar 'paper'") and '-57.78' in out
    assert_four_panels_of_two_curves(imread(target))


def test_unreachable_range_writes_nothing() -> None:
    result = run_sweep('--alpha-end', '200', '--plot', 'never.png')
    assert_clean_failure(result.returncode, result.stdout, result.stderr, 2,
                         'is not reachable: the loop closes only for α in [-1.941°, 181.941°]')
    assert not (REPO / 'never.png').exists()


def test_dead_point_writes_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    dead_point = repr(math.degrees(PAPER.reachability.dead_points[0]))
    target = tmp_path / 'dead.png'
    status, out, err = run_in_process(capsys, '--alpha-start', dead_point, '--alpha-end',
                                      dead_point, '--plot', str(target), '--table')
    assert_clean_failure(status, out, err, 2, 'is at a dead point')
    assert not target.exists()


@pytest.mark.parametrize(
    ('args', 'message'),
    [
        (['--alpha-step', '0'], '--alpha-step must not be zero'),
        (['--alpha-step', '-1', '--alpha-end', '10'], 'a step of -1° never gets from 0° to 10°'),
        (['--alpha-step', '1e-9'], 'would give more than 1000000 rows'),
        (['--omega0', 'nan'], "argument --omega0: must be a finite number, got 'nan'"),
        (['--k', 'inf'], "argument --k: must be a finite number, got 'inf'"),
        (['--alpha-end', 'ninety'], "argument --alpha-end: not a number: 'ninety'"),
        (['--crank-length', '0'], "argument --crank-length: must be a length > 0 m, got '0'"),
        (['--rocker-length', '-0.3'], "must be a length > 0 m, got '-0.3'"),
        (['--ground-x', '10'], 'the loop cannot close at any crank angle'),
        (['--preset', 'moon'], "argument --preset: invalid choice: 'moon'"),
        (['--branch', '2'], 'argument --branch: invalid choice: 2'),
        (['--plot', 'figure.pdf'], "give a file name ending in .png, got 'figure.pdf'"),
        (['--table', '--rows', '0'], 'argument --rows: must be at least 1'),
        (['--from-bag', 'x', '--k', '1', '--preset', 'paper'],
         '--from-bag takes the states from the bag; drop --preset, --k'),
        (['--sideways'], 'unrecognized arguments: --sideways'),
    ],
)
def test_bad_arguments(capsys: pytest.CaptureFixture[str], args: list[str], message: str) -> None:
    status, out, err = run_in_process(capsys, *args)
    assert_clean_failure(status, out, err, 2, message)


def test_unwritable_plot_path(tmp_path: Path) -> None:
    target = tmp_path / 'missing_folder' / 'figure.png'
    result = run_sweep('--plot', str(target))
    assert_clean_failure(result.returncode, result.stdout, result.stderr, 1,
                         f'cannot write the plot {target}: No such file or directory')
    assert not target.parent.exists()


def test_from_bag_gives_the_same_csv_as_computing(tmp_path: Path) -> None:
    alpha_deg = np.arange(91.0)
    state = solve_many(PAPER, np.radians(alpha_deg), DriveLaw(0.1, 2.3))
    write_bag_folder(tmp_path / 'bag', state)
    from_bag = run_sweep('--from-bag', str(tmp_path / 'bag'))
    assert from_bag.returncode == 0, from_bag.stderr
    computed = run_sweep('--omega0', '0.1', '--k', '2.3', '--alpha-step', '1')
    logged_columns = parse_csv(from_bag.stdout)
    computed_columns = parse_csv(computed.stdout)
    for name in CSV_COLUMNS[1:]:
        np.testing.assert_array_equal(logged_columns[name], computed_columns[name], err_msg=name)
    # The bag holds α in rad; the computed sweep shows its degree grid as given.
    np.testing.assert_array_equal(computed_columns['alpha_deg'], alpha_deg)
    np.testing.assert_allclose(logged_columns['alpha_deg'], alpha_deg, rtol=1e-15, atol=0)
    np.testing.assert_array_equal(logged_columns['alpha_deg'], np.degrees(state.alpha))


def test_from_bag_table_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    state = solve_many(PAPER, np.radians(np.arange(0.0, 90.5, 0.5)), DriveLaw(2.0))
    write_bag_folder(tmp_path / 'bag', state)
    target = tmp_path / 'logged.png'
    status, out, err = run_in_process(capsys, '--from-bag', str(tmp_path / 'bag'), '--table',
                                      '--plot', str(target))
    assert (status, err) == (0, '')
    assert out == format_tables(state, title=f"Logged run {tmp_path / 'bag'}")
    assert_four_panels_of_two_curves(imread(target))


def test_from_truncated_bag_uses_the_complete_part(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    state = solve_many(PAPER, np.radians(np.arange(91.0)), DriveLaw(2.0))
    whole = tmp_path / 'whole.mcap'
    write_mcap(whole, state, chunk_size=2000)
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(whole.read_bytes()[: whole.stat().st_size // 2])
    status, out, err = run_in_process(capsys, '--from-bag', str(cut))
    assert status == 0
    assert 'linkage-sweep: note:' in err and 'ends without its footer' in err
    columns = parse_csv(out)
    count = len(columns['alpha_deg'])
    assert 10 < count < 91
    np.testing.assert_array_equal(columns['alpha_deg'], np.degrees(state.alpha[:count]))


def test_from_bag_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    not_mcap = tmp_path / 'table.csv'
    not_mcap.write_text('alpha_deg\n0\n')
    foreign_only = tmp_path / 'foreign.mcap'
    write_mcap(foreign_only, None, foreign=True)
    for bag, message in (
        (tmp_path / 'absent', 'no bag at'),
        (not_mcap, 'is not an MCAP file'),
        (foreign_only, 'holds no /linkage/state messages (topics present: /chatter)'),
    ):
        target = tmp_path / 'never.png'
        status, out, err = run_in_process(capsys, '--from-bag', str(bag), '--plot', str(target))
        assert_clean_failure(status, out, err, 1, message)
        assert not target.exists()


def test_help_documents_outputs_and_exit_status() -> None:
    result = run_sweep('--help')
    assert result.returncode == 0
    assert HEADER in result.stdout
    assert 'exit status:' in result.stdout and '--from-bag' in result.stdout
