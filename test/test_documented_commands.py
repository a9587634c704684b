# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The shell and console blocks of README.md, CONTRIBUTING.md and docs/*.md, run as written.

A ```` ```bash ```` block must succeed as a whole; a ```` ```console ```` block's ``$ `` lines
must each succeed and print what the block shows after them (stdout and stderr as a terminal
shows them). A block preceded by ``<!-- not run: REASON -->`` is skipped with that reason (it
needs a ROS 2 install, a lab's robot, a bag of one's own, minutes); one preceded by
``<!-- runs until stopped: the test stops it once it prints "TEXT" -->`` is a process that runs
until Ctrl-C (a node): it must print TEXT, and end cleanly on SIGINT.

The blocks run in a copy of the repository's layout (its files linked, so that what a command
writes stays out of the tree), in the test's own ROS domain, with ``./dev run CMD`` done by a
stand-in that runs CMD in this environment (the real one would reinstall the package first), the
package's console scripts run from the tree, and ``.venv/bin/python`` this interpreter.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib.metadata import entry_points
import os
from pathlib import Path
import re
import selectors
import shlex
import signal
import subprocess
import sys
import time

from node_process import ros_environment
import pytest

REPOSITORY = Path(__file__).resolve().parent.parent
DOCUMENTS = [REPOSITORY / 'README.md', REPOSITORY / 'CONTRIBUTING.md',
             *sorted((REPOSITORY / 'docs').glob('*.md'))]
SHELL_LANGUAGES = ('bash', 'console')
FENCE = re.compile(r'^(\s*)```(\S*)\s*$')
NOT_RUN = re.compile(r'^\s*<!-- not run: (\S.*?) -->\s*$')
RUNS_UNTIL = re.compile(
    r'^\s*<!-- runs until stopped: the test stops it once it prints "([^"]+)" -->\s*$')
MARKER = re.compile(r'^\s*<!-- (not run|runs until)')
# What the copy of the layout leaves out: the environment, the build and the bags of the tree.
NOT_LINKED = {'.git', '.venv', 'bags', 'build', 'install', 'log', '.pytest_cache', '.hypothesis'}
COMMAND_TIMEOUT = 300.0  # s, one block; the slowest (an accuracy script) takes about 10 s
START_TIMEOUT = 60.0  # s, for a node to print what its block waits for
DEV_STAND_IN = """#!/bin/sh
# The test's stand-in for ./dev: `./dev run CMD` runs CMD in the test's environment.
[ "$1" = run ] || { echo "./dev $1: only ./dev run is run by the documents' test" >&2; exit 2; }
shift
exec "$@"
"""


@dataclass(frozen=True)
class Block:
    """One shell or console block of a document, and how the document says to run it."""

    document: Path
    line: int  # of the opening fence, 1-based
    language: str
    text: str
    not_run: str | None = None  # the reason the document gives
    runs_until: str | None = None  # the output after which the test stops the process

    @property
    def name(self) -> str:
        return f'{self.document.relative_to(REPOSITORY)}:{self.line}'


def blocks_of(document: Path) -> list[Block]:
    """Return the document's shell and console blocks with the marker before each, if any."""
    lines = document.read_text(encoding='utf-8').splitlines()
    blocks = []
    index = 0
    while index < len(lines):
        fence = FENCE.match(lines[index])
        if fence is None:
            index += 1
            continue
        indent, language = fence.groups()
        end = index + 1
        while end < len(lines) and lines[end].strip() != '```':
            end += 1
        if language in SHELL_LANGUAGES:
            text = '\n'.join(line[len(indent):] for line in lines[index + 1:end]) + '\n'
            before = next((line for line in reversed(lines[:index]) if line.strip()), '')
            not_run, runs_until = NOT_RUN.match(before), RUNS_UNTIL.match(before)
            blocks.append(Block(document, index + 1, language, text,
                                not_run[1] if not_run else None,
                                runs_until[1] if runs_until else None))
        index = end + 1
    return blocks


def markers_without_a_block(document: Path) -> list[str]:
    """Return each marker not followed by a shell or console block, or not understood."""
    lines = document.read_text(encoding='utf-8').splitlines()
    problems = []
    for index, line in enumerate(lines):
        if not MARKER.match(line):
            continue
        if not (NOT_RUN.match(line) or RUNS_UNTIL.match(line)):
            problems.append(f'{document.name}:{index + 1}: marker not understood: {line.strip()}')
            continue
        following = next((later for later in lines[index + 1:] if later.strip()), '')
        fence = FENCE.match(following)
        if fence is None or fence[2] not in SHELL_LANGUAGES:
            problems.append(f'{document.name}:{index + 1}: marker without a shell block after it')
    return problems


