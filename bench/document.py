# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
docs/benchmarks.md, written from a run's figures: ``./dev bench`` writes it, nobody types one.

Each section of the document is one section of bench/run.py, between two markers, headed by the
run it comes from (date, commit, Python, machine, load, command). A run of some sections
(``--only``) rewrites those and keeps the others as their own runs left them; the text around
the figures (what a section measures and how) lives here. Each table of a section gets its own
heading, so that a reader finds one table per heading.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import datetime
import os
import pathlib
import re
import subprocess
import textwrap

ROOT = pathlib.Path(__file__).resolve().parent.parent
DOCUMENT = ROOT / 'docs' / 'benchmarks.md'
BEGIN = '<!-- bench section: {} -->'
END = '<!-- end of bench section: {} -->'
SECTION_TEXT = re.compile(r'<!-- bench section: (\w+) -->\n(.*?)<!-- end of bench section: \1 -->',
                          re.S)


@dataclass(frozen=True)
class Section:
    """A section of the document: its heading, what it measures, its tables' headings, plots."""

    heading: str
    about: str
    tables: tuple[str, ...]
    plots: tuple[tuple[str, str], ...] = ()  # (file in docs/, alternative text)


SECTIONS = {
    'kinematics': Section(
        'Kinematics: time per configuration against error',
        "The library's closed form, scalar (`kinematics.solve`) and vectorised "
        '(`kinematics.solve_many`), against what else computes the same (`bench/competitors.py`, '
        '`bench/seed_formulation.py`): a minimal hand-written closed form with no checks (the '
        "yardstick for the scalar path's overhead) and the same as whole-array numpy code (for "
        "`solve_many`'s), the paper's own equations, Newton and `scipy.optimize.root`/`fsolve` "
        'on the loop equations warm-started as a timer-driven node would, finite differences of '
        "exact positions, and pylinkage. Three sets of crank angles under both of the paper's "
        "drive laws: the paper's 0°–90° turn; down to 1e-13 rad from the paper mechanism's dead "
        "point; through a parallelogram's change point, on it included. Errors are against the "
        'independent 50-digit reference (`test/reference.py`), the largest over the set and both '
        'laws: angles in rad, rates and accelerations relative to the larger exact value; a '
        'method that returns NaN or inf at an angle counts as failed there. Times are medians of '
        "interleaved repetitions on the sweep under the variable law; the goals' ratios are "
        'medians of back-to-back pairs. The plot: time against the worst of the three errors, '
        'one point per method and setting.',
        ('Time per configuration and largest error',),
        (('benchmark_speed_error.png',
          'time per configuration against largest error, one point per method and setting'),)),
    'drive': Section(
        'The drive law in time',
        'A node ticking at a timer rate needs α at every tick: the library computes it from the '
        "elapsed time with the law's exact flow (`DriveLaw.alpha_at`); the alternative integrates "
        'dα/dt = ω0 + k·α tick by tick (explicit Euler, classical RK4). Errors are against the '
        "closed form α(t) in 50-digit mpmath at the tick's exact time, from α = 0, over the "
        '90° turn and over an hour; the cost per tick under the variable law at 1 kHz.',
        ('Error of α at the end', 'Cost per tick')),
    'tf': Section(
        "One state's /tf: prepared against generic forward kinematics",
        'For every state the node logs the `/tf` robot_state_publisher would publish for its '
        'URDF (`messages.RobotStateTransforms`: each joint prepared once per URDF), timed against '
        "the package's previous generic forward kinematics (`bench/tf_bench.py`, `GenericTF`) on "
        "the same random states, the node's URDF and a long chain; the bytes must be identical.",
        ("One state's /tf",)),
    'node': Section(
        'The node',
        "The node's timer tick and its parts against a bare rclpy publish, in one process (a "
        'listener in another process subscribes); the CPU of logging one message in the node and '
        'in its bag writer; then node processes (`bench/node_bench.py`): the share of ticks '
        "missed at each timer rate with logging on and off (from the node's own /diagnostics), "
        'timer jitter and latency to another process, and the size of the log.',
        ('Cost per tick', 'Logging one message', 'Sustained rate', 'Timer jitter and latency')),
    'cost': Section(
        'The node against a minimal hand-written publisher',
        "`linkage_node` (logging on, its bag writer's CPU included) and the rclpy node a lab "
        'would write by hand (`bench/minimal_publisher.py`: one JointState per timer tick) run '
        'side by side, at once, at the same rate, nothing subscribed (`bench/cost_bench.py`); '
        'CPU is utime + stime over the same seconds, one core = 100 %. Then the highest timer '
        'rate the node sustains with logging, missing under 1 % of its ticks, with the default '
        'placement and with `cpu_affinity:=0`, with jitter and latency there. The plot: CPU '
        'against the timer rate, both side by side at each rate.',
        ('CPU at 1 kHz', 'Sustained rate', 'Timer jitter and latency', 'CPU against rate'),
        (('benchmark_cost_rate.png', 'CPU against timer rate, linkage_node and the minimal '
          'publisher side by side'),)),
    'measured': Section(
        'The measured source against a minimal hand-written relay',
        "`bench/encoder.py` publishes the Grashof crank-rocker's crank at 1 kHz on absolute "
        'deadlines, stamped just before it is published; `linkage_node` (`source:=measured`, '
        'logging on) and `bench/minimal_relay.py` (subscribe JointState → publish JointState, '
        'what a lab writes by hand) follow it at once, and `bench/listener.py`, a third process, '
        "receives both outputs (`bench/measured_bench.py`). CPU over the listener's window (the "
        "node's with its bag writer's), latency from the encoder's stamp to the listener, a "
        "sample lost when it was published within the window and never arrived; the node's own "
        'bag says which samples it published a joint state for.',
        ('Followers side by side',)),
    'loops': Section(
        "A URDF's loops closed",
        "The measured section's run with `linkage_node` closing a URDF's four loops "
        '(`loops:=robot_description`, `bench/loops_bench.py`) on two robots of '
        "`test/loop_robots.py`: a quadruped's four four-bar knees and an excavator's three "
        "cylinder loops and bucket four-bar, the encoder publishing the robot's measured joints. "
        'First the per-sample path in this process (input bytes decoded, the loops followed, the '
        "joint_states bytes, the whole robot's /tf) against the path before each was prepared, "
        'checking both give the same fields and bytes; then each robot side by side with the '
        "relay. The run stops if the node's messages do not carry exactly the loops' passive "
        'joints.',
        ('The per-sample path in this process', 'The quadruped, side by side with the relay',
         'The excavator, side by side with the relay')),
    'biped': Section(
        "A biped's loops closed at 1 kHz: issue 29's cost goal",
        '`urdf/biped.urdf`: per leg three hip joints outside the loops, a knee driven through a '
        'planar four-bar from its motor and a parallel pitch–roll ankle on two motors (twelve '
        'measured joints, four closure groups: two planar one-degree-of-freedom knees, two '
        'two-degree-of-freedom ankles solved by Newton), walked by the encoder (each joint '
        "swinging at 0.5 Hz over a walk's range, the right leg half a period behind the left, "
        'velocities included; `bench/biped_bench.py`). First the per-sample path in this '
        'process, part by part over one period of the walk: CPU time per sample of each part '
        "(medians of interleaved runs), its share of the whole callback's, and with valgrind "
        'its instructions per sample (callgrind, counted inside the part only: they do not '
        "depend on the machine's load); the hand relay's callback with rclpy's "
        '(de)serialisation is the yardstick of its own Python work. Then the measured '
        "section's run: `linkage_node` (`loops:=robot_description`, logging on) and "
        "`bench/minimal_relay.py` follow the encoder at once; CPU of each (the node's with its "
        "bag writer's), latency from the encoder's stamp to a third process, samples lost, "
        "and from the node's own bag which samples it received and published. The goal: CPU "
        "≤ 1.0× the relay's, p99 latency ≤ the relay's + 0.5 ms, no sample lost by the node.",
        ('The per-sample path in this process, part by part',
         'Side by side with the relay')),
    'relay': Section(
        "Commands relayed to a biped's actuators: issue 30's cost goal",
        '`linkage_command_node` on `urdf/biped.urdf` (per leg three hip joints passed through, '
        "the knee through a planar four-bar to its motor, the ankle's pitch and roll to its two "
        'motors: four closure groups, twelve joints in and out; `bench/relay_bench.py`). First '
        "the relay's work per message in this process, bytes in to bytes out as the node does "
        "it: one forward command (`Float64MultiArray`, positions) beside the hand relay's "
        "callback with rclpy's deserialisation and serialisation (the yardstick's own Python "
        'work), and a 1000-point '
        '`JointTrajectory` at 100 Hz converted whole, with positions, velocities and '
        'accelerations as a planner sends them and with positions alone; the goal is the whole '
        "trajectory in less time than its first point's time_from_start, 10 ms, that is under "
        '10 µs per point. Then `bench/commander.py` publishes forward commands at 1 kHz, and '
        '`linkage_command_node` (logging on) and `bench/minimal_command_relay.py` (what a lab '
        "writes by hand: each value times a constant ratio, rclpy's default executor) relay "
        'them at once; `bench/command_listener.py`, a third process, receives both outputs. CPU '
        "over the listener's window (the node's with its bag writer's), latency from just before "
        'the commander published to the listener, a command lost when it was published within '
        "the window and its answer never arrived; the node's own bag says which commands it "
        "received and relayed. The goals: CPU ≤ 1.0× the hand relay's, p99 latency ≤ the hand "
        "relay's + 0.5 ms, no command lost. Figures measured while other work ran on the "
        "machine are provisional: the run's line gives the load.",
        ("The relay's work per message in this process", 'Side by side with the hand relay')),
    'parallel': Section(
        'Parallel robots closed per sample, against the peers',
        "The package's general closure (`loops.newton.GroupSolver`, built as the node builds "
        "it: the URDF and its closure file read once, the tree with the file's joint "
        'overrides, the closure groups of the actuated joints, each group planned at the '
        'assembled pose; `bench/parallel_ours.py`) beside what labs use instead: Pinocchio '
        "with a short Gauss–Newton loop on the closures (stopped at 1e-12 or 10 steps), PlaCo's "
        'kinematics solver with soft closure tasks (one QP step per sample, as its examples, '
        "and steps to 1e-12) and toolbox-parallel-robots' SLSQP closure "
        '(`bench/parallel_peers.py`; the peers are pinned in `bench/requirements-peers.txt` '
        'and installed on first use). The models: the humanoid ankle (`urdf/humanoid_ankle.urdf`, '
        "motors measured) and Gepetto/example-parallel-robots' (`test/models/`), each from its "
        'own URDF and closure file; kangaroo_like is left out, as no assembly of it was found. '
        'The motion: sinusoids of the actuated joints about an assembled pose that Pinocchio '
        'found (`bench/parallel_trajectories.json`), every follower warm started sample after '
        'sample from its previous answer. Errors: the worst over the joints the actuated ones '
        'determine, in rad or m, against the independent 50-digit reference '
        '(`test/closure_reference.py`, `bench/parallel_reference.py`) at every k-th sample, '
        'started from the assembly a continuation keeps; the joints of idle freedoms (a rod '
        'spinning about its axis, collinear pins), whose value is a convention, apart: the '
        'reference and the package hold them at the assembled pose, minimum-norm steps let them '
        "drift. The package computes the passive joints' velocities too (its time includes "
        'them), the peers positions only. Not closed: the samples the follower itself did not '
        "close (the package's refusals, a peer's own convergence test) or answered with a "
        "non-finite value; errors count the package's answered samples only, and every answer "
        "of a peer. The notes give the package's largest conditioning κ: its floor is κ·ε. "
        'The plot: median time per sample against the worst error, one point per model and '
        'follower, but for a model its actuated joints do not determine.',
        ('Per model and follower',),
        (('benchmark_parallel.png', 'time per sample against worst error, one point per model '
          'and follower'),)),
    'memory': Section(
        'Memory over a long run',
        'Resident memory of a node at 1 kHz with logging on, with its bag writer process, from '
        'start to the end of the run.',
        ('Resident memory',)),
}


