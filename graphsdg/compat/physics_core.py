"""Isaac compat area: ``omni.physics.core``: physics step subscriptions, stepping by hand and scene queries.

``omni.physics.core.get_physics_simulation_interface().subscribe_physics_on_step_events(
pre_step, order, on_update)`` calls ``on_update(step_size, context)`` before
(``pre_step=True``) or after every physics step, lower ``order`` first. Here
the steps are MuJoCo's (:mod:`graphsdg.sim.physics_steps`): 120 Hz, two per 60 Hz
timeline frame, so ``step_size`` is the model's timestep. The subscription ends on
``unsubscribe()`` or when the script drops it.

Example:
    >>> import graphsdg as rep
    >>> from graphsdg.compat import physics_core
    >>> _ = rep.stage.new_stage()
    >>> steps = []
    >>> sub = physics_core.get_physics_simulation_interface().subscribe_physics_on_step_events(
    ...     pre_step=False, order=0, on_update=lambda dt, context: steps.append(dt))
    >>> tl = rep.timeline.get_timeline_interface()
    >>> tl.play()
    >>> rep.orchestrator.update()
    >>> tl.stop()
    >>> [round(dt, 6) for dt in steps]
    [0.008333, 0.008333]
    >>> sub.unsubscribe()

The simulation interface also steps physics by hand, as Isaac's warm-ups and
``SimulationManager`` do: ``initialize(stage_id)`` attaches the current stage
(compiling it), ``simulate(elapsed_time, current_time)`` advances MuJoCo by
``elapsed_time`` seconds at the model's step size (writing poses back to the stage,
so ``fetch_results()`` finds them there already), ``flush_changes()`` brings the
simulation up to date with stage edits, ``pause_change_tracking(True)`` keeps
stage edits from reaching it. ``get_physics_scene_query_interface()`` answers
overlap and ray queries against the colliders (:mod:`graphsdg.physics.queries`),
naming hit prims by ``PhysicsSchemaTools.sdfPathToInt`` integers, as
``omni.physics.core`` does.
"""
from __future__ import annotations

import types
from typing import Any, Callable

from pxr import Usd, UsdUtils

from graphsdg.compat.modules import CompatModule, CompatObject
from graphsdg.compat.physx_schema import sdfPathToInt
from graphsdg.physics import queries
from graphsdg.engine.runtime import runtime
from graphsdg.sim import physics_steps
from graphsdg.stage.context import get_stage, stage_context


class PhysicsStepContext(CompatObject):
    """What ``on_update``'s second argument carries here: ``step_size`` and ``pre_step``."""

    _compat_name = "omni.physics.core step context"

    def __init__(self, step_size: float, pre_step: bool) -> None:
        self.step_size = step_size
        self.pre_step = pre_step


class PhysicsStepSubscription(CompatObject):
    """A physics step subscription: ``unsubscribe()`` or dropping it ends it."""

    _compat_name = "omni.physics.core.PhysicsStepSubscription"

    def __init__(self, handle: int) -> None:
        self._handle = handle

    @property
    def id(self) -> int:
        """The subscription's identifier (for ``unsubscribe_physics_on_step_events``)."""
        return self._handle

    def unsubscribe(self) -> None:
        """Stop receiving step events."""
        physics_steps.unsubscribe(self._handle)

    def __del__(self) -> None:
        try:
            physics_steps.unsubscribe(self._handle)
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


