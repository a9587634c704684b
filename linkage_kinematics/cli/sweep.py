# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``linkage-sweep``.

The seed's tables and figures for any crank-angle range, or for a logged run.

States come from ``kinematics.solve_many`` (or, with ``--from-bag``, from a run the node logged);
this module only lays them out: a lossless CSV, the seed's head-and-tail tables
(``format_tables``) and its four-panel figure (``write_plot``).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import dataclasses
from decimal import Decimal, ROUND_FLOOR
import io
import math
import os
from pathlib import Path
import sys
from typing import Optional, TextIO
import unicodedata

from linkage_kinematics.bag.errors import BagError
from linkage_kinematics.bag.reader import bag_files, read_states
from linkage_kinematics.cli.arguments import number
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import (
    DIMENSIONS,
    FourBar,
    GeometryError,
    preset,
    PRESETS,
    UnreachableError,
)
from linkage_kinematics.kinematics.solver import (
    continued_branch,
    DeadPointError,
    LinkageState,
    solve_many,
)
import numpy as np

PROGRAM = 'linkage-sweep'
CSV_COLUMNS = (
    'alpha_deg', 'beta_deg', 'gamma_deg', 'omega', 'omega_dot', 'v_a', 'v_b',
    'omega_ab', 'omega_bc', 'omega_dot_ab', 'omega_dot_bc',
)
# The seed's step and turn; the default sweep runs this far in the drive's direction.
DEFAULT_STEP_DEG = 0.5
DEFAULT_TURN_DEG = 90.0
DEFAULT_OMEGA0 = 2.0
# A sweep this long is already about 200 MB of CSV; more is almost surely a mistyped step.
MAX_ROWS = 1_000_000
_ANGLE_COLUMNS = (('α (°)', 'alpha_deg'), ('β (°)', 'beta_deg'), ('γ (°)', 'gamma_deg'))
_VELOCITY_COLUMNS = _ANGLE_COLUMNS + (
    ('V_A (m/s)', 'v_a'),
    ('V_B (m/s)', 'v_b'),
    ('ω (rad/s)', 'omega'),
    ('ω_AB (rad/s)', 'omega_ab'),
    ('ω_BC (rad/s)', 'omega_bc'),
)
_ACCELERATION_COLUMNS = _ANGLE_COLUMNS + (
    ('ω̇_AB (rad/s²)', 'omega_dot_ab'),
    ('ω̇_BC (rad/s²)', 'omega_dot_bc'),
)


class SweepRangeError(ValueError):
    """The crank-angle range options do not describe a sweep."""


def crank_angles(start_deg: float, end_deg: float, step_deg: float) -> np.ndarray:
    """
    Crank angles in degrees from ``start_deg`` by ``step_deg`` up to ``end_deg``.

    The end is included when it lands on the grid; a negative step sweeps clockwise. The grid
    is counted in decimal, as the numbers were typed, so 0 to 1 by 0.1 ends on 1 and its fourth
    angle is 0.3, not 0.30000000000000004.
    """
    if step_deg == 0.0:
        raise SweepRangeError('--alpha-step must not be zero')
    span = end_deg - start_deg
    if span != 0.0 and (span > 0.0) != (step_deg > 0.0):
        raise SweepRangeError(
            f'a step of {step_deg:g}° never gets from {start_deg:g}° to {end_deg:g}°; '
            'use a step of the other sign'
        )
    if not span / step_deg < MAX_ROWS:
        raise SweepRangeError(
            f'{start_deg:g}° to {end_deg:g}° by {step_deg:g}° would give more than {MAX_ROWS} '
            'rows; use a larger --alpha-step'
        )
    # repr gives the shortest decimal that reads back as the same float: what was typed.
    start, end, step = (Decimal(repr(value)) for value in (start_deg, end_deg, step_deg))
    count = int(((end - start) / step).to_integral_value(rounding=ROUND_FLOOR)) + 1
    return np.array([float(start + step * index) for index in range(count)])