ALL_BLOCKS = [block for document in DOCUMENTS for block in blocks_of(document)]


def console_commands(text: str) -> list[tuple[str, str]]:
    """Return a console block's (command, expected output) pairs; output lines follow ``$ ``."""
    pairs: list[tuple[str, list[str]]] = []
    for line in text.splitlines():
        if line.startswith('$ '):
            pairs.append((line[2:], []))
        elif pairs:
            pairs[-1][1].append(line)
        else:
            raise ValueError(f'a console block starts with output, not a "$ " line: {line!r}')
    return [(command, '\n'.join(output)) for command, output in pairs]


def layout(folder: Path) -> dict[str, str]:
    """Make ``folder`` the repository as a user has it; return the environment to run in."""
    for entry in REPOSITORY.iterdir():
        if entry.name not in NOT_LINKED and entry.name != 'dev':
            (folder / entry.name).symlink_to(entry)
    (folder / 'dev').write_text(DEV_STAND_IN)
    scripts = folder / '.venv' / 'bin'
    scripts.mkdir(parents=True)
    # each of the package's console scripts as pip writes it, run by this interpreter
    programs = {'python': f'#!/bin/sh\nexec {shlex.quote(sys.executable)} "$@"\n'}
    for script in entry_points(group='console_scripts'):
        if script.value.startswith('linkage_kinematics.'):
            module, function = script.value.split(':')
            programs[script.name] = (f'#!{sys.executable}\nimport sys\nfrom {module} import '
                                     f'{function}\nsys.exit({function}())\n')
    assert {'linkage_node', 'linkage-check-loops', 'linkage-sweep'} <= set(programs), programs
    for name, text in programs.items():
        (scripts / name).write_text(text)
    for program in [folder / 'dev', *scripts.iterdir()]:
        program.chmod(0o755)
    return {'PATH': f'{scripts}{os.pathsep}{os.environ["PATH"]}',
            'PYTHONPATH': str(REPOSITORY), 'PYTHONUNBUFFERED': '1'}


def run_shell(command: str, folder: Path, environment: dict[str, str], errexit: bool = True
              ) -> tuple[int, str]:
    """Run ``command`` with bash (pipefail; errexit for a script) in ``folder``: status, output."""
    options = ['-e', '-o', 'pipefail'] if errexit else ['-o', 'pipefail']
    done = subprocess.run(['bash', *options, '-c', command], cwd=folder,
                          env=environment, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=COMMAND_TIMEOUT)
    return done.returncode, done.stdout


def problems_of_console(block: Block, folder: Path, environment: dict[str, str]) -> list[str]:
    """Return how each command's status or output differs from what the block shows."""
    problems = []
    for command, expected in console_commands(block.text):
        # as typed at a prompt: a failing command of a list does not end it
        status, output = run_shell(command, folder, environment, errexit=False)
        if status != 0:
            problems.append(f'$ {command}\nexited with status {status}:\n{output}')
        elif output.rstrip('\n') != expected:
            problems.append(f'$ {command}\nprinted:\n{output}\nwhere the document shows:\n'
                            f'{expected}')
    return problems


def problems_of_bash(block: Block, folder: Path, environment: dict[str, str]) -> list[str]:
    """Return the block's failure, if it fails."""
    status, output = run_shell(block.text, folder, environment)
    return [] if status == 0 else [f'exited with status {status}:\n{output}']


def problems_of_running(block: Block, folder: Path, environment: dict[str, str]) -> list[str]:
    """Start the block, wait for its text, stop it with SIGINT: what went wrong, if anything."""
    process = subprocess.Popen(['bash', '-e', '-o', 'pipefail', '-c', block.text], cwd=folder,
                               env=environment, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, start_new_session=True)
    output = b''
    deadline = time.monotonic() + START_TIMEOUT
    with selectors.DefaultSelector() as selector:
        selector.register(process.stdout, selectors.EVENT_READ)
        while block.runs_until.encode() not in output and time.monotonic() < deadline:
            if selector.select(timeout=0.1):
                chunk = os.read(process.stdout.fileno(), 65536)
                if not chunk:  # the process ended before it printed the text
                    break
                output += chunk
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGINT)
    try:
        rest, _ = process.communicate(timeout=START_TIMEOUT)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        rest, _ = process.communicate()
    text = (output + rest).decode(errors='replace')
    problems = []
    if block.runs_until not in text:
        problems.append(f'never printed {block.runs_until!r}')
    if process.returncode != 0:
        problems.append(f'ended with status {process.returncode} on SIGINT')
    return problems + ([f'its output:\n{text}'] if problems else [])


