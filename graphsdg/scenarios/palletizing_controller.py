"""The palletizing cell's controller: conveyor, feeder and the arm's pick-flip-place cycle.

It runs as a physics callback (before every physics step, as Isaac's tasks do)
and only reads and writes simulation state, so it does exactly the same thing
whether or not anything pauses the timeline in between:

* **conveyor**: bins touching the belt are pulled towards the end stop with the
  belt's traction (a force towards the belt speed, at most the belt friction's
  ``0.5 m g``; the belt surface itself is nearly frictionless);
* **feeder**: when the bin on the belt has been lifted off, the next waiting bin is
  set down at the belt's upstream end (upside down if the scenario says so);
* **arm**: a task script per bin. The tool centre point follows smooth paths
  (quintic timing; swings about the base in cylindrical coordinates, straight
  approaches and retreats); each physics step inverse kinematics turns the
  commanded tool pose into joint position and velocity targets for the drives.
  The suction cup grips on contact: when the cup touches the bin, the bin's
  pre-authored fixed joint is switched on holding the current relative pose
  (:func:`graphsdg.physics.articulations.set_fixed_joint_enabled`). Upright bins go
  straight to their slot on the pallet; upside-down bins are turned over on the
  flip helper first: laid on their side, re-gripped from above and stood up,
  re-gripped from the top.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterator

import numpy as np

from graphsdg.maths.rotations import matrix_to_quat_wxyz, quat_wxyz_to_matrix, rotation_about
from graphsdg.scenarios.palletizing_cell import CellLayout
from graphsdg.scenarios.ur10 import HOME, Ur10Kinematics
from graphsdg.physics.articulations import ArticulationView, set_fixed_joint_enabled
from graphsdg.sim.joints import Frame

Z = np.array([0.0, 0.0, 1.0])
SPEED = 1.0                 # m/s, peak tool speed of swings and long descents
TURN_SPEED = 2.5            # rad/s, peak tool turning speed (a UR10's wrist turns at up to 3.1 rad/s)
APPROACH_SPEED = 0.4        # m/s, peak speed of short straight approaches and retreats
TOUCH_SPEED = 0.1           # m/s, the last centimetres before the cup touches
PLACE_CLEARANCE = 0.004     # a bin is let go this far above its support
BELT_GAIN = 8.0             # 1/s, traction towards the belt speed
BELT_FRICTION = 0.5


@dataclass
class Event:
    """Something the cell did, at simulated time ``time``."""

    time: float
    what: str               # fed, gripped, released_on_helper, released_on_pallet, done
    bin: int


def _quintic(s: float) -> tuple[float, float]:
    """Minimum-jerk progress and its derivative at normalised time ``s``."""
    return 10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5, 30 * s ** 2 - 60 * s ** 3 + 30 * s ** 4


def _slerp(r0: np.ndarray, r1: np.ndarray, s: float) -> np.ndarray:
    q0, q1 = matrix_to_quat_wxyz(r0), matrix_to_quat_wxyz(r1)
    d = float(np.dot(q0, q1))
    if d < 0:
        q1, d = -q1, -d
    if d > 0.9995:
        q = q0 + s * (q1 - q0)
    else:
        a = math.acos(d)
        q = (math.sin((1 - s) * a) * q0 + math.sin(s * a) * q1) / math.sin(a)
    return quat_wxyz_to_matrix(q / np.linalg.norm(q))


def _angle_between(r0: np.ndarray, r1: np.ndarray) -> float:
    return math.acos(max(-1.0, min(1.0, (np.trace(r0.T @ r1) - 1) / 2)))


@dataclass
class _Ids:
    """Compiled-model indices the controller needs (refreshed after a recompile)."""

    version: tuple = ()
    cup: int = -1
    belt: int = -1
    bin_body: list[int] = field(default_factory=list)
    bin_qpos: list[int] = field(default_factory=list)
    bin_qvel: list[int] = field(default_factory=list)
    geom_bin: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))   # geom id -> bin or -1


class PalletizingController:
    """Conveyor, feeder and arm of the cell (see the module docstring)."""

    def __init__(self, layout: CellLayout, kinematics: Ur10Kinematics, robot: str, cup: str, belt: str,
                 bins: list[str], flipped: list[bool], suction_joints: list[str]) -> None:
        self.layout = layout
        self.kin = kinematics
        self.robot, self.cup_path, self.belt_path = robot, cup, belt
        self.bins, self.flipped, self.suction = list(bins), list(flipped), list(suction_joints)
        self.view = ArticulationView(robot)
        self.q_cmd = self.view.get_joint_positions()
        self.qd_cmd = np.zeros(6)
        self.tcp_cmd = self.kin.forward(self.q_cmd)
        self.dt = 1.0 / 120.0
        self.events: list[Event] = []
        self.placed: list[int] = []
        self.done = False
        self._ids = _Ids()
        self._on_belt = 0            # the bin the feeder put on the belt last (bin 0 starts there)
        self._next_feed = 1
        self._carrying: int | None = None
        self._layers_used = 0
        self._task: Iterator[None] = self._run()

    # ---- the physics callback ------------------------------------------------
    def physics_step(self, step_size: float) -> None:
        """Advance everything by one physics step (registered with ``add_physics_callback``)."""
        from graphsdg.engine.runtime import runtime
        sim = runtime().sim
        c = sim.compiled
        self.dt = float(step_size)
        self._refresh_ids(sim, c)
        self._drive_belt(c)
        self._feed(c)
        if not self.done:
            try:
                next(self._task)
            except StopIteration:
                self.done = True
                self.events.append(Event(float(c.data.time), "done", -1))
        self.view.set_joint_position_targets(self.q_cmd)
        self.view.set_joint_velocity_targets(self.qd_cmd)

    def _refresh_ids(self, sim, c) -> None:
        key = (id(sim), sim.model_version)
        if self._ids.version == key:
            return
        ids = _Ids(version=key)
        ids.cup = c.geoms[self.cup_path].geom_id
        ids.belt = c.geoms[self.belt_path].geom_id
        geom_bin = np.full(c.model.ngeom, -1, dtype=np.int64)
        index = {p: i for i, p in enumerate(self.bins)}
        for gid, owner in c.collider_owner.items():
            if owner in index:
                geom_bin[gid] = index[owner]
        ids.geom_bin = geom_bin
        for p in self.bins:
            b = c.bodies[p]
            ids.bin_body.append(b.body_id)
            ids.bin_qpos.append(b.qpos_adr)
            ids.bin_qvel.append(b.qvel_adr)
        self._ids = ids

    # ---- state of the bins -----------------------------------------------------
    def _data(self):
        from graphsdg.engine.runtime import runtime
        return runtime().sim.compiled.data

    def bin_pose(self, i: int) -> Frame:
        q = self._data().qpos[self._ids.bin_qpos[i]:self._ids.bin_qpos[i] + 7]
        return Frame(q[:3].copy(), quat_wxyz_to_matrix(q[3:]))

    def bin_speed(self, i: int) -> float:
        a = self._ids.bin_qvel[i]
        return float(np.linalg.norm(self._data().qvel[a:a + 6]))

    def _touching(self, c, geom: int) -> np.ndarray:
        """Indices of the bins in contact with ``geom``."""
        d = c.data
        n = d.ncon
        if n == 0:
            return np.zeros(0, dtype=np.int64)
        g1, g2 = d.contact.geom1[:n], d.contact.geom2[:n]
        other = np.concatenate([g2[g1 == geom], g1[g2 == geom]])
        found = self._ids.geom_bin[other]
        return np.unique(found[found >= 0])

    # ---- conveyor and feeder -----------------------------------------------------
    def _drive_belt(self, c) -> None:
        d, m = c.data, c.model
        on_belt = set(self._touching(c, self._ids.belt).tolist())
        for i, body in enumerate(self._ids.bin_body):
            if i not in on_belt or i == self._carrying:
                d.xfrc_applied[body] = 0.0
                continue
            vx = d.qvel[self._ids.bin_qvel[i]]
            a = max(-BELT_FRICTION * 9.81, min(BELT_FRICTION * 9.81, BELT_GAIN * (self.layout.belt_speed - vx)))
            d.xfrc_applied[body] = 0.0
            d.xfrc_applied[body, 0] = m.body_subtreemass[body] * a

    def _feed(self, c) -> None:
        if self._next_feed >= len(self.bins):
            return
        belt_bin = self.bin_pose(self._on_belt).pos
        if belt_bin[2] < self.layout.belt_top + self.layout.bin_size[2] + 0.05:
            return       # still on the belt (or just gripped)
        i = self._next_feed
        d = c.data
        pos = np.array([self.layout.feed_x, self.layout.belt_y,
                        self.layout.belt_top + self.layout.bin_size[2] / 2 + 0.001])
        rot = rotation_about(0, math.pi) if self.flipped[i] else np.eye(3)
        a, v = self._ids.bin_qpos[i], self._ids.bin_qvel[i]
        d.qpos[a:a + 3] = pos
        d.qpos[a + 3:a + 7] = matrix_to_quat_wxyz(rot)
        d.qvel[v:v + 6] = 0.0
        self._on_belt = i
        self._next_feed += 1
        self.events.append(Event(float(d.time), "fed", i))

    # ---- motion primitives -----------------------------------------------------------
    def _command(self, target: Frame) -> None:
        q = self.kin.track(target, self.q_cmd)
        self.qd_cmd = (q - self.q_cmd) / self.dt
        self.q_cmd = q
        self.tcp_cmd = target

    def _hold(self, seconds: float) -> Iterator[None]:
        self.qd_cmd = np.zeros(6)
        for _ in range(max(1, int(round(seconds / self.dt)))):
            yield

    def _path(self, target: Frame, swing: bool, speed: float) -> Iterator[None]:
        """Move the tool to ``target``: a swing about the base (cylindrical) or a straight line."""
        start = self.tcp_cmd
        if swing:
            r0, r1 = np.hypot(*start.pos[:2]), np.hypot(*target.pos[:2])
            a0, a1 = math.atan2(start.pos[1], start.pos[0]), math.atan2(target.pos[1], target.pos[0])
            da = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi
            rel0 = rotation_about(2, -a0) @ start.rot
            rel1 = rotation_about(2, -a1) @ target.rot
            length = math.sqrt((r1 - r0) ** 2 + (0.5 * (r0 + r1) * da) ** 2 + (target.pos[2] - start.pos[2]) ** 2)
            turn = _angle_between(rel0, rel1)
        else:
            length = float(np.linalg.norm(target.pos - start.pos))
            turn = _angle_between(start.rot, target.rot)
        duration = max(0.25, 1.875 * max(length / speed, turn / TURN_SPEED))
        n = max(1, int(math.ceil(duration / self.dt)))
        for k in range(1, n + 1):
            s, _ = _quintic(k / n)
            if swing:
                a = a0 + s * da
                r = r0 + s * (r1 - r0)
                pos = np.array([r * math.cos(a), r * math.sin(a), start.pos[2] + s * (target.pos[2] - start.pos[2])])
                rot = rotation_about(2, a) @ _slerp(rel0, rel1, s)
            else:
                pos = start.pos + s * (target.pos - start.pos)
                rot = _slerp(start.rot, target.rot, s)
            self._command(Frame(pos, rot))
            yield
        self.q_cmd = self.kin.solve(target, self.q_cmd)        # land exactly on the target
        self.tcp_cmd = target
        self.qd_cmd = np.zeros(6)

    def _safe_height(self) -> float:
        height = self.layout.bin_size[2]
        stack_top = self.layout.pallet_top + self._layers_used * height
        carried = height + 0.03 if self._carrying is not None else 0.0     # a gripped bin hangs under the cup
        return max(0.30, stack_top + 0.08 + carried)

    def _travel(self, target: Frame, final_speed: float = APPROACH_SPEED, final_drop: float = 0.10
                ) -> Iterator[None]:
        """Up to the safe height, swing over ``target``, then straight down to it (the last part slowly)."""
        z_safe = self._safe_height()
        if self.tcp_cmd.pos[2] < z_safe - 1e-6:
            yield from self._path(Frame(np.array([*self.tcp_cmd.pos[:2], z_safe]), self.tcp_cmd.rot), False,
                                  0.8 * SPEED)
        z_safe = max(z_safe, target.pos[2] + final_drop)       # the swing climbs on its way if need be
        yield from self._path(Frame(np.array([*target.pos[:2], z_safe]), target.rot), True, SPEED)
        above = Frame(target.pos + Z * final_drop, target.rot)
        if z_safe > above.pos[2] + 1e-6:
            yield from self._path(above, False, 0.8 * SPEED)
        yield from self._path(target, False, final_speed)

    # ---- gripping ---------------------------------------------------------------------
    def _kindest(self, position: np.ndarray, rotations: list[np.ndarray]) -> np.ndarray:
        """Of tool orientations that are all fine for the task (a bin is the same turned by half a turn),
        the one that leaves the wrist's last joint nearest zero: the wrist never runs into its limit."""
        best, best_cost = rotations[0], math.inf
        for rot in rotations:
            try:
                q = self.kin.solve(Frame(position, rot), self.kin.seed_for(position, self.q_cmd))
            except ValueError:
                continue
            cost = abs(q[5]) + 10.0 * float(np.sum(np.maximum(np.abs(q) - (2 * math.pi - 0.5), 0.0)))
            if cost < best_cost:
                best, best_cost = rot, cost
        return best

    def _tool_down(self, position: np.ndarray, x_axis: np.ndarray) -> np.ndarray:
        """Tool pointing down, its x along the horizontal ``x_axis`` (either sign: see :meth:`_kindest`)."""
        x = np.array([x_axis[0], x_axis[1], 0.0])
        x /= np.linalg.norm(x)
        z = -Z
        return self._kindest(position, [np.stack([s * x, np.cross(z, s * x), z], axis=1) for s in (1.0, -1.0)])

    def _up_face(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """(centre of the bin's upward face, tool-down rotation aligned with the bin's long axis)."""
        pose = self.bin_pose(i)
        half = np.array(self.layout.bin_size) / 2
        k = int(np.argmax(np.abs(pose.rot[2, :])))
        face = pose.pos + pose.rot[:, k] * np.sign(pose.rot[2, k]) * half[k]
        long_axis = pose.rot[:, 0] if k != 0 else pose.rot[:, 1]
        return face, self._tool_down(face, long_axis)

    def _grip_from_above(self, i: int) -> Iterator[None]:
        """Travel over bin ``i``'s upward face, come down until the cup touches, switch the grip on."""
        face, rot = self._up_face(i)
        yield from self._travel(Frame(face + Z * 0.03, rot))
        from graphsdg.engine.runtime import runtime
        c = runtime().sim.compiled
        start = self.tcp_cmd
        depth = 0.045
        n = int(math.ceil(depth / TOUCH_SPEED / self.dt))
        for k in range(1, n + 1):
            if i in self._touching(c, self._ids.cup):
                break
            self._command(Frame(start.pos - Z * depth * k / n, start.rot))
            yield
        else:
            raise RuntimeError(f"the suction cup never touched bin {i} (is it where the controller expects?)")
        set_fixed_joint_enabled(self.suction[i], True)
        self.qd_cmd = np.zeros(6)
        self._carrying = i
        self.events.append(Event(float(c.data.time), "gripped", i))
        self._grasp = self.bin_pose(i).inverse() @ self.tcp_cmd      # the tool in the bin's frame
        yield from self._hold(0.1)

    def _release(self, i: int, where: str) -> Iterator[None]:
        yield from self._hold(0.1)          # let the bin settle in the grip before letting go
        set_fixed_joint_enabled(self.suction[i], False)
        self._carrying = None
        self.events.append(Event(float(self._data().time), f"released_on_{where}", i))
        yield from self._hold(0.15)

    def _lift(self, height: float) -> Iterator[None]:
        yield from self._path(Frame(self.tcp_cmd.pos + Z * height, self.tcp_cmd.rot), False, APPROACH_SPEED)

    # ---- the task ------------------------------------------------------------------------
    def _run(self) -> Iterator[None]:
        for i in range(len(self.bins)):
            yield from self._wait_for_bin(i)
            yield from self._grip_from_above(i)
            yield from self._lift(0.12)
            if self.flipped[i]:
                yield from self._flip_on_helper(i)
            yield from self._place_on_pallet(i)
        yield from self._travel(self.kin.forward(HOME), final_drop=0.0)

    def _wait_for_bin(self, i: int) -> Iterator[None]:
        self.qd_cmd = np.zeros(6)
        while True:
            pose = self.bin_pose(i)
            if abs(pose.pos[0] - self.layout.pick_x) < 0.01 and abs(pose.pos[1] - self.layout.belt_y) < 0.02 \
                    and self.bin_speed(i) < 0.02:
                return
            yield

    def _flip_on_helper(self, i: int) -> Iterator[None]:
        """Lay the bin on its side on the helper, grip it from above, stand it up, grip its top."""
        lay = self.layout
        length, width, height = lay.bin_size
        u = lay.helper_u
        r_in, z_h = lay.helper_inner_radius, lay.helper_top
        # 1. on its side: the tool turns horizontal (pointing away from the robot), the bin's bottom faces it
        at = u * r_in + Z * (z_h + width / 2 + PLACE_CLEARANCE)
        yield from self._travel(Frame(at, self._sideways(at)), final_speed=0.15, final_drop=0.05)
        yield from self._release(i, "helper")
        yield from self._path(Frame(self.tcp_cmd.pos - u * 0.06, self.tcp_cmd.rot), False, APPROACH_SPEED)
        yield from self._lift(0.10)
        # 2. grip the side now facing up and stand the bin up on the helper
        yield from self._grip_from_above(i)
        yield from self._lift(0.15)
        at = u * r_in + Z * (z_h + height / 2 + PLACE_CLEARANCE)
        yield from self._travel(Frame(at, self._sideways(at)), final_speed=0.15, final_drop=0.05)
        yield from self._release(i, "helper")
        yield from self._path(Frame(self.tcp_cmd.pos - u * 0.06, self.tcp_cmd.rot), False, APPROACH_SPEED)
        yield from self._lift(0.10)
        # 3. grip the top (now facing up) and carry on to the pallet
        yield from self._grip_from_above(i)
        yield from self._lift(0.12)

    def _sideways(self, position: np.ndarray) -> np.ndarray:
        """Tool horizontal and pointing away from the robot over the helper, its x along the bin."""
        u = self.layout.helper_u
        t = np.cross(Z, u)
        return self._kindest(position, [np.stack([x, np.cross(u, x), u], axis=1) for x in (t, -t)])

    def _place_on_pallet(self, i: int) -> Iterator[None]:
        slot = len(self.placed)
        centre, yaw = self.layout.slot(slot)
        # either of the two yaws half a turn apart puts the bin in its slot
        options = [Frame(centre + Z * PLACE_CLEARANCE, rotation_about(2, yaw + k * math.pi)) @ self._grasp
                   for k in (0, 1)]
        rot = self._kindest(options[0].pos, [o.rot for o in options])
        target = next(o for o in options if o.rot is rot)
        yield from self._travel(target, final_speed=0.15, final_drop=0.05)
        yield from self._release(i, "pallet")
        self.placed.append(i)
        self._layers_used = max(self._layers_used, slot // 6 + 1)
        yield from self._lift(0.12)