def seed_columns(
    state: LinkageState, alpha_deg: Optional[np.ndarray] = None
) -> dict[str, np.ndarray]:
    """
    Return the CSV columns (``CSV_COLUMNS``) of an array state: SI units, angles in degrees.

    β and γ are unwrapped along the rows so they are continuous. ``alpha_deg``, when given, is
    the grid the state was computed on (``state.alpha`` is its radians): it is shown as given,
    since converting back to degrees would turn 1.5 into 1.5000000000000002.
    """
    return {
        'alpha_deg': np.degrees(state.alpha) if alpha_deg is None else np.asarray(alpha_deg),
        'beta_deg': np.degrees(np.unwrap(state.beta)),
        'gamma_deg': np.degrees(np.unwrap(state.gamma)),
        'omega': np.asarray(state.omega),
        'omega_dot': np.asarray(state.omega_dot),
        'v_a': np.asarray(state.v_a),
        'v_b': np.asarray(state.v_b),
        'omega_ab': np.asarray(state.omega_ab),
        'omega_bc': np.asarray(state.omega_bc),
        'omega_dot_ab': np.asarray(state.omega_dot_ab),
        'omega_dot_bc': np.asarray(state.omega_dot_bc),
    }


def write_csv(
    state: LinkageState, stream: TextIO, alpha_deg: Optional[np.ndarray] = None
) -> None:
    """
    Return the states as CSV with header ``CSV_COLUMNS``; repr floats, so the text is lossless.

    ``alpha_deg`` as in ``seed_columns``.
    """
    columns = seed_columns(state, alpha_deg)
    stream.write(','.join(CSV_COLUMNS) + '\n')
    rows = zip(*(columns[name].tolist() for name in CSV_COLUMNS))
    stream.writelines(','.join(map(repr, row)) + '\n' for row in rows)


def describe_mechanism(linkage: FourBar, name: Optional[str] = None) -> str:
    """One line naming the mechanism and its dimensions, for titles."""
    dimensions = (
        f'OA = {linkage.crank_length:.4g} m, AB = {linkage.coupler_length:.4g} m, '
        f'BC = {linkage.rocker_length:.4g} m, C = ({linkage.ground_x:.4g}, '
        f'{linkage.ground_y:.4g}) m'
    )
    return f'{name}: {dimensions}' if name else dimensions


def describe_drive(drive: DriveLaw) -> str:
    """Return the drive law in words, for titles."""
    if drive.k == 0.0:
        return f'constant ω = {drive.omega0:g} rad/s'
    sign = '+' if drive.k > 0.0 else '−'
    return f'ω = {drive.omega0:g} {sign} {abs(drive.k):g}·α rad/s (α in rad)'


def format_tables(state: LinkageState, rows: int = 1, title: Optional[str] = None) -> str:
    """
    Return the seed's Tables 1–4 layout: velocities, then accelerations; head, ⋮, tail rows.

    ``rows`` is how many rows to show at each end; a state with no more than ``2·rows`` rows is
    shown whole. Angles in degrees (β and γ unwrapped), rates to 4 significant digits.
    """
    if rows < 1:
        raise ValueError(f'rows must be at least 1, got {rows}')
    columns = seed_columns(state)
    count = len(columns['alpha_deg'])
    if count > 2 * rows:
        shown: list[Optional[int]] = [*range(rows), None, *range(count - rows, count)]
    else:
        shown = list(range(count))
    parts = [] if title is None else [title, '']
    parts.append(_table('Velocities', _VELOCITY_COLUMNS, columns, shown))
    parts.append('')
    parts.append(_table('Accelerations', _ACCELERATION_COLUMNS, columns, shown))
    return '\n'.join(parts) + '\n'