@dataclass(frozen=True)
class Run:
    """What the figures were measured with: the commit, the machine (with Python), the command."""

    commit: str
    machine: str
    command: str

    @staticmethod
    def now(machine: str, command: str) -> Run:
        """Return this run: the working tree's commit, ``machine`` and ``command``."""
        return Run(commit_of(ROOT), machine, command)


@dataclass(frozen=True)
class Measured:
    """One section's markdown, one string per part of the run, and when it was measured."""

    parts: tuple[str, ...]
    started: datetime.datetime
    load_after: tuple[float, float, float] = field(default_factory=os.getloadavg)

    @staticmethod
    def clock() -> datetime.datetime:
        """Return the time now, in UTC."""
        return datetime.datetime.now(datetime.timezone.utc)

    def line(self, run: Run) -> str:
        """Return the section's run line: date, commit, machine and Python, load, command."""
        load = ', '.join(f'{value:.2f}' for value in self.load_after)
        return (f'*Measured {self.started:%Y-%m-%d %H:%M} UTC at commit {run.commit} on '
                f'{run.machine}; load average after the section {load}; by `{run.command}`.*')


def commit_of(root: pathlib.Path) -> str:
    """Return the short commit of the tree at ``root``, and whether it has changes beside it."""
    def git(*arguments: str) -> str:
        return subprocess.run(['git', '-C', str(root), *arguments], capture_output=True,
                              text=True, check=False).stdout.strip()

    commit = git('rev-parse', '--short', 'HEAD') or 'unknown (no git)'
    changed = git('status', '--porcelain', '--untracked-files=no')
    return f'`{commit}`' + (' with uncommitted changes' if changed else '')