def problems_of(block: Block, folder: Path, environment: dict[str, str]) -> list[str]:
    """Run a block as its document says; return what differs from what it says."""
    if block.runs_until is not None:
        return problems_of_running(block, folder, environment)
    if block.language == 'console':
        return problems_of_console(block, folder, environment)
    return problems_of_bash(block, folder, environment)


@pytest.fixture(scope='module')
def user_folder(tmp_path_factory: pytest.TempPathFactory, domain_id: int
                ) -> tuple[Path, dict[str, str]]:
    """Return a copy of the repository's layout and the environment the blocks run in."""
    folder = tmp_path_factory.mktemp('documented_commands')
    environment = ros_environment(domain_id)
    environment.update(layout(folder))
    return folder, environment


@pytest.mark.parametrize('block', ALL_BLOCKS, ids=lambda block: block.name)
def test_the_documented_block_runs_as_written(block: Block, user_folder) -> None:
    if block.not_run is not None:
        pytest.skip(f'not run, as the document says: {block.not_run}')
    problems = problems_of(block, *user_folder)
    assert not problems, f'{block.name} ({block.language}):\n' + '\n'.join(problems)


def test_every_marker_stands_before_a_shell_block() -> None:
    problems = [problem for document in DOCUMENTS for problem in markers_without_a_block(document)]
    assert problems == []


def test_the_documents_hold_blocks_the_test_runs() -> None:
    # An empty or misread set of blocks would pass every test above for the wrong reason.
    run = [block for block in ALL_BLOCKS if block.not_run is None]
    assert {block.document.name for block in run} >= {
        'README.md', 'following_loops.md', 'kinematics.md'}
    assert {block.language for block in run} == {'bash', 'console'}
    assert any(block.runs_until for block in run)
    assert all(block.not_run.strip() for block in ALL_BLOCKS if block.not_run is not None)


# --- the runner itself, on blocks made to fail ------------------------------------------------

def made_block(language: str, text: str, runs_until: str | None = None) -> Block:
    return Block(REPOSITORY / 'README.md', 1, language, text, runs_until=runs_until)


@pytest.mark.parametrize(('language', 'text', 'expected'), [
    ('console', '$ echo one\none\n$ echo two\ntwo\n', []),
    ('console', '$ echo one\ntwo\n', ['printed']),
    ('console', '$ false\n', ['exited with status 1']),
    ('console', '$ false; echo "exit status $?"\nexit status 1\n', []),
    ('console', '$ ./dev run linkage-check-loops nothing.urdf; echo "exit status $?"\n'
                'linkage-check-loops: cannot read nothing.urdf: [Errno 2] No such file or '
                "directory: 'nothing.urdf'\nexit status 2\n", []),
    ('bash', 'true\nfalse\ntrue\n', ['exited with status 1']),
    ('bash', 'test -L urdf && test ! -e .git && python -c "import sys"\n', []),
    ('bash', './dev test\n', ['exited with status 2']),
])
def test_the_runner_reports_what_differs(language: str, text: str, expected: list[str],
                                         user_folder) -> None:
    problems = problems_of(made_block(language, text), *user_folder)
    assert [problem for problem in problems
            if not any(part in problem for part in expected)] == []
    assert len(problems) == len(expected)


def test_the_runner_stops_a_process_and_reports_one_that_never_prints_its_text(
        user_folder) -> None:
    script = 'trap "exit 0" INT; echo started; while true; do sleep 0.1; done\n'
    assert problems_of(made_block('bash', script, runs_until='started'), *user_folder) == []
    problems = problems_of(made_block('bash', 'echo other; exit 3\n', runs_until='started'),
                           *user_folder)
    assert problems[:2] == ["never printed 'started'", 'ended with status 3 on SIGINT']


def test_a_console_block_must_start_with_a_command() -> None:
    with pytest.raises(ValueError, match='starts with output'):
        console_commands('output\n$ echo\n')