def write_plot(state: LinkageState, path: str | os.PathLike[str], title: str) -> None:
    """
    Return the seed's Figs. 4 and 5 as a PNG at ``path``: four panels against α in degrees.

    The image is rendered in memory first, so a failure leaves no file behind.
    """
    from matplotlib.figure import Figure  # matplotlib is slow to import; only plots need it

    columns = seed_columns(state)
    alpha = columns['alpha_deg']
    # Few points would draw as almost nothing without markers.
    style = {'marker': 'o', 'markersize': 3} if len(alpha) <= 50 else {}
    figure = Figure(figsize=(12, 8), layout='constrained')
    axes = figure.subplots(2, 2, sharex=True)
    panels = (
        (axes[0, 0], 'Rocker and coupler angles', 'angle (°)',
         ((r'$\beta$', 'beta_deg'), (r'$\gamma$', 'gamma_deg'))),
        (axes[1, 0], 'Pin speeds', 'speed (m/s)', ((r'$V_A$', 'v_a'), (r'$V_B$', 'v_b'))),
        (axes[0, 1], 'Bar angular velocities', 'angular velocity (rad/s)',
         ((r'$\omega_{AB}$', 'omega_ab'), (r'$\omega_{BC}$', 'omega_bc'))),
        (axes[1, 1], 'Bar angular accelerations', r'angular acceleration (rad/s$^2$)',
         ((r'$\dot\omega_{AB}$', 'omega_dot_ab'), (r'$\dot\omega_{BC}$', 'omega_dot_bc'))),
    )
    for panel, panel_title, ylabel, curves in panels:
        for label, column in curves:
            panel.plot(alpha, columns[column], label=label, **style)
        panel.set_title(panel_title)
        panel.set_ylabel(ylabel)
        panel.grid(True, alpha=0.4)
        panel.legend()
    for panel in axes[1]:
        panel.set_xlabel(r'crank angle $\alpha$ (°)')
    figure.suptitle(title)
    image = io.BytesIO()
    figure.savefig(image, format='png', dpi=100)
    with open(path, 'wb') as output:
        try:
            output.write(image.getvalue())
        except OSError:
            output.close()
            os.unlink(path)
            raise


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Run ``linkage-sweep``; returns the exit status (see ``--help``)."""
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_request:
        return int(exit_request.code or 0)

    if args.from_bag is not None:
        conflicting = [
            '--' + name.replace('_', '-')
            for name in ('preset', 'omega0', 'k', 'branch', 'alpha_start', 'alpha_end',
                         'alpha_step', *DIMENSIONS)
            if getattr(args, name) is not None
        ]
        if conflicting:
            return _fail(
                f"--from-bag takes the states from the bag; drop {', '.join(conflicting)}", 2
            )
        try:
            for mcap_file in bag_files(args.from_bag):
                if mcap_file.truncated:
                    _note(
                        f'{mcap_file.path} ends without its footer (the recorder was stopped '
                        f'abruptly); using the complete records in its first '
                        f'{mcap_file.readable_size} of {mcap_file.size} bytes'
                    )
            _, state = read_states(args.from_bag)
        except BagError as error:
            return _fail(str(error), 1)
        alpha_deg = None
        title = f'Logged run {args.from_bag}'
    else:
        try:
            state, alpha_deg, title = _computed_sweep(args)
        except (GeometryError, SweepRangeError, UnreachableError, DeadPointError) as error:
            return _fail(str(error), 2)

    if args.plot is not None:
        try:
            write_plot(state, args.plot, title)
        except OSError as error:
            return _fail(f'cannot write the plot {args.plot}: {error.strerror or error}', 1)
    try:
        if args.table:
            sys.stdout.write(format_tables(state, rows=args.rows, title=title))
        elif args.plot is None:
            write_csv(state, sys.stdout, alpha_deg)
        sys.stdout.flush()
    except BrokenPipeError:
        # The reader stopped early (e.g. `| head`); keep Python from failing to flush at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    return 0


def _computed_sweep(args: argparse.Namespace) -> tuple[LinkageState, np.ndarray, str]:
    """Return the states the options ask for, their crank angles in degrees, and a title."""
    preset_name = args.preset or 'paper'
    chosen = preset(preset_name)
    overrides = {
        name: getattr(args, name) for name in DIMENSIONS if getattr(args, name) is not None
    }
    linkage = dataclasses.replace(chosen.geometry, **overrides) if overrides else chosen.geometry
    omega0 = DEFAULT_OMEGA0 * chosen.drive_sign if args.omega0 is None else args.omega0
    drive = DriveLaw(omega0, 0.0 if args.k is None else args.k)
    start = 0.0 if args.alpha_start is None else args.alpha_start
    if args.alpha_step is not None:
        direction = math.copysign(1.0, args.alpha_step)
    elif args.alpha_end is not None:
        direction = -1.0 if args.alpha_end < start else 1.0
    else:
        direction = -1.0 if drive.angular_velocity(math.radians(start)) < 0.0 else 1.0
    end = start + DEFAULT_TURN_DEG * direction if args.alpha_end is None else args.alpha_end
    step = DEFAULT_STEP_DEG * direction if args.alpha_step is None else args.alpha_step
    branch = 1 if args.branch is None else args.branch
    alpha_deg = crank_angles(start, end, step)
    alpha = np.radians(alpha_deg)
    # The branch names the assembly at the start; through change points the mechanism goes on
    # along its smooth motion, on which B changes sides.
    state = solve_many(linkage, alpha, drive,
                       continued_branch(linkage, float(alpha[0]), branch, alpha))
    name = f"'{preset_name}' modified" if overrides else f"'{preset_name}'"
    title = (
        f'Four-bar {describe_mechanism(linkage, name)}, branch {branch:+d} at the start\n'
        f'{describe_drive(drive)}, α from {start:g}° to {end:g}° by {step:g}°'
    )
    return state, alpha_deg, title


def _table(
    caption: str,
    layout: tuple[tuple[str, str], ...],
    columns: dict[str, np.ndarray],
    shown: list[Optional[int]],
) -> str:
    cells = [
        [header for header, _ in layout],
        *(
            ['⋮'] * len(layout)
            if row is None
            else [_format_cell(key, float(columns[key][row])) for _, key in layout]
            for row in shown
        ),
    ]
    widths = [max(_display_width(line[index]) for line in cells) for index in range(len(layout))]
    lines = [caption]
    for row_index, line in enumerate(cells):
        lines.append('  '.join(_pad(cell, width) for cell, width in zip(line, widths)))
        if row_index == 0:
            lines.append('  '.join('-' * width for width in widths))
    return '\n'.join(lines)


def _format_cell(key: str, value: float) -> str:
    """Angles to 0.01°, everything else to 4 significant digits (at most 4 decimals)."""
    if not math.isfinite(value):
        return str(value)
    if key.endswith('_deg'):
        decimals = 2
    elif value == 0.0:
        decimals = 4
    else:
        decimals = min(max(3 - math.floor(math.log10(abs(value))), 0), 4)
    text = f'{value:.{decimals}f}'
    return text.lstrip('-') if float(text) == 0.0 else text


def _display_width(text: str) -> int:
    """Terminal columns of ``text``: combining marks (the dot of ω̇) take none."""
    return sum(not unicodedata.combining(character) for character in text)


def _pad(text: str, width: int) -> str:
    return ' ' * (width - _display_width(text)) + text


def _fail(message: str, status: int) -> int:
    print(f'{PROGRAM}: error: {message}', file=sys.stderr)
    return status


def _note(message: str) -> None:
    print(f'{PROGRAM}: note: {message}', file=sys.stderr)


def _png_path(text: str) -> Path:
    path = Path(text)
    if path.suffix.lower() != '.png':
        raise argparse.ArgumentTypeError(
            f'the plot is a PNG: give a file name ending in .png, got {text!r}'
        )
    return path


_finite = number()
_length = number(above=0.0, rule='a length > 0 m')
_row_count = number(int, at_least=1, rule='at least 1')


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROGRAM,
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            'Sweep the crank angle α of a four-bar linkage and print every state (CSV), the\n'
            "seed's head-and-tail tables (--table) or its four-panel figure (--plot); or do the\n"
            'same for a run the node logged (--from-bag).'
        ),
        epilog=(
            'output:\n'
            '  Without --table or --plot: CSV on stdout, one row per crank angle, header\n'
            f"    {','.join(CSV_COLUMNS)}\n"
            '  in SI units (m/s, rad/s, rad/s²), degrees only in the three angle columns,\n'
            '  β and γ unwrapped, floats at full precision. --table prints the tables instead\n'
            '  of CSV; --plot writes only the PNG; both together write the PNG and print the\n'
            '  tables.\n'
            '  When the range leaves the reachable set nothing is written.\n'
            'exit status:\n'
            '  0 success; 2 bad arguments, including a range that leaves the reachable set or\n'
            '  meets a dead point (change points are passed through); 1 a bag that cannot be\n'
            '  read or a plot that cannot be written.'
        ),
    )
    mechanism = parser.add_argument_group(
        'mechanism', 'a preset; each dimension given overrides that one value of the preset'
    )
    mechanism.add_argument(
        '--preset', choices=sorted(PRESETS), default=None,
        help="named mechanism (default: paper, the seed's)",
    )
    for option, what in (
        ('--crank-length', 'disk radius OA (m)'),
        ('--coupler-length', 'coupler AB (m)'),
        ('--rocker-length', 'rocker BC (m)'),
    ):
        mechanism.add_argument(option, type=_length, default=None, metavar='M', help=what)
    mechanism.add_argument('--ground-x', type=_finite, default=None, metavar='M',
                           help='x of the rocker pivot C relative to O (m)')
    mechanism.add_argument('--ground-y', type=_finite, default=None, metavar='M',
                           help='y of the rocker pivot C relative to O (m)')
    mechanism.add_argument(
        '--branch', type=int, choices=(1, -1), default=None,
        help="assembly at the first crank angle: +1 (default, the seed's: B left of the line "
             'A→C) or -1; through a change point the mechanism continues smoothly, so B may '
             'change sides there')
    drive = parser.add_argument_group('drive law ω = ω0 + k·α (α in rad)')
    drive.add_argument(
        '--omega0', type=_finite, default=None, metavar='RAD_PER_S',
        help=f"ω0 in rad/s (default {DEFAULT_OMEGA0:g} times the preset's drive sign)",
    )
    drive.add_argument('--k', type=_finite, default=None, metavar='PER_S',
                       help='k in 1/s (default 0: constant ω)')
    sweep = parser.add_argument_group(
        'crank-angle range (degrees)',
        f'default: {DEFAULT_TURN_DEG:g}° from the start by {DEFAULT_STEP_DEG:g}° in the direction '
        'the drive turns the crank\n(0 to 90 by 0.5 for the paper preset); given only a step or '
        'an end, the other follows\nits direction.',
    )
    sweep.add_argument('--alpha-start', type=_finite, default=None, metavar='DEG',
                       help='first crank angle (default 0)')
    sweep.add_argument('--alpha-end', type=_finite, default=None, metavar='DEG',
                       help='last crank angle, included when it lands on the grid')
    sweep.add_argument('--alpha-step', type=_finite, default=None, metavar='DEG',
                       help='step; negative sweeps clockwise')
    output = parser.add_argument_group('output')
    output.add_argument('--table', action='store_true',
                        help="print the seed's velocity and acceleration tables instead of CSV")
    output.add_argument('--rows', type=_row_count, default=1, metavar='N',
                        help='with --table: rows shown at the head and at the tail (default 1)')
    output.add_argument('--plot', type=_png_path, default=None, metavar='FILE.png',
                        help="write the seed's four-panel figure to FILE.png (no CSV then)")
    output.add_argument(
        '--from-bag', default=None, metavar='BAG',
        help='use the states the node logged on /linkage/state in BAG (a rosbag2 MCAP folder '
             'or an .mcap file) instead of computing; no mechanism, drive or range options then',
    )
    return parser


if __name__ == '__main__':
    sys.exit(main())