def split_tables(output: str) -> list[str]:
    """
    Split a section's markdown into parts of one table each.

    A part starts with the prose paragraph just before its table (its caption), if any, and
    holds what follows the table up to the next part; text before the first part joins it.
    """
    paragraphs = [paragraph.strip('\n') for paragraph in re.split(r'\n\s*\n', output.strip())]
    is_table = [paragraph.startswith('|') for paragraph in paragraphs]
    starts = []
    for index, table in enumerate(is_table):
        if table:
            caption = index > 0 and not is_table[index - 1] and not paragraphs[
                index - 1].startswith('- ') and (not starts or starts[-1] < index - 1)
            starts.append(index - 1 if caption else index)
    if not starts:
        return ['\n\n'.join(paragraphs)]
    starts[0] = 0
    bounds = starts + [len(paragraphs)]
    return ['\n\n'.join(paragraphs[begin:end]) for begin, end in zip(bounds, bounds[1:])]


def render(key: str, run: Run, measured: Measured) -> str:
    """Return the document's section ``key`` from the run's markdown for it."""
    section = SECTIONS[key]
    parts = [table for part in measured.parts for table in split_tables(part)]
    titles = (section.tables if len(section.tables) == len(parts)
              else tuple(f'Table {number}' for number in range(1, len(parts) + 1)))
    lines = [BEGIN.format(key), f'## {section.heading}', '', wrapped(measured.line(run)), '',
             wrapped(section.about), '']
    for title, part in zip(titles, parts):
        if len(parts) > 1:
            lines += [f'### {title}', '']
        lines += [part, '']
    for file, text in section.plots:
        lines += [f'![{text}]({file})', '']
    lines.append(END.format(key))
    return '\n'.join(lines)


