# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The parallel section's peers from PyPI: installed on first use, outside the project's venv.

``./dev bench`` (the parallel section) calls ``activate(install=True)``: the first time, or when
bench/requirements-peers.txt changed, it runs ``pip install --no-deps --target`` of that file
into ``.bench-peers/pythonX.Y`` beside the venv, then adds that folder to ``sys.path`` as a site
folder (its ``cmeel.pth`` puts the cmeel prefix, where pinocchio and placo live, on the path).
The venv that ``./dev test`` uses never holds them (about 400 MB); a test of the adapters
activates the folder if a bench run installed it, and is skipped otherwise.

toolbox-parallel-robots 1.2.0 from PyPI does not import as published (``import_toolbox``):
its package imports ``casadi``, ``pinocchio.casadi`` and ``qpsolvers`` at module level,
none of which it declares, and PyPI's ``pin`` wheels are built without Pinocchio's CasADi
bindings, so no install from PyPI provides ``pinocchio.casadi``. Only its CasADi and QP paths
use them; its SLSQP closure (``closedLoopForwardKinematicsScipy``) needs neither, but ``scipy``
(also undeclared; the project's venv has it).
"""

from __future__ import annotations

from importlib import metadata
import os
import pathlib
import site
import subprocess
import sys
import types

ROOT = pathlib.Path(__file__).resolve().parent.parent
REQUIREMENTS = ROOT / 'bench' / 'requirements-peers.txt'
PEERS_FOLDER = ROOT / '.bench-peers' / f'python{sys.version_info.major}.{sys.version_info.minor}'
# The copy of the requirements the folder was installed from (as ./dev keeps the venv's).
STAMP = PEERS_FOLDER / '.installed-requirements'
PACKAGES = ('pin', 'placo', 'toolbox-parallel-robots')
# What toolbox-parallel-robots imports at module level and PyPI does not give it (see above).
TOOLBOX_MISSING = ('casadi', 'pinocchio.casadi', 'qpsolvers')


class PeersMissing(RuntimeError):
    """The peers are not installed, or do not import; the message says which and why."""


def activate(install: bool) -> dict[str, str]:
    """
    Put the peers on ``sys.path`` and return their versions by package name.

    With ``install``, install them first if the folder is missing or was installed from other
    requirements. PeersMissing if they are still not there or do not import.
    """
    wanted = REQUIREMENTS.read_text()
    current = STAMP.read_text() if STAMP.exists() else None
    if install and current != wanted:
        print(f'installing the peers ({REQUIREMENTS.name}) into {PEERS_FOLDER} ...', flush=True)
        subprocess.run([sys.executable, '-m', 'pip', 'install', '--quiet', '--no-deps',
                        '--upgrade', '--target', str(PEERS_FOLDER), '-r', str(REQUIREMENTS)],
                       check=True)
        STAMP.write_text(wanted)
        current = wanted
    if current is None:
        raise PeersMissing(f'the peers are not installed in {PEERS_FOLDER} '
                           '(./dev bench --only parallel installs them)')
    if str(PEERS_FOLDER) not in sys.path:
        site.addsitedir(str(PEERS_FOLDER))
    try:
        import pinocchio  # noqa: F401
        import placo  # noqa: F401
    except ImportError as error:
        raise PeersMissing(f'the peers do not import: {error}') from None
    return {package: metadata.version(package) for package in PACKAGES}


def _absent(name: str) -> types.ModuleType:
    """
    Return a module ``name`` whose every attribute refuses use: what PyPI does not provide.

    A capitalised attribute is a class no object is an instance of (the toolbox's ``mergeq`` asks
    ``isinstance(model, pin.casadi.Model)``), whose construction raises; any other a function
    that raises. Both raise PeersMissing naming the attribute.
    """
    module = types.ModuleType(name, f'{name}: not available from PyPI (bench/peers.py)')

    def refuse(attribute: str) -> None:
        raise PeersMissing(f'{name}.{attribute} is not available from PyPI; '
                           'toolbox-parallel-robots is used through its SLSQP path only')

    def missing(attribute: str) -> object:
        if attribute.startswith('__'):
            raise AttributeError(attribute)
        if attribute[:1].isupper():
            return type(attribute, (), {'__init__': lambda self, *_, **__: refuse(attribute)})
        return lambda *_, **__: refuse(attribute)

    module.__getattr__ = missing
    return module


def import_toolbox() -> types.ModuleType:
    """
    Import toolbox_parallel_robots, giving it stand-ins for the modules PyPI does not provide.

    Each stand-in raises on use; the toolbox's forward kinematics then reports CasADi present,
    so the bench calls ``closedLoopForwardKinematicsScipy`` itself (its documented SLSQP
    closure), never the dispatching ``closedLoopForwardKinematics``.
    """
    import pinocchio

    for name in TOOLBOX_MISSING:
        if name not in sys.modules:
            try:
                __import__(name)
            except ImportError:
                sys.modules[name] = _absent(name)
    if not hasattr(pinocchio, 'casadi'):
        pinocchio.casadi = sys.modules['pinocchio.casadi']
    import toolbox_parallel_robots

    return toolbox_parallel_robots


def peers_available() -> bool:
    """Return whether a bench run installed the peers for this Python (tests skip without)."""
    return STAMP.exists() and os.access(PEERS_FOLDER, os.R_OK)
