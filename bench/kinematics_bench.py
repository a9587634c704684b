# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""Section 1: cost per configuration against error, for the library and its alternatives."""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Callable

import competitors
from competitors import QUANTITIES, States
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import FourBar, preset
from linkage_kinematics.kinematics.solver import continued_branch, solve, solve_many
from mpmath import mp, mpf
import numpy as np
from reference import continued_sides, reference_state
from seed_formulation import seed_state
from timing import (
    format_error,
    format_seconds,
    interleaved_medians,
    markdown_table,
    paired_ratio,
)

LAWS = {'constant ω = 2 rad/s': DriveLaw(2.0), 'ω = 0.10 + 2.3·α': DriveLaw(0.1, 2.3)}
# The rows the goals compare.
SCALAR = 'closed form, scalar: kinematics.solve'
VECTOR = 'closed form, vectorised: kinematics.solve_many'
MINIMAL = 'minimal hand-written closed form (bench code, no checks, tuple out)'
MINIMAL_NUMPY = 'minimal numpy closed form (bench code, whole arrays, no checks, tuple out)'
# Closest approach to the dead point: 1e-13 rad, just outside the library's refusal zone (a
# one-ulp change of α moves the exact accelerations by more than 0.1 % within ~1e-14 rad).
NEAR_DEAD_CLOSEST = 1e-13
# The change-point set: the parallelogram OA = BC = 0.3, AB = OC = 1.0 on its crossed assembly,
# turning through its change point at α = 90° from 80° on.
PARALLELOGRAM = FourBar(0.3, 1.0, 0.3, 1.0, 0.0)
CHANGE_START = math.radians(80.0)
# An error this small or smaller is drawn at this height on the log plot (0 cannot be drawn).
PLOT_FLOOR = 1e-17
# Label placements (points) that keep the clustered exact methods' labels apart.
LABEL_OFFSETS = {'solve': (-10, -16), 'minimal': (-30, 8), 'Newton 1e-08': (-20, 10),
                 'Newton 1e-12': (4, -14), 'root 1e-12': (6, 4), 'pylinkage': (6, 6),
                 'solve_many': (-20, 10), 'fsolve': (6, 4), 'root 1e-08': (6, -10),
                 'minimal numpy': (-24, -16)}


@dataclass
class AngleSet:
    """
    Crank angles of one motion of one linkage.

    The motion starts at ``start`` on ``branch`` and turns smoothly through ``alphas``; ``sides``
    are the assemblies the reference's own continuation finds there (what a method must follow);
    ``start_guess`` is the (γ, β) an iterative solver starts from at ``start``.
    """

    linkage: FourBar
    alphas: list[float]
    start: float
    branch: int
    sides: list[int]
    start_guess: tuple[float, float]
    title: str


@dataclass
class Method:
    """One way of computing the state, one setting of it."""

    name: str
    family: str
    states: Callable[[AngleSet, DriveLaw], States]
    workload: Callable[[], int]
    note: str = ''


@dataclass
class Errors:
    """Largest errors over a set of angles and both drive laws (NaN: no result at all)."""

    position: float
    rate: float
    acceleration: float
    missing: int
    per_point: list[float]

    @property
    def worst(self) -> float:
        return max(self.position, self.rate, self.acceleration)