def wrapped(text: str) -> str:
    """Return a paragraph in lines of at most 99 characters, as the documents are written."""
    return textwrap.fill(text, width=99, break_long_words=False, break_on_hyphens=False)


def head() -> str:
    """Return the document's opening: what it is, how to rerun it, where the history is."""
    contents = '\n'.join(f'- [{section.heading}](#{anchor(section.heading)})'
                         for section in SECTIONS.values())
    return f"""# Benchmarks: speed, error and cost

<!-- Written by ./dev bench (bench/document.py) from the run's figures: change the text there. -->

Today's figures. Every table and plot below comes from the `./dev bench` run its section names
(date, commit, Python, machine, load); `./dev bench --only SECTION` reruns one section and
rewrites only its part. Earlier figures are in this file's git history
(`git log -p docs/benchmarks.md`).

<!-- not run: every section takes about 25 minutes (the memory run 10, the parallel one 10) -->
```bash
./dev bench                        # every section, written here
./dev bench --quick                # about 7 minutes: fewer angles, shorter runs
./dev bench --only cost            # one section (kinematics, drive, tf, node, cost, measured,
                                   # loops, biped, relay, parallel, memory)
./dev bench --only node --no-document   # print only
```

[bench/README.md](../bench/README.md) lists the options and files. Benchmarks are not tests:
nothing asserts a time. Timings interleave the compared methods round-robin in one process and
quote medians, so that each sees the same drift of a shared machine: compare the ratios, which
hold from run to run, more than the absolute times.

{contents}
"""


def anchor(heading: str) -> str:
    """Return GitHub's anchor of a heading."""
    return re.sub(r'[^\w\- ]', '', heading.lower()).replace(' ', '-')


def write(path: pathlib.Path, run: Run, outputs: dict[str, Measured]) -> None:
    """
    Write the document at ``path`` with the sections in ``outputs``, measured in ``run``.

    The sections not run keep their part of the document as it is, or say how to run them.
    """
    kept = dict(SECTION_TEXT.findall(path.read_text(encoding='utf-8'))) if path.exists() else {}
    parts = [head()]
    for key, section in SECTIONS.items():
        if key in outputs:
            parts.append(render(key, run, outputs[key]))
        elif key in kept:
            parts.append(BEGIN.format(key) + '\n' + kept[key] + END.format(key))
        else:
            parts.append('\n'.join([
                BEGIN.format(key), f'## {section.heading}', '',
                f'Not measured yet: `./dev bench --only {key}`.', '', END.format(key)]))
    path.write_text('\n\n'.join(part.strip('\n') for part in parts) + '\n', encoding='utf-8')


if __name__ == '__main__':
    # After a change of the text above: the document's text around its sections, rewritten
    # with every section's figures kept as they are (no benchmark runs).
    write(DOCUMENT, Run('', '', ''), {})
    print(f'{DOCUMENT} rewritten around its sections')