class PhysicsStepper:
    """Stepping physics by hand on the current stage, shared by ``omni.physics.core`` and ``omni.physx``."""

    def __init__(self) -> None:
        self._attached: int | None = None      # stage id given to initialize()
        self._tracking_pause = None             # the tracker's muted() block while change tracking is paused

    @staticmethod
    def stage_id(stage: Usd.Stage) -> int:
        """``stage``'s id in USD's stage cache (inserted on first use)."""
        cache = UsdUtils.StageCache.Get()
        found = cache.GetId(stage).ToLongInt()
        return found if found >= 0 else cache.Insert(stage).ToLongInt()

    def check_stage(self, stage_id: int, caller: str) -> None:
        """Raise unless ``stage_id`` is the current stage's (graphsdg simulates that stage only)."""
        current = self.stage_id(get_stage())
        if int(stage_id) != current:
            raise ValueError(f"{caller}: stage id {stage_id} is not the current stage's ({current}); graphsdg "
                             f"simulates the USD context's stage (UsdUtils.StageCache.Get().GetId(stage))")

    def initialize(self, stage_id: int) -> bool:
        """Attach the stage ``stage_id`` (the current one) and compile its simulation."""
        self.check_stage(stage_id, "initialize")
        sim = runtime().sim
        sim.sync_dirty_prims()
        sim.ensure_compiled()
        self._attached = int(stage_id)
        return True

    def close(self) -> None:
        """Detach the stage (stepping by hand needs ``initialize`` again); change tracking resumes."""
        self._attached = None
        self.pause_change_tracking(False)

    def get_attached_stage(self) -> int:
        """The attached stage's id (0 when none, as PhysX)."""
        return self._attached or 0

    def simulate(self, elapsed_time: float, current_time: float = 0.0) -> None:
        """Advance physics by ``elapsed_time`` seconds (at the model's step size) and write poses back."""
        if isinstance(elapsed_time, bool) or not isinstance(elapsed_time, (int, float)) or not elapsed_time > 0:
            raise ValueError(f"simulate: elapsed_time must be a positive number of seconds, got {elapsed_time!r}")
        sim = runtime().sim
        if self._tracking_pause is None:
            sim.sync_dirty_prims()
        sim.advance(float(elapsed_time))

    def flush_changes(self) -> None:
        """Bring the simulation up to date with every stage edit so far."""
        runtime().sim.sync_dirty_prims()

    def pause_change_tracking(self, pause: bool) -> None:
        """Stop (``True``) or resume (``False``) passing stage edits to the simulation; edits made while paused
        never reach it, as with PhysX."""
        tracker = runtime().sim.tracker
        if pause and self._tracking_pause is None:
            runtime().sim.sync_dirty_prims()
            self._tracking_pause = tracker.muted()
            self._tracking_pause.__enter__()
        elif not pause and self._tracking_pause is not None:
            self._tracking_pause.__exit__(None, None, None)
            self._tracking_pause = None

    def is_change_tracking_paused(self) -> bool:
        """Whether stage edits are kept from the simulation."""
        return self._tracking_pause is not None

    def on_stage_replaced(self, stage: Usd.Stage | None) -> None:
        """A new stage is attached to nothing and tracked (the pause belonged to the old stage's tracker)."""
        self._attached = None
        if self._tracking_pause is not None:
            self._tracking_pause.__exit__(None, None, None)
            self._tracking_pause = None


stepper = PhysicsStepper()
stage_context.subscribe_replaced(stepper.on_stage_replaced)


class PhysicsSimulationInterface(CompatObject):
    """omni.physics.core's simulation interface: step event subscriptions and stepping by hand."""

    _compat_name = "omni.physics.core.IPhysicsSimulation"

    def initialize(self, stage_id: int) -> bool:
        """Attach the current stage (its ``UsdUtils.StageCache`` id) and compile its simulation."""
        return stepper.initialize(stage_id)

    def close(self) -> None:
        """Detach the stage."""
        stepper.close()

    def get_attached_stage(self) -> int:
        """The attached stage's id (0 when none)."""
        return stepper.get_attached_stage()

    def is_capable_of_simulating(self) -> bool:
        """True: MuJoCo simulates every stage graphsdg compiles."""
        return True

    def simulate(self, elapsed_time: float, current_time: float = 0.0) -> None:
        """Advance physics by ``elapsed_time`` seconds (``current_time`` is PhysX's clock; MuJoCo keeps its own)."""
        stepper.simulate(elapsed_time, current_time)

    def fetch_results(self) -> None:
        """Results are on the stage as soon as :meth:`simulate` returns (graphsdg steps synchronously)."""

    def check_results(self) -> bool:
        """True: a simulation step is always complete when :meth:`simulate` returns."""
        return True

    def flush_changes(self) -> None:
        """Bring the simulation up to date with stage edits."""
        stepper.flush_changes()

    def pause_change_tracking(self, pause: bool) -> None:
        """Keep stage edits from (``True``) or pass them to (``False``) the simulation."""
        stepper.pause_change_tracking(pause)

    def is_change_tracking_paused(self) -> bool:
        """Whether stage edits are kept from the simulation."""
        return stepper.is_change_tracking_paused()

    def subscribe_physics_on_step_events(self, pre_step: bool, order: int,
                                         on_update: Callable[[float, Any], Any]) -> PhysicsStepSubscription:
        """Call ``on_update(step_size, context)`` before (``pre_step``) or after every physics step."""
        if not isinstance(pre_step, (bool, int)):
            raise TypeError(f"pre_step must be a bool, got {pre_step!r}")
        if not callable(on_update):
            raise TypeError(f"on_update must be a callable taking (step_size, context), got {on_update!r}")
        pre = bool(pre_step)
        handle = physics_steps.subscribe(pre, order, lambda dt: on_update(dt, PhysicsStepContext(dt, pre)))
        return PhysicsStepSubscription(handle)

    def unsubscribe_physics_on_step_events(self, subscription: PhysicsStepSubscription | int) -> None:
        """End a subscription (the object or its ``id``)."""
        physics_steps.unsubscribe(subscription.id if isinstance(subscription, PhysicsStepSubscription)
                                  else int(subscription))