def angle_sets(linkage: FourBar, quick: bool) -> dict[str, AngleSet]:
    """
    Return the seed's 0°–90° sweep.

    A sweep from 1e-3 rad down to 1e-13 rad above the dead point; and the crossed parallelogram
    through its change point, from 1e-3 rad below it to 1e-13 rad below, on the float nearest it,
    and from 1e-13 to 1e-3 rad above.
    """
    dead = linkage.reachability.intervals[0][0]
    sweep = np.radians(np.linspace(0.0, 90.0, 31 if quick else 91))
    offsets = np.logspace(-3, math.log10(NEAR_DEAD_CLOSEST), 11 if quick else 21)
    near_dead = [float(dead + offset) for offset in offsets]
    change = math.pi / 2
    change_offsets = np.logspace(-3, -13, 6 if quick else 11)
    through_change = ([float(change - offset) for offset in change_offsets] + [change]
                      + [float(change + offset) for offset in change_offsets[::-1]])
    paper_guess = competitors.seed_start_guess(linkage)
    start_state = solve(PARALLELOGRAM, CHANGE_START, DriveLaw(1.0), 1)
    change_guess = (start_state.gamma, start_state.beta)
    return {
        '0°–90° sweep': AngleSet(linkage, [float(a) for a in sweep], 0.0, 1,
                                 [1] * sweep.size, paper_guess, 'paper mechanism'),
        'near the dead point': AngleSet(linkage, near_dead, 0.0, 1, [1] * len(near_dead),
                                        paper_guess, 'paper mechanism'),
        'through a change point': AngleSet(
            PARALLELOGRAM, through_change, CHANGE_START, 1,
            continued_sides(PARALLELOGRAM, CHANGE_START, 1, through_change), change_guess,
            'crossed parallelogram'),
    }


def references(sets: dict[str, AngleSet]) -> dict[tuple[str, str], list[dict[str, mpf]]]:
    """
    Return the mpmath reference at every angle of every set.

    Under each law, on the set's sides.
    """
    return {
        (set_name, law_name): [reference_state(angle_set.linkage, alpha, law, side)
                               for alpha, side in zip(angle_set.alphas, angle_set.sides)]
        for set_name, angle_set in sets.items()
        for law_name, law in LAWS.items()
    }


def measure_errors(
    method: Method, sets: dict[str, AngleSet],
    reference: dict[tuple[str, str], list[dict[str, mpf]]], set_name: str,
) -> Errors:
    """
    Angles: largest |error| of β and γ (rad).

    Rates and accelerations: largest |error| of the two bars', relative to the larger of the two at
    that angle (so the figure means the same far from and close to the dead point, where the rates
    grow without bound).
    """
    position = rate = acceleration = 0.0
    missing = 0
    per_point = [0.0] * len(sets[set_name].alphas)
    provided = QUANTITIES[:2] if method.note == 'no rates' else QUANTITIES
    with mp.workdps(30):
        for law_name, law in LAWS.items():
            states = method.states(sets[set_name], law)
            for index, exact in enumerate(reference[(set_name, law_name)]):
                values = {name: float(states[name][index]) for name in provided}
                if any(not math.isfinite(value) for value in values.values()):
                    missing += 1
                    per_point[index] = math.inf
                    continue
                angle_error = max(
                    float(abs(_wrap(mpf(values[name]) - exact[name])))
                    for name in ('beta', 'gamma')
                )
                rate_error = acceleration_error = 0.0
                if method.note != 'no rates':
                    rate_error = _relative(values, exact, ('omega_ab', 'omega_bc'))
                    acceleration_error = _relative(values, exact,
                                                   ('omega_dot_ab', 'omega_dot_bc'))
                position = max(position, angle_error)
                rate = max(rate, rate_error)
                acceleration = max(acceleration, acceleration_error)
                per_point[index] = max(per_point[index], angle_error, rate_error,
                                       acceleration_error)
    if missing == len(sets[set_name].alphas) * len(LAWS):
        position = rate = acceleration = math.nan
    return Errors(position, rate, acceleration, missing, per_point)


def _wrap(angle: mpf) -> mpf:
    return angle - 2 * mp.pi * mp.nint(angle / (2 * mp.pi))


def _relative(values: dict[str, float], exact: dict[str, mpf], names: tuple[str, str]) -> float:
    scale = max(abs(exact[name]) for name in names)
    return float(max(abs(mpf(values[name]) - exact[name]) for name in names) / scale)


