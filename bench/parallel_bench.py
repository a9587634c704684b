# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section parallel: closing parallel robots' loops per sample, against the peers (issue 29 item 8).

On the same models (bench/parallel_models.py: Gepetto/example-parallel-robots' and the
package's humanoid ankle) and the same motions of their actuated joints,
every follower (bench/parallel_peers.py, and the package's own when it lands: ``ours``) closes
the loops sample after sample, warm started from its previous answer. Per model and follower:
the worst position error (rad or m) of the determined coordinates against the reference, the
largest difference of the idle coordinates (whose value is a convention: the reference holds
them at the assembled pose), the median and p90 time per sample, and the samples the follower
itself did not close (its own verdict, or a non-finite answer).

Trajectories (``TRAJECTORIES``, written by ``python bench/parallel_bench.py --write``): per
model, the assembled pose every follower starts from and, per actuated joint k (in name_mot
order), q_k(i) = centre_k + amplitude·sin(2π·(k + 1)·i/N) over N samples: sample 0 is the
assembled pose, every joint moves at its own frequency, N = 500 (``--quick``: the first 100
of them). The amplitude is the largest of 0.2, 0.1, 0.05, ... (rad; a tenth of it in m for a
prismatic joint) along which Gauss–Newton closes every sample. The assembled pose is Pinocchio's
(``parallel_peers.assemble``), not the package's, so that no follower starts from its own
assembly.

Two slots wait for helper C1's branch (issue 29 items 3–4 and the 50-digit reference in test/):

* ``reference``: today PROVISIONAL, Pinocchio's Gauss–Newton iterated to stagnation (float64:
  errors below ~1e-14 mean nothing against it);
* ``ours_follower``: today None (no row), the package's own closure once loops.newton lands.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from dataclasses import dataclass
import json
import math
import pathlib
import statistics
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
if __name__ == '__main__':
    sys.path[1:1] = [str(ROOT), str(ROOT / 'test')]

from parallel_models import MODELS, ParallelModel, section_model  # noqa: E402
from timing import format_error, markdown_table  # noqa: E402

TRAJECTORIES = ROOT / 'bench' / 'parallel_trajectories.json'
SAMPLES = 500
QUICK_SAMPLES = 100
AMPLITUDES = (0.2, 0.1, 0.05, 0.025, 0.0125)
# A prismatic joint's amplitude is this times the revolute one's, in m.
PRISMATIC_SCALE = 0.1
# Runs of each trajectory per follower for the times (at most: the toolbox takes up to 0.1 s a
# sample); 3 runs of 500 samples give the median and p90 of 1500 samples.
RUNS = 3
# A model whose best assembly leaves more than this (m or rad) is reported, not followed.
ASSEMBLED = 1e-12
REFERENCE_LABEL = ('PROVISIONAL reference: Pinocchio Gauss–Newton to stagnation in float64 '
                   "(stand-in for C1's 50-digit reference)")
# Errors of 0 are drawn at this height on the log plot.
PLOT_FLOOR = 1e-17


@dataclass(frozen=True)
class Trajectory:
    """A model's motion: the assembled pose, the actuated joints' centres, the amplitudes (N)."""

    model: str
    pose: dict[str, float]
    amplitude: float
    prismatic: tuple[str, ...]
    idle: tuple[str, ...]

    def samples(self, model: ParallelModel, count: int) -> list[tuple[float, ...]]:
        """Return ``count`` samples of the actuated joints' values (module text)."""
        amplitudes = [self.amplitude * (PRISMATIC_SCALE if name in self.prismatic else 1.0)
                      for name in model.actuated]
        centres = [self.pose[name] for name in model.actuated]
        return [tuple(centre + amplitude * math.sin(2.0 * math.pi * (k + 1) * i / count)
                      for k, (centre, amplitude) in enumerate(zip(centres, amplitudes)))
                for i in range(count)]


@dataclass
class Row:
    """One follower on one model: the section's figures (data; ``table`` prints them)."""

    model: str
    follower: str
    samples: int
    error: float
    idle_difference: float
    median_time: float
    p90_time: float
    failures: int
    note: str = ''


def reference(model: ParallelModel, trajectory: Trajectory,
              samples: Sequence[Sequence[float]]) -> list[tuple[float, ...]]:
    """
    Return the reference's answer to every sample, in ``model.coordinates``' order.

    PROVISIONAL (REFERENCE_LABEL): Pinocchio's Gauss–Newton, 30 minimum-norm steps per sample,
    in float64. The slot for C1's 50-digit reference (test/closure_reference.py in its branch:
    ``Reference(urdf, closures, overrides).solve(known, guess, unknown)``, idle freedoms held at
    the assembled pose): the same samples from ``trajectory.pose``, its answers as mpf (the
    errors are taken in mpmath), or every k-th sample if 500 take too long.
    """
    from parallel_peers import PinocchioGaussNewton

    follower = PinocchioGaussNewton(model, tolerance=0.0, iterations=30)
    follower.start(trajectory.pose)
    return [follower.follow(sample).positions for sample in samples]


def ours_follower(model: ParallelModel):
    """
    Return the package's own follower of ``model``, or None while it has none (no row).

    The slot for the package's spatial closure (helper C1: loops.tree, structure, newton): a
    ``parallel_peers.Follower`` whose ``start`` takes the trajectory's assembled pose (every
    coordinate by name) and whose ``follow`` closes a sample of ``model.actuated`` and returns
    every coordinate in ``model.coordinates``' order, built from ``model.source_urdf`` and
    ``model.closure_file`` as the node reads them (not from the peers' rewritten URDF).
    """
    return None


def peer_followers(model: ParallelModel) -> list[object]:
    """Return the peers' followers of ``model`` (bench/parallel_peers.py)."""
    from parallel_peers import PinocchioGaussNewton, PlacoClosure, ToolboxSlsqp

    return [PinocchioGaussNewton(model), PlacoClosure(model, steps=1),
            PlacoClosure(model, steps=10), ToolboxSlsqp(model)]


def load_trajectories() -> dict[str, Trajectory]:
    """Return the stored trajectories by model name."""
    stored = json.loads(TRAJECTORIES.read_text())
    return {name: Trajectory(name, entry['pose'], entry['amplitude'],
                             tuple(entry['prismatic']), tuple(entry['idle']))
            for name, entry in stored['models'].items()}


def run(quick: bool, repetitions: int,
        models: Sequence[str] = MODELS) -> tuple[list[Row], dict[str, str]]:
    """
    Follow every stored model's trajectory with every follower; return the rows and notes.

    Times: each follower runs the whole trajectory ``repetitions`` times (at most RUNS), the
    followers of a model round-robin (each from the assembled pose again); median and p90 over
    all samples of all runs. Errors and failures: the first run.
    """
    trajectories = load_trajectories()
    count = QUICK_SAMPLES if quick else SAMPLES
    rows: list[Row] = []
    notes: dict[str, str] = {}
    for name in models:
        model = section_model(name)
        trajectory = trajectories.get(name)
        if trajectory is None:
            left_out = json.loads(TRAJECTORIES.read_text())['left_out']
            notes[name] = 'left out: ' + left_out.get(name, f'not in {TRAJECTORIES.name}')
            continue
        # --quick follows the start of the same motion: the spacing of samples the stored
        # amplitude was checked at
        samples = trajectory.samples(model, SAMPLES)[:count]
        exact = reference(model, trajectory, samples)
        followers = [follower for follower in (ours_follower(model), *peer_followers(model))
                     if follower is not None]
        answers = {}
        times: dict[int, list[float]] = {index: [] for index in range(len(followers))}
        for repetition in range(min(repetitions, RUNS)):
            for index, follower in enumerate(followers):
                follower.start(trajectory.pose)
                run_answers, run_times = _follow(follower.follow, samples)
                times[index] += run_times
                if repetition == 0:
                    answers[index] = run_answers
        for index, follower in enumerate(followers):
            rows.append(_row(model, trajectory, follower.label, answers[index], exact,
                             times[index]))
    return rows, notes


def _follow(follow: Callable, samples: Sequence[Sequence[float]]) -> tuple[list, list[float]]:
    answers, times = [], []
    clock = time.perf_counter
    for sample in samples:
        start = clock()
        answer = follow(sample)
        times.append(clock() - start)
        answers.append(answer)
    return answers, times


def _row(model: ParallelModel, trajectory: Trajectory, label: str, answers: list,
         exact: list[tuple[float, ...]], times: list[float]) -> Row:
    prismatic = set(trajectory.prismatic)
    idle = set(trajectory.idle)
    error = idle_difference = 0.0
    failures = 0
    for answer, expected in zip(answers, exact):
        if not answer.converged or not all(map(math.isfinite, answer.positions)):
            failures += 1
        if not all(map(math.isfinite, answer.positions)):
            continue
        for name, value, wanted in zip(model.coordinates, answer.positions, expected):
            # taken in the reference's type (mpf for a 50-digit one), then rounded
            difference = float(value - wanted)
            if name not in prismatic:
                difference = math.remainder(difference, 2.0 * math.pi)
            if name in idle:
                idle_difference = max(idle_difference, abs(difference))
            else:
                error = max(error, abs(difference))
    deciles = statistics.quantiles(times, n=10)
    return Row(model.name, label, len(answers), error, idle_difference,
               statistics.median(times), deciles[8], failures)


def table(rows: Sequence[Row], notes: dict[str, str]) -> str:
    """Return the section's markdown: one row per model and follower, then the notes."""
    header = ['model', 'follower', 'worst error (rad, m)', 'idle coordinates: largest difference',
              'time / sample: median', 'p90', 'not closed (own verdict)']
    lines = markdown_table(header, [
        [row.model, row.follower, format_error(row.error),
         format_error(row.idle_difference) if row.idle_difference else '–',
         f'{row.median_time * 1e6:.1f} µs', f'{row.p90_time * 1e6:.1f} µs',
         f'{row.failures} of {row.samples}'] for row in rows])
    extra = [f'- {model}: {note}' for model, note in notes.items()]
    return '\n'.join([f'Errors against the {REFERENCE_LABEL}.', '', lines,
                      *([''] + extra if extra else [])])


def plot(rows: Sequence[Row], path: str) -> None:
    """Draw median time per sample against worst error, log-log: one marker per follower, model."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    followers = list(dict.fromkeys(row.follower for row in rows))
    models = list(dict.fromkeys(row.model for row in rows))
    markers = dict(zip(followers, 'os^Dv<>P'))
    colours = dict(zip(models, plt.get_cmap('tab10').colors))
    figure, axis = plt.subplots(figsize=(13, 6.5))
    for row in rows:
        axis.loglog(row.median_time, max(row.error, PLOT_FLOOR), marker=markers[row.follower],
                    color=colours[row.model], markersize=8, linestyle='none',
                    markerfacecolor='none' if row.failures else colours[row.model])
    for follower in followers:
        axis.plot([], [], marker=markers[follower], color='grey', linestyle='none',
                  label=follower)
    for model in models:
        axis.plot([], [], marker='s', color=colours[model], linestyle='none', label=model)
    axis.set_xlabel('time per sample (s), median')
    axis.set_ylabel('worst position error (rad, m)')
    axis.grid(True, which='major', alpha=0.4)
    axis.legend(fontsize=8, loc='upper left', bbox_to_anchor=(1.01, 1.0))
    axis.set_title('Closing parallel robots per sample (lower left is better; hollow: some '
                   'samples not closed)\nerrors against the ' + REFERENCE_LABEL, fontsize=9)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def write_trajectories(models: Sequence[str] = MODELS) -> dict[str, str]:
    """
    Assemble each of ``models``, choose its amplitude, and store its trajectory (module text).

    The stored entries of the other models are kept as they are. Returns why a model was left
    out. The assembly is Pinocchio's (parallel_peers.assemble): no follower starts from its own.
    """
    from parallel_peers import assemble, idle_coordinates

    stored = json.loads(TRAJECTORIES.read_text()) if TRAJECTORIES.exists() else {
        'samples': SAMPLES, 'models': {}, 'left_out': {}}
    left_out = {}
    for name in models:
        stored['models'].pop(name, None)
        stored['left_out'].pop(name, None)
        model = section_model(name)
        pose, residual = assemble(model)
        if residual > ASSEMBLED:
            left_out[name] = (f'no assembly found: Levenberg–Marquardt from the zero pose stops '
                              f'at a residual of {residual:.2g} (m, rad)')
            continue
        prismatic = tuple(joint.get('name') for joint in _joints(model)
                          if joint.get('type') == 'prismatic')
        idle = idle_coordinates(model, pose)
        for amplitude in AMPLITUDES:
            trajectory = Trajectory(name, pose, amplitude, prismatic, idle)
            if _closes(model, trajectory):
                stored['models'][name] = {'pose': pose, 'amplitude': amplitude,
                                          'prismatic': list(prismatic), 'idle': list(idle)}
                break
        else:
            left_out[name] = f'Gauss–Newton fails even at an amplitude of {AMPLITUDES[-1]}'
    stored['left_out'].update(left_out)
    stored['models'] = {name: stored['models'][name] for name in MODELS
                        if name in stored['models']}
    TRAJECTORIES.write_text(json.dumps(stored, indent=1) + '\n')
    return left_out


def _joints(model: ParallelModel) -> list:
    import lxml.etree

    return lxml.etree.fromstring(model.urdf.encode()).findall('joint')


def _closes(model: ParallelModel, trajectory: Trajectory) -> bool:
    """Return whether Gauss–Newton closes every sample of ``trajectory`` to 1e-12."""
    from parallel_peers import PinocchioGaussNewton

    follower = PinocchioGaussNewton(model, iterations=30)
    follower.start(trajectory.pose)
    return all(follower.follow(sample).converged
               for sample in trajectory.samples(model, SAMPLES))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--write', action='store_true',
                        help=f'assemble the models and write their entries of {TRAJECTORIES.name}')
    parser.add_argument('models', nargs='*', metavar='MODEL',
                        help=f'the models to write (default: all of {", ".join(MODELS)})')
    arguments = parser.parse_args()
    unknown = sorted(set(arguments.models) - set(MODELS))
    if unknown:
        parser.error(f'not models of the section: {", ".join(unknown)}')
    import peers

    peers.activate(install=True)
    if arguments.write:
        for name, reason in write_trajectories(arguments.models or MODELS).items():
            print(f'{name}: {reason}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