_interface = PhysicsSimulationInterface()


def get_physics_simulation_interface() -> PhysicsSimulationInterface:
    """omni.physics.core.get_physics_simulation_interface()."""
    return _interface


# ---- scene queries --------------------------------------------------------------------------------------------
class SceneQueryHit(CompatObject):
    """A query hit: ``rigid_body`` and ``collision`` as ``PhysicsSchemaTools.sdfPathToInt`` integers; ray hits add
    ``position``, ``normal``, ``distance``, ``face_index`` and ``material`` (0: graphsdg does not report materials)."""

    _compat_name = "omni.physics.core scene query hit"

    def __init__(self, rigid_body: str, collision: str, **ray: object) -> None:
        self.rigid_body = sdfPathToInt(rigid_body)
        self.collision = sdfPathToInt(collision)
        self.proto_index = 0xFFFFFFFF
        self.__dict__.update(ray)

    @classmethod
    def of_ray(cls, hit: queries.RaycastHit) -> "SceneQueryHit":
        return cls(hit.rigid_body, hit.collision, position=tuple(hit.position.tolist()),
                   normal=tuple(hit.normal.tolist()), distance=float(hit.distance), face_index=0, material=0)


class PhysicsSceneQueryInterface(CompatObject):
    """omni.physics.core's scene query interface over :mod:`graphsdg.physics.queries` (quaternions x, y, z, w)."""

    _compat_name = "omni.physics.core.IPhysicsSceneQuery"

    @staticmethod
    def _reporter(report_fn):
        if report_fn is None:
            return None
        if not callable(report_fn):
            raise TypeError(f"report_fn must be callable as report_fn(hit) -> bool, got {report_fn!r}")
        return lambda hit: report_fn(SceneQueryHit(hit.rigid_body, hit.collision))

    def overlap_box(self, half_extent, pos, rot, report_fn=None, any_hit: bool = False) -> int:
        """Report the colliders a box touches (``report_fn(hit)`` returning False stops); returns how many."""
        return queries.overlap_box(tuple(half_extent), tuple(pos), tuple(rot), self._reporter(report_fn), any_hit)

    def overlap_sphere(self, radius: float, pos, report_fn=None, any_hit: bool = False) -> int:
        """Report the colliders a sphere touches; returns how many."""
        return queries.overlap_sphere(radius, tuple(pos), self._reporter(report_fn), any_hit)

    def overlap_box_any(self, half_extent, pos, rot) -> bool:
        """Whether a box touches any collider."""
        return self.overlap_box(half_extent, pos, rot, None, True) > 0

    def overlap_sphere_any(self, radius: float, pos) -> bool:
        """Whether a sphere touches any collider."""
        return self.overlap_sphere(radius, pos, None, True) > 0

    @staticmethod
    def _nearest(origin, direction, distance: float) -> queries.RaycastHit | None:
        found: list[queries.RaycastHit] = []
        queries.raycast_all(tuple(origin), tuple(direction), distance, lambda hit: found.append(hit) or False)
        return found[0] if found else None   # raycast_all reports nearest first

    def raycast_closest(self, origin, dir, distance: float, bothSides: bool = False):  # noqa: A002,N803
        """``(hit?, hit)``: the nearest collider along the ray (``hit`` is None when nothing is hit)."""
        hit = self._nearest(origin, dir, distance)
        return (True, SceneQueryHit.of_ray(hit)) if hit is not None else (False, None)

    def raycast_any(self, origin, dir, distance: float, bothSides: bool = False) -> bool:  # noqa: A002,N803
        """Whether the ray meets any collider."""
        return self._nearest(origin, dir, distance) is not None

    def raycast_all(self, origin, dir, distance: float, report_fn, bothSides: bool = False) -> bool:  # noqa: A002,N803
        """Report every collider along the ray, nearest first; True when anything was hit."""
        reporter = None if report_fn is None else (lambda hit: report_fn(SceneQueryHit.of_ray(hit)))
        return queries.raycast_all(tuple(origin), tuple(dir), distance, reporter) > 0


_scene_query = PhysicsSceneQueryInterface()


def get_physics_scene_query_interface() -> PhysicsSceneQueryInterface:
    """omni.physics.core.get_physics_scene_query_interface()."""
    return _scene_query


def modules() -> list[types.ModuleType]:
    """The compat modules of this area."""
    return [CompatModule("omni.physics.core", get_physics_simulation_interface=get_physics_simulation_interface,
                         get_physics_scene_query_interface=get_physics_scene_query_interface)]