def methods(linkage: FourBar, quick: bool) -> list[Method]:
    """Every method and setting, each with a timing workload on the seed's sweep."""
    variable = LAWS['ω = 0.10 + 2.3·α']
    scalar_count = 3000 if quick else 10000
    vector_count = 200_000 if quick else 1_000_000
    iterative_count = 200 if quick else 500
    sweep = np.linspace(0.0, math.pi / 2, vector_count)
    scalar_alphas = [float(a) for a in np.linspace(0.0, math.pi / 2, scalar_count)]
    iterative_alphas = [float(a) for a in np.linspace(0.0, math.pi / 2, iterative_count)]
    start = competitors.seed_start_guess(linkage)
    parameters = (linkage.crank_length, linkage.coupler_length, linkage.rocker_length,
                  linkage.ground_x, linkage.ground_y, 1, variable.omega0, variable.k)

    def library_states(angle_set: AngleSet, drive: DriveLaw) -> States:
        rows = [solve(angle_set.linkage, alpha, drive, branch)
                for alpha, branch in zip(angle_set.alphas, _library_branches(angle_set))]
        return {name: [getattr(row, name) for row in rows] for name in QUANTITIES}

    def library_many_states(angle_set: AngleSet, drive: DriveLaw) -> States:
        alphas = np.array(angle_set.alphas)
        state = solve_many(angle_set.linkage, alphas, drive,
                           np.array(_library_branches(angle_set)))
        return {name: getattr(state, name) for name in QUANTITIES}

    def continued(function: Callable[..., States], *settings) -> Callable[..., States]:
        """
        March an iterative solver from the set's start position.

        From there (for the paper mechanism the seed's, at α = 0) to the set's first angle, as a
        node turning the crank would, then along the set.
        """
        def states(angle_set: AngleSet, drive: DriveLaw) -> States:
            alphas = angle_set.alphas
            lead_in = [float(a) for a in np.linspace(angle_set.start, alphas[0], 20)]
            result = function(angle_set.linkage, lead_in + alphas, drive, *settings,
                              angle_set.start_guess)
            return {name: values[len(lead_in):] for name, values in result.items()}
        return states

    def scalar_loop(function: Callable[[float], object], alphas: list[float]) -> Callable[[], int]:
        def workload() -> int:
            for alpha in alphas:
                function(alpha)
            return len(alphas)
        return workload

    def minimal_loop() -> int:
        closed_form = competitors.minimal_closed_form
        crank, coupler, rocker, ground_x, ground_y, branch, omega0, k = parameters
        for alpha in scalar_alphas:
            closed_form(crank, coupler, rocker, ground_x, ground_y, branch, omega0, k, alpha)
        return len(scalar_alphas)

    def library_loop() -> int:
        for alpha in scalar_alphas:
            solve(linkage, alpha, variable)
        return len(scalar_alphas)

    result = [
        Method(SCALAR, 'closed form (this library)',
               library_states, library_loop),
        Method(VECTOR, 'closed form (this library)',
               library_many_states,
               lambda: (solve_many(linkage, sweep, variable), sweep.size)[1]),
        Method(MINIMAL, 'closed form (bench yardstick)',
               lambda angle_set, drive: competitors.minimal_states(
                   angle_set.linkage, angle_set.alphas, drive, angle_set.sides),
               minimal_loop),
        Method(MINIMAL_NUMPY, 'closed form (bench yardstick)',
               lambda angle_set, drive: competitors.minimal_numpy_states(
                   angle_set.linkage, angle_set.alphas, drive, angle_set.sides),
               lambda: (competitors.minimal_numpy_closed_form(*parameters, sweep),
                        sweep.size)[1]),
        Method("seed paper's Eqs. (2)–(19)", 'seed formulation',
               lambda angle_set, drive: _seed_states(angle_set, drive),
               scalar_loop(lambda alpha: seed_state(linkage, alpha, variable), scalar_alphas)),
    ]
    for tolerance in (1e-4, 1e-8, 1e-12):
        result.append(Method(
            f'Newton on the loop equations, step size < {tolerance:g}', 'generic solver',
            continued(competitors.newton_states, tolerance),
            lambda tolerance=tolerance: len(competitors.newton_states(
                linkage, iterative_alphas, variable, tolerance, start)['beta'])))
    for tolerance in (1e-4, 1e-8, 1e-12):
        result.append(Method(
            f'scipy.optimize.root (hybr, analytic Jacobian), tol = {tolerance:g}',
            'generic solver',
            continued(competitors.scipy_root_states, tolerance),
            lambda tolerance=tolerance: len(competitors.scipy_root_states(
                linkage, iterative_alphas, variable, tolerance, start)['beta'])))
    result.append(Method(
        'scipy.optimize.fsolve, defaults', 'generic solver',
        continued(competitors.fsolve_states),
        lambda: len(competitors.fsolve_states(linkage, iterative_alphas, variable,
                                              start)['beta'])))
    result.extend(_finite_difference_methods(linkage, sweep[: vector_count // 4], variable))
    result.extend(_pylinkage_methods(linkage, iterative_count))
    return result


def _finite_difference_methods(linkage: FourBar, alphas: np.ndarray, law: DriveLaw
                               ) -> list[Method]:
    """Central differences of exact positions at several steps, timed on ``alphas``."""
    return [
        Method(
            f'finite differences of exact positions, h = {step:g} rad', 'finite differences',
            lambda angle_set, drive, step=step: competitors.finite_difference_states(
                angle_set.linkage, np.array(angle_set.alphas), drive, step, angle_set.start,
                angle_set.branch),
            lambda step=step: (competitors.finite_difference_states(
                linkage, alphas, law, step), alphas.size)[1])
        for step in (1e-2, 1e-4, 1e-6, 1e-8)
    ]


def _library_branches(angle_set: AngleSet) -> list[int]:
    """Return the library's own branch at each angle of the set's motion (continued_branch)."""
    return [continued_branch(angle_set.linkage, angle_set.start, angle_set.branch, alpha)
            for alpha in angle_set.alphas]


def _seed_states(angle_set: AngleSet, drive: DriveLaw) -> States:
    """
    Return the seed's equations' states, for its own mechanism only.

    They hold only there (OA = BC, C level with O, the α = 0 start): no result for another
    linkage.
    """
    if angle_set.linkage != preset('paper').geometry:
        return {name: [math.nan] * len(angle_set.alphas) for name in QUANTITIES}
    rows = [seed_state(angle_set.linkage, alpha, drive) for alpha in angle_set.alphas]
    return {name: [row[name] for row in rows] for name in QUANTITIES}


def _pylinkage_methods(linkage: FourBar, count: int) -> list[Method]:
    try:
        import pylinkage
    except ImportError as error:
        print(f'pylinkage is not installed ({error}); its rows are left out')
        return []
    step = (math.pi / 2) / count
    sweeper = competitors.PylinkageModel(linkage, step)
    constant = LAWS['constant ω = 2 rad/s']

    def states(angle_set: AngleSet, drive: DriveLaw) -> States:
        # a model per set, assembled at the set's start on its branch
        model = competitors.PylinkageModel(angle_set.linkage, 0.0, angle_set.start,
                                           angle_set.branch)
        return model.states(angle_set.alphas, drive)

    return [
        Method(f'pylinkage {pylinkage.__version__} step_with_derivatives', 'other package',
               states, lambda: sweeper.sweep(count, constant),
               'timed on its own constant-ω loop'),
        Method(f'pylinkage {pylinkage.__version__} step (positions only)', 'other package',
               lambda angle_set, drive: {**states(angle_set, drive),
                                         **{name: [math.nan] * len(angle_set.alphas)
                                            for name in QUANTITIES[2:]}},
               lambda: sweeper.sweep_positions(count), 'no rates'),
    ]


def run(quick: bool, repetitions: int) -> tuple[str, dict[str, object]]:
    """Measure, print and return the section's markdown and the figures the goals need."""
    linkage = preset('paper').geometry
    sets = angle_sets(linkage, quick)
    reference = references(sets)
    all_methods = methods(linkage, quick)
    errors = {
        (method.name, set_name): measure_errors(method, sets, reference, set_name)
        for method in all_methods
        for set_name in sets
    }
    times = interleaved_medians({m.name: m.workload for m in all_methods}, repetitions)
    header = ['method', 'time / configuration']
    for set_name in sets:
        header += [f'{set_name}: angles (rad)', 'rates (rel.)', 'accelerations (rel.)']
    rows = []
    for method in all_methods:
        row = [method.name + (f' ({method.note})' if method.note else ''),
               format_seconds(times[method.name])]
        for set_name in sets:
            error = errors[(method.name, set_name)]
            cells = [format_error(error.position), format_error(error.rate),
                     format_error(error.acceleration)]
            if error.missing and not math.isnan(error.position):
                cells[0] += (f' ({error.missing} of {len(sets[set_name].alphas) * len(LAWS)} '
                             'failed)')
            if method.note == 'no rates':
                cells[1] = cells[2] = 'no rates'
            row += cells
        rows.append(row)
    table = markdown_table(header, rows)
    figures = _goal_figures(all_methods, errors, times, sets)
    workloads = {method.name: method.workload for method in all_methods}
    pairs = 3 * repetitions
    figures.update(
        pairs=pairs,
        scalar_over_minimal=paired_ratio(workloads[SCALAR], workloads[MINIMAL], pairs),
        vector_over_minimal=paired_ratio(workloads[VECTOR], workloads[MINIMAL_NUMPY], pairs),
    )
    return table, {'methods': all_methods, 'errors': errors, 'times': times, 'sets': sets,
                   **figures}


def _goal_figures(all_methods, errors, times, sets) -> dict[str, object]:
    exactness = {}
    for set_name in sets:
        library = errors[(SCALAR, set_name)].per_point
        worse_by = []
        for index, library_error in enumerate(library):
            best_other = min(
                errors[(method.name, set_name)].per_point[index]
                for method in all_methods
                if not method.family.startswith('closed form') and method.note != 'no rates'
            )
            worse_by.append((library_error / best_other if best_other > 0.0
                             else (1.0 if library_error == 0.0 else math.inf), index))
        worst_ratio, worst_index = max(worse_by)
        exactness[set_name] = (sum(ratio > 1.0 for ratio, _ in worse_by),
                               sum(ratio > 2.0 for ratio, _ in worse_by), len(library),
                               worst_ratio, sets[set_name].alphas[worst_index])
    return {
        'vector_rate': 1.0 / times[VECTOR],
        'scalar_time': times[SCALAR],
        'exactness': exactness,
    }


def plot(results: dict[str, object], path: str) -> None:
    """Log-log time per configuration against worst error, one panel per angle set."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    sets = results['sets']
    markers = {'closed form (this library)': ('o', 'tab:green'),
               'closed form (bench yardstick)': ('s', 'tab:olive'),
               'seed formulation': ('X', 'tab:red'),
               'generic solver': ('^', 'tab:blue'),
               'finite differences': ('v', 'tab:purple'),
               'other package': ('D', 'tab:orange')}
    figure, axes = plt.subplots(1, len(sets), figsize=(17, 6.5), sharey=True)
    for axis, set_name in zip(axes, sets):
        no_result = []
        finite_differences_labelled = False
        for method in results['methods']:
            error = results['errors'][(method.name, set_name)]
            worst = error.worst
            if method.note == 'no rates':
                continue
            if math.isnan(worst):
                no_result.append(_short_label(method))
                continue
            marker, colour = markers[method.family]
            x = results['times'][method.name]
            y = max(worst, PLOT_FLOOR)
            axis.loglog(x, y, marker=marker, color=colour, markersize=9, linestyle='none',
                        label=method.family)
            label = _short_label(method)
            if (method.family == 'finite differences' and worst > 0.1
                    and set_name != '0°–90° sweep'):
                # every step size fails here; one label for the overlapping markers
                if finite_differences_labelled:
                    continue
                label, finite_differences_labelled = 'FD, every h', True
            offset = LABEL_OFFSETS.get(label, (6, 4))
            axis.annotate(label, (x, y), textcoords='offset points', xytext=offset, fontsize=8)
        if no_result:
            axis.text(0.03, 0.97, 'no result: ' + ', '.join(no_result), transform=axis.transAxes,
                      va='top', fontsize=9)
        axis.set_title(f'{set_name}\n({sets[set_name].title}, both drive laws)', fontsize=10)
        axis.set_xlabel('time per configuration (s), median')
        axis.grid(True, which='major', alpha=0.4)
        axis.set_xlim(3e-8, 3e-3)
    axes[0].set_ylabel('max error: angles (rad), rates and accelerations (relative)')
    handles, labels = axes[0].get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    figure.legend(unique.values(), unique.keys(), loc='lower center', ncol=6, fontsize=9)
    figure.suptitle('Speed against error (lower left is better; errors of 0 drawn at 1e-17)')
    figure.tight_layout(rect=(0, 0.06, 1, 0.96))
    figure.savefig(path, dpi=110)
    plt.close(figure)


def _short_label(method: Method) -> str:
    name = method.name
    replacements = {
        SCALAR: 'solve',
        VECTOR: 'solve_many',
        MINIMAL: 'minimal',
        MINIMAL_NUMPY: 'minimal numpy',
        "seed paper's Eqs. (2)–(19)": 'seed Eqs.',
        'scipy.optimize.fsolve, defaults': 'fsolve',
    }
    if name in replacements:
        return replacements[name]
    if name.startswith('Newton'):
        return 'Newton ' + name.rsplit('< ', 1)[1]
    if name.startswith('scipy.optimize.root'):
        return 'root ' + name.rsplit('= ', 1)[1]
    if name.startswith('finite'):
        return 'FD h=' + name.split('h = ')[1].split(' ')[0]
    if name.startswith('pylinkage'):
        return 'pylinkage' + (' (pos.)' if 'positions' in name else '')
    return name


def goals(results: dict[str, object]) -> str:
    """Return the kinematics goals, each with its measured figure."""
    ratio = results['scalar_over_minimal']
    rate = results['vector_rate']
    vector_ratio = results['vector_over_minimal']
    lines = [
        f"- scalar path: {format_seconds(results['scalar_time'])} per configuration, "
        f"{ratio:.2f}× the minimal hand-written closed form (median of {results['pairs']} "
        f'back-to-back pairs; goal ≤ 1.5×: '
        f"{'met' if ratio <= 1.5 else 'missed'})",
        f'- vectorised path: {rate / 1e6:.1f} million configurations per second on '
        f'a 0°–90° sweep (goal ≥ 5: '
        f"{'met' if rate >= 5e6 else 'missed'}), {vector_ratio:.2f}× the minimal numpy closed "
        f"form (median of {results['pairs']} back-to-back pairs; goal ≤ 1.1×: "
        f"{'met' if vector_ratio <= 1.1 else 'missed'})",
    ]
    for set_name, (better, much_better, total, worst, alpha) in results['exactness'].items():
        lines.append(
            f'- {set_name}: some other method is more exact than the closed form at {better} '
            f"of {total} angles, by more than 2× at {much_better}; at worst the closed form's "
            f"error is {worst:.2g}× the best other method's (α = {math.degrees(alpha):.9f}°); "
            'per angle: the worst of angles, rates and accelerations over both laws')
    return '\n'.join(lines)
