# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section parallel: closing parallel robots' loops per sample, against the peers (issue 29 item 8).

On the same models (bench/parallel_models.py: Gepetto/example-parallel-robots' and the
package's humanoid ankle) and the same motions of their actuated joints, every follower (the
package's own, bench/parallel_ours.py, and the peers, bench/parallel_peers.py) closes the loops
sample after sample, warm started from its previous answer. Per model and follower: the worst
position error (rad or m) of the determined coordinates against the 50-digit reference
(bench/parallel_reference.py, at every ``EVERY``-th sample), the largest difference of the idle
coordinates (whose value is a convention: the reference holds them at the assembled pose, as
the package does), the median and p90 time per sample, and the samples the follower itself did
not close (its own verdict: the package's refusals, a peer's convergence test; or a non-finite
answer).

Trajectories (``TRAJECTORIES``, written by ``python bench/parallel_bench.py --write``): per
model, the assembled pose every follower starts from and, per actuated joint k (in name_mot
order), q_k(i) = centre_k + amplitude·sin(2π·(k + 1)·i/N) over N samples: sample 0 is the
assembled pose, every joint moves at its own frequency, N = 500 (``--quick``: the first 100
of them). The amplitude is the largest of 0.2, 0.1, 0.05, ... (rad; a tenth of it in m for a
prismatic joint) along which Gauss–Newton closes every sample. The assembled pose is Pinocchio's
(``parallel_peers.assemble``), not the package's, so that no follower starts from its own
assembly; the package plans its groups there (loops.newton.plan_group), which moves the pose
by rounding only (below 2e-14).

Errors are taken at every ``EVERY``-th sample (``QUICK_EVERY``-th with ``--quick``): the
50-digit reference takes 0.1 to 7 s a sample on these models.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from dataclasses import dataclass
import json
import math
import pathlib
import re
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
# The samples the 50-digit reference closes: every EVERY-th (20 of 500; 10 of 100 with --quick).
EVERY = 25
QUICK_EVERY = 10
EPSILON = sys.float_info.epsilon
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
    median_time: float  # NaN: the follower refused to start
    p90_time: float
    failures: int
    # False where the actuated joints leave free motion: the error is then a distance from the
    # reference's convention, and the plot leaves the row out
    determined: bool = True


def reference_every(quick: bool) -> int:
    """Return k: the reference closes every k-th sample (module text)."""
    return QUICK_EVERY if quick else EVERY


def reference(model: ParallelModel, trajectory: Trajectory, samples: Sequence[Sequence[float]],
              every: int) -> tuple[dict[int, tuple], list[str], bool]:
    """
    Return the 50-digit reference's answer to every ``every``-th sample, notes, determinacy.

    Answers by sample index, every coordinate in ``model.coordinates``' order (the solved ones
    mpf); bench/parallel_reference.py says how. Its start at each sample is Pinocchio's
    Gauss–Newton continued over every sample from the trajectory's pose (30 steps, to
    stagnation). The notes: samples it left out, and groups the actuated joints do not
    determine (their free motions' held value is the reference's convention only); the bool:
    whether they determine every group.
    """
    from parallel_peers import PinocchioGaussNewton
    from parallel_reference import ReferencePath

    path = ReferencePath(model, trajectory.pose)
    continuation = PinocchioGaussNewton(model, tolerance=0.0, iterations=30)
    continuation.start(trajectory.pose)
    answers = {}
    for index, sample in enumerate(samples):
        guess = continuation.follow(sample).positions
        if index % every == 0:
            answer = path.solve(sample, guess)
            if answer is not None:
                answers[index] = answer
    taken = range(0, len(samples), every)
    notes = []
    if path.undetermined:
        notes.append('its actuated joints leave free motions that move other joints (the '
                     "package's structure, in group(s) " + ', '.join(path.undetermined) + '): '
                     "the pose is not determined, and each follower's error is its distance "
                     "from the reference's convention, those motions held at the assembled "
                     'pose')
    if len(answers) < len(taken):
        notes.append(f'the reference left out {len(taken) - len(answers)} of its {len(taken)} '
                     "samples (no closure on Gauss–Newton's assembly there)")
    return answers, notes, not path.undetermined


def ours_follower(model: ParallelModel):
    """Return the package's own follower of ``model`` (bench/parallel_ours.py)."""
    from parallel_ours import PackageClosure

    return PackageClosure(model)


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


def run(quick: bool, repetitions: int, models: Sequence[str] = MODELS
        ) -> tuple[list[Row], dict[str, list[str]]]:
    """
    Follow every stored model's trajectory with every follower; return the rows and notes.

    Times: each follower runs the whole trajectory ``repetitions`` times (at most RUNS), the
    followers of a model round-robin (each from the assembled pose again); median and p90 over
    all samples of all runs. Errors and failures: the first run. Notes by model: why it was left
    out, what the reference says of it, the package's largest conditioning κ (its floor κ·ε) or
    why it refused to start.
    """
    from parallel_ours import StartRefused

    trajectories = load_trajectories()
    count = QUICK_SAMPLES if quick else SAMPLES
    every = reference_every(quick)
    rows: list[Row] = []
    notes: dict[str, list[str]] = {}
    for name in models:
        model = section_model(name)
        trajectory = trajectories.get(name)
        if trajectory is None:
            left_out = json.loads(TRAJECTORIES.read_text())['left_out']
            notes[name] = ['left out: ' + left_out.get(name, f'not in {TRAJECTORIES.name}')]
            continue
        # --quick follows the start of the same motion: the spacing of samples the stored
        # amplitude was checked at
        samples = trajectory.samples(model, SAMPLES)[:count]
        exact, notes[name], determined = reference(model, trajectory, samples, every)
        ours = ours_follower(model)
        try:
            ours.start(trajectory.pose)
        except StartRefused as refused:
            rows.append(Row(model.name, ours.label, len(samples), math.nan, math.nan, math.nan,
                            math.nan, len(samples), determined))
            notes[name].append(f'the package refuses to start: {_elided(str(refused))}')
            ours = None
        followers = [follower for follower in (ours, *peer_followers(model))
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
                    if follower is ours:
                        conditioning = ours.conditioning
        if ours is not None:
            notes[name].append(f"the package's largest conditioning κ = {conditioning:.3g}: "
                               f'its floor κ·ε = {conditioning * EPSILON:.1e}')
        for index, follower in enumerate(followers):
            row = follower_row(model, trajectory, follower.label, answers[index], exact,
                               times[index])
            row.determined = determined
            rows.append(row)
    return rows, notes


def _elided(problem: str) -> str:
    """Return a plan's problem line with its long lists of joints counted, for the notes."""
    return re.sub(r'\[([^\]]{60,})\]',
                  lambda match: f'[{match.group(1).count(",") + 1} names]', problem)


def _follow(follow: Callable, samples: Sequence[Sequence[float]]) -> tuple[list, list[float]]:
    answers, times = [], []
    clock = time.perf_counter
    for sample in samples:
        start = clock()
        answer = follow(sample)
        times.append(clock() - start)
        answers.append(answer)
    return answers, times


def follower_row(model: ParallelModel, trajectory: Trajectory, label: str, answers: list,
                 exact: dict[int, tuple], times: list[float]) -> Row:
    """Return a follower's row: errors at the reference's samples, failures over all."""
    prismatic = set(trajectory.prismatic)
    idle = set(trajectory.idle)
    error = idle_difference = 0.0
    failures = 0
    for index, answer in enumerate(answers):
        finite = all(map(math.isfinite, answer.positions))
        if not answer.converged or not finite:
            failures += 1
        if not finite or index not in exact:
            continue
        for name, value, wanted in zip(model.coordinates, answer.positions, exact[index]):
            # taken in the reference's type (mpf for a solved joint), then rounded
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


def table(rows: Sequence[Row], notes: dict[str, list[str]], every: int) -> str:
    """Return the section's markdown: one row per model and follower, then the notes."""
    header = ['model', 'follower', 'worst error (rad, m)', 'idle coordinates: largest difference',
              'time / sample: median', 'p90', 'not closed (own verdict)']
    lines = markdown_table(header, [
        [row.model, row.follower,
         '–' if math.isnan(row.error) else format_error(row.error),
         format_error(row.idle_difference) if row.idle_difference > 0.0 else '–',
         '–' if math.isnan(row.median_time) else f'{row.median_time * 1e6:.1f} µs',
         '–' if math.isnan(row.p90_time) else f'{row.p90_time * 1e6:.1f} µs',
         f'{row.failures} of {row.samples}'] for row in rows])
    extra = [f'- {model}: {note}' for model, texts in notes.items() for note in texts]
    return '\n'.join([f'Errors against the 50-digit reference at every {every}-th sample; '
                      'times over every sample.', '', lines, *([''] + extra if extra else [])])


def plot(rows: Sequence[Row], path: str) -> None:
    """
    Draw median time per sample against worst error, log-log: one marker per follower, model.

    Rows without figures (a follower that refused to start) and of models the actuated joints
    do not determine (no error to draw) are left out.
    """
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    rows = [row for row in rows if row.determined and not math.isnan(row.median_time)]
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
    axis.set_title('Closing parallel robots per sample, errors against a 50-digit reference '
                   '(lower left is better; hollow: some samples not closed)', fontsize=9)
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
