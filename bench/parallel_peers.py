# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Other ways to close a robot's loops per sample, for the parallel section (bench/parallel_bench.py).

Each follower is built from a ``ParallelModel`` (bench/parallel_models.py), is started at an
assembled pose (``start``: every coordinate by name), and then closes the loops for one sample of
the actuated joints at a time (``follow``: their values in ``model.actuated``'s order), warm
started from its previous answer as a real follower would be. An ``Answer`` holds every
coordinate's value in ``model.coordinates``' order and whether the follower itself reports
convergence. Needs the peers (bench/peers.py ``activate``) on ``sys.path``.

* ``PinocchioGaussNewton``: Pinocchio's forward kinematics and frame Jacobians of the closure
  frames, Gauss–Newton on the passive coordinates with the actuated ones fixed: residual of a weld
  log6 of the relative placement, of a ball the difference of the origins; minimum-norm steps
  (least squares, so that redundant rows and idle freedoms need no special care); stopped when
  the largest residual component is below ``tolerance`` (1e-12 m or rad) or after ``iterations``
  (10) steps, which is then a convergence failure.
* ``PlacoClosure``: PlaCo's kinematics solver as PlaCo's examples close loops: a relative frame
  task (weld) or relative position task (ball) per closure, soft with weight 1 (the issue's
  measurement), the actuated joints masked at their sample's values, the floating base masked,
  joint limits off (the models' limits are the exporter's, not the mechanism's); ``steps`` QP
  steps per sample: 1, as PlaCo's examples take one per control tick, or until the largest task
  error is below ``tolerance`` (at most ``steps``).
* ``ToolboxSlsqp``: toolbox-parallel-robots' ``closedLoopForwardKinematicsScipy`` (scipy's SLSQP
  with its defaults: minimise the change of the free coordinates subject to the closures) with
  Pinocchio constraint models built as example-parallel-robots' loader builds them. Workarounds,
  each needed to run it from PyPI with numpy 2 (bench/peers.py for the import): ``q_prec`` is
  handed in a wrapper, as the function's ``q_prec == []`` test raises for an array under numpy 2;
  its ``fmin_slsqp`` is called with ``iprint=0`` (it prints four lines per sample otherwise) and
  ``full_output`` so that SLSQP's exit mode is kept (mode 0 is convergence), the same search
  otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
import pathlib
import tempfile
from typing import Callable, Mapping, Protocol, Sequence

from linkage_kinematics.loops.closures import ClosureKind
import numpy as np
from parallel_models import ParallelModel

GAUSS_NEWTON_TOLERANCE = 1e-12
GAUSS_NEWTON_ITERATIONS = 10


@dataclass(frozen=True)
class Answer:
    """A follower's answer to one sample: every coordinate's value, and its own verdict."""

    positions: tuple[float, ...]
    converged: bool


class Follower(Protocol):
    """What the section times: a per-sample closure of one model's loops."""

    label: str

    def start(self, pose: Mapping[str, float]) -> None:
        """Take ``pose`` (every coordinate by name) as the previous answer."""

    def follow(self, actuated: Sequence[float]) -> Answer:
        """Close the loops for the actuated joints' values ``actuated``."""


class PinocchioTree:
    """Pinocchio's model of a ``ParallelModel``'s URDF: coordinates' indices, closure residuals."""

    def __init__(self, model: ParallelModel) -> None:
        import pinocchio

        self.pinocchio = pinocchio
        self.model = pinocchio.buildModelFromXML(model.urdf)
        self.data = self.model.createData()
        index = {name: self.model.joints[self.model.getJointId(name)].idx_q
                 for name in model.coordinates}
        self.coordinates = model.coordinates
        self.order = np.array([index[name] for name in model.coordinates])
        self.actuated = np.array([index[name] for name in model.actuated])
        self.passive = np.array([index[name] for name in model.passive])
        self.closures = [(closure.kind, self.frame(closure.parent_frame),
                          self.frame(closure.child_frame)) for closure in model.closures]
        self.rows = sum(6 if kind is ClosureKind.WELD else 3 for kind, _, _ in self.closures)

    def frame(self, name: str) -> int:
        """Return the id of the frame of link ``name``."""
        return self.model.getFrameId(name, self.pinocchio.FrameType.BODY)

    def configuration(self, pose: Mapping[str, float]) -> np.ndarray:
        """Return Pinocchio's q of a pose given by coordinate name."""
        q = self.pinocchio.neutral(self.model)
        q[self.order] = [pose[name] for name in self.coordinates]
        return q

    def positions(self, q: np.ndarray) -> tuple[float, ...]:
        """Return q's values in the model's coordinate order."""
        return tuple(q[self.order].tolist())

    def residual(self, q: np.ndarray, jacobian: bool = True
                 ) -> tuple[np.ndarray, np.ndarray | None]:
        """Return the closures' residual at q and (with ``jacobian``) its Jacobian (all of q)."""
        pinocchio = self.pinocchio
        model, data = self.model, self.data
        if jacobian:
            pinocchio.computeJointJacobians(model, data, q)
        else:
            pinocchio.forwardKinematics(model, data, q)
        pinocchio.updateFramePlacements(model, data)
        values = np.empty(self.rows)
        rows = np.empty((self.rows, model.nv)) if jacobian else None
        row = 0
        for kind, first, second in self.closures:
            placement_1, placement_2 = data.oMf[first], data.oMf[second]
            if kind is ClosureKind.WELD:
                relative = placement_1.actInv(placement_2)
                values[row:row + 6] = pinocchio.log6(relative).vector
                if jacobian:
                    local = pinocchio.ReferenceFrame.LOCAL
                    jacobian_1 = pinocchio.getFrameJacobian(model, data, first, local)
                    jacobian_2 = pinocchio.getFrameJacobian(model, data, second, local)
                    rows[row:row + 6] = pinocchio.Jlog6(relative) @ (
                        jacobian_2 - relative.inverse().action @ jacobian_1)
                row += 6
            else:
                values[row:row + 3] = placement_1.translation - placement_2.translation
                if jacobian:
                    aligned = pinocchio.ReferenceFrame.LOCAL_WORLD_ALIGNED
                    rows[row:row + 3] = (
                        pinocchio.getFrameJacobian(model, data, first, aligned)[:3]
                        - pinocchio.getFrameJacobian(model, data, second, aligned)[:3])
                row += 3
        return values, rows


class PinocchioGaussNewton:
    """Pinocchio's kinematics closed by Gauss–Newton on the passive coordinates (module text)."""

    def __init__(self, model: ParallelModel, tolerance: float = GAUSS_NEWTON_TOLERANCE,
                 iterations: int = GAUSS_NEWTON_ITERATIONS) -> None:
        import pinocchio

        self.tree = PinocchioTree(model)
        self.tolerance = tolerance
        self.iterations = iterations
        self.label = f'Pinocchio {pinocchio.__version__} + Gauss–Newton'
        self.q = self.tree.configuration(dict.fromkeys(model.coordinates, 0.0))

    def start(self, pose: Mapping[str, float]) -> None:
        """Take ``pose`` as the previous answer."""
        self.q = self.tree.configuration(pose)

    def follow(self, actuated: Sequence[float]) -> Answer:
        """Gauss–Newton from the previous answer with the actuated coordinates at ``actuated``."""
        tree, q = self.tree, self.q
        q[tree.actuated] = actuated
        converged = False
        for iteration in range(self.iterations + 1):
            values, rows = tree.residual(q, iteration < self.iterations)
            if float(np.max(np.abs(values))) < self.tolerance:
                converged = True
                break
            if rows is not None:
                step = np.linalg.lstsq(rows[:, tree.passive], values, rcond=None)[0]
                q[tree.passive] -= step
        return Answer(tree.positions(q), converged)


class PlacoClosure:
    """PlaCo's kinematics solver with soft closure tasks (module text)."""

    def __init__(self, model: ParallelModel, steps: int = 1,
                 tolerance: float = GAUSS_NEWTON_TOLERANCE, weight: float = 1.0) -> None:
        from importlib import metadata

        import placo

        with tempfile.TemporaryDirectory() as folder:
            path = pathlib.Path(folder) / 'robot.urdf'
            path.write_text(model.urdf)
            self.robot = placo.RobotWrapper(str(path), placo.Flags.ignore_collisions)
        self.solver = placo.KinematicsSolver(self.robot)
        self.solver.mask_fbase(True)
        self.solver.enable_joint_limits(False)
        self.tasks = []
        for closure in model.closures:
            if closure.kind is ClosureKind.WELD:
                task = self.solver.add_relative_frame_task(
                    closure.parent_frame, closure.child_frame, np.eye(4))
                task.configure(closure.name, 'soft', weight, weight)
                self.tasks += [task.position(), task.orientation()]
            else:
                task = self.solver.add_relative_position_task(
                    closure.parent_frame, closure.child_frame, np.zeros(3))
                task.configure(closure.name, 'soft', weight)
                self.tasks.append(task)
        for joint in model.actuated:
            self.solver.mask_dof(joint)
        self.model = model
        self.steps = steps
        self.tolerance = tolerance
        offsets = {name: self.robot.get_joint_offset(name) for name in model.coordinates}
        self.order = np.array([offsets[name] for name in model.coordinates])
        self.label = f"PlaCo {metadata.version('placo')}, " + (
            'one QP step per sample' if steps == 1
            else f'QP steps to {tolerance:g} (at most {steps})')

    def start(self, pose: Mapping[str, float]) -> None:
        """Take ``pose`` as the previous answer."""
        for name, value in pose.items():
            self.robot.set_joint(name, value)

    def follow(self, actuated: Sequence[float]) -> Answer:
        """Take ``steps`` QP steps (or fewer, to ``tolerance``) from the previous answer."""
        robot, solver = self.robot, self.solver
        for name, value in zip(self.model.actuated, actuated):
            robot.set_joint(name, value)
        converged = False
        for _ in range(self.steps):
            robot.update_kinematics()
            solver.solve(True)
            robot.update_kinematics()
            if self._error() < self.tolerance:
                converged = True
                break
        return Answer(tuple(robot.state.q[self.order].tolist()), converged)

    def _error(self) -> float:
        """Return the largest closure task error (PlaCo's own: m, rad) at the robot's state."""
        largest = 0.0
        for task in self.tasks:
            task.update()
            largest = max(largest, float(np.max(np.abs(task.error()))))
        return largest


class _WarmStart:
    """
    A previous configuration as toolbox-parallel-robots' SLSQP closure can take it.

    ``closedLoopForwardKinematicsScipy`` tests ``q_prec == []``, an error for a numpy array under
    numpy 2 (a shape mismatch, no longer a warning); this answers that test with False and
    indexes as the array.
    """

    def __init__(self, q: np.ndarray) -> None:
        self.q = q

    def __eq__(self, other: object) -> bool:
        return False

    __hash__ = None

    def __getitem__(self, index: object) -> np.ndarray:
        return self.q[index]


class _QuietSlsqp:
    """Scipy's fmin_slsqp as the toolbox calls it, with iprint=0, keeping the last exit mode."""

    def __init__(self, fmin_slsqp: Callable[..., tuple]) -> None:
        self.fmin_slsqp = fmin_slsqp
        self.mode = -1

    def __call__(self, *arguments: object, **keywords: object) -> np.ndarray:
        solution, _, _, mode, _ = self.fmin_slsqp(*arguments, **keywords, iprint=0,
                                                  full_output=True)
        self.mode = int(mode)
        return solution


class ToolboxSlsqp:
    """toolbox-parallel-robots' SLSQP closure, with the workarounds of the module text."""

    def __init__(self, model: ParallelModel) -> None:
        from importlib import metadata

        import peers
        import pinocchio

        toolbox = peers.import_toolbox()
        from toolbox_parallel_robots import forward_kinematics

        self.tree = PinocchioTree(model)
        pinocchio_model = self.tree.model
        self.constraints = []
        for closure in model.closures:
            frames = [pinocchio_model.frames[self.tree.frame(name)]
                      for name in (closure.parent_frame, closure.child_frame)]
            contact = (pinocchio.ContactType.CONTACT_6D if closure.kind is ClosureKind.WELD
                       else pinocchio.ContactType.CONTACT_3D)
            constraint = pinocchio.RigidConstraintModel(
                contact, pinocchio_model, frames[0].parentJoint, frames[0].placement,
                frames[1].parentJoint, frames[1].placement, pinocchio.ReferenceFrame.LOCAL)
            constraint.name = closure.name
            self.constraints.append(constraint)
        self.constraint_data = [constraint.createData() for constraint in self.constraints]
        self.actuation = toolbox.ActuationModel(pinocchio_model, list(model.actuated))
        # the toolbox orders the motors' targets by their index in q, not by name_mot
        self.motor_order = np.argsort(self.tree.actuated)
        self._function = forward_kinematics.closedLoopForwardKinematicsScipy
        if not isinstance(forward_kinematics.fmin_slsqp, _QuietSlsqp):
            forward_kinematics.fmin_slsqp = _QuietSlsqp(forward_kinematics.fmin_slsqp)
        self.slsqp = forward_kinematics.fmin_slsqp
        self.q = pinocchio.neutral(pinocchio_model)
        self.label = (f"toolbox-parallel-robots {metadata.version('toolbox-parallel-robots')} "
                      'SLSQP')

    def start(self, pose: Mapping[str, float]) -> None:
        """Take ``pose`` as the previous answer."""
        self.q = self.tree.configuration(pose)

    def follow(self, actuated: Sequence[float]) -> Answer:
        """One call of the toolbox's SLSQP closure from the previous answer."""
        targets = np.asarray(actuated)[self.motor_order]
        q = self._function(self.tree.model, self.tree.data, self.constraints,
                           self.constraint_data, self.actuation, targets, _WarmStart(self.q))
        self.q = q
        converged = self.slsqp.mode == 0 and bool(np.all(np.isfinite(q)))
        return Answer(self.tree.positions(q), converged)


def idle_coordinates(model: ParallelModel, pose: Mapping[str, float],
                     tolerance: float = 1e-9) -> tuple[str, ...]:
    """
    Return the passive coordinates that take part in an idle freedom at ``pose``.

    An idle freedom (issue 29: a rod spinning about its own axis, two collinear pins in series)
    is a motion of the passive coordinates that keeps the closures and moves no joint origin and
    no closure frame's origin: the null space of the closures' Jacobian and of every such point's
    velocity together, by SVD with ``tolerance`` relative to the largest singular value. Its
    coordinates' values are a convention (the reference holds them at the assembled pose), so the
    section reports them apart. The bench's stand-in until loops.structure lands.
    """
    import pinocchio

    tree = PinocchioTree(model)
    q = tree.configuration(pose)
    _, rows = tree.residual(q)
    aligned = pinocchio.ReferenceFrame.LOCAL_WORLD_ALIGNED
    points = [pinocchio.getJointJacobian(tree.model, tree.data, joint, aligned)[:3]
              for joint in range(1, tree.model.njoints)]
    points += [pinocchio.getFrameJacobian(tree.model, tree.data, frame, aligned)[:3]
               for _, first, second in tree.closures for frame in (first, second)]
    stacked = np.vstack([rows, *points])[:, tree.passive]
    _, singular, right = np.linalg.svd(stacked)
    rank = int(np.sum(singular > tolerance * singular[0]))
    idle = right[rank:]
    involved = np.max(np.abs(idle), axis=0) > tolerance if len(idle) else []
    passive = model.passive
    return tuple(passive[index] for index, taking_part in enumerate(involved) if taking_part)


def assemble(model: ParallelModel, start: Mapping[str, float] | None = None,
             iterations: int = 200) -> tuple[dict[str, float], float]:
    """
    Return an assembled pose near ``start`` (default: every coordinate at 0) and its residual.

    Levenberg–Marquardt on every coordinate (actuated ones too) with Pinocchio's residual: the
    bench's stand-in until the package's own assembly (loops.assembly) lands. The damping is
    relative to the Jacobian's scale and shrinks as the residual falls, so that the last steps are
    Gauss–Newton's and the pose closes to rounding.
    """
    tree = PinocchioTree(model)
    pose = dict.fromkeys(model.coordinates, 0.0) if start is None else dict(start)
    q = tree.configuration(pose)
    damping = 1e-3
    values, rows = tree.residual(q)
    cost = float(values @ values)
    for _ in range(iterations):
        normal = rows.T @ rows
        scale = float(np.max(np.diag(normal))) or 1.0
        step = np.linalg.solve(normal + damping * scale * np.eye(len(q)), rows.T @ values)
        trial = q - step
        trial_values, trial_rows = tree.residual(trial)
        trial_cost = float(trial_values @ trial_values)
        if trial_cost < cost:
            q, values, rows, cost = trial, trial_values, trial_rows, trial_cost
            damping = max(damping / 10.0, 1e-15)
            if math.sqrt(cost) < 1e-15 or float(np.max(np.abs(step))) < 1e-15:
                break
        else:
            damping *= 10.0
    return dict(zip(model.coordinates, tree.positions(q))), float(np.max(np.abs(values)))
