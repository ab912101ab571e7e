"""Isaac compat area: ``isaacsim.core.rendering_manager`` (``RenderingManager``, ``RenderingEvent``, ``ViewportManager``).

* ``RenderingManager.render()`` is one app update in which physics does not step
  (``/app/player/playSimulations`` is False during it, as in Kit): a playing
  timeline still ticks and captures; ``set_dt(dt)`` / ``get_dt()`` set and read
  the application's frame length: the stage's and the timeline's time codes per
  second (``1 / dt``, so each app update advances ``dt``) and Kit's loop-runner
  step; ``register_callback(RenderingEvent.NEW_FRAME)``
  observes the stage rendering event ``NEW_FRAME``, which graphsdg sends for every
  capture that rendered (it renders only when it captures: docs/porting.md).
* ``ViewportManager`` drives graphsdg's one viewport
  (:mod:`graphsdg.compat.viewport`): its camera, resolution and render product;
  ``set_camera_view`` places any camera by Isaac's eye / target / centre-of-interest
  rules.

The application's frame length (Kit's loop runner in manual mode) is kept here
(:func:`app_dt`): ``SimulationContext.set_simulation_dt`` writes it too.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> RenderingManager.set_dt(1 / 30)
    >>> round(RenderingManager.get_dt(), 6), rep.timeline.get_timeline_interface().get_time_codes_per_seconds()
    (0.033333, 30.0)
"""
from __future__ import annotations

import enum
import logging
import types
import weakref
from typing import Any, Callable

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom

from graphsdg.base import settings_store as settings
from graphsdg.compat import viewport
from graphsdg.compat.event_dispatch import get_eventdispatcher
from graphsdg.compat.event_names import StageRenderingEventType, stage_rendering_event_name
from graphsdg.compat.kit import get_app
from graphsdg.compat.modules import CompatError, CompatModule
from graphsdg.maths.rotations import decompose, look_at_matrix, matrix_to_quat_wxyz
from graphsdg.physics.timeline import get_timeline_interface
from graphsdg.physics.world_pose import set_world_pose
from graphsdg.render.render_product import RenderProduct, registry
from graphsdg.sim.timeline import PLAY_SIMULATIONS_SETTING
from graphsdg.stage.context import get_stage

log = logging.getLogger("carb")

RATE_LIMIT_ENABLED = "/app/runLoops/main/rateLimitEnabled"
RATE_LIMIT_FREQUENCY = "/app/runLoops/main/rateLimitFrequency"
KIT_RATE_LIMIT_FREQUENCY = 120.0   # Kit's default for the setting (what Isaac reads until a script sets it)


class _LoopRunner:
    """Kit's Isaac loop runner in manual mode: the fixed frame length app updates use (None: not in manual mode)."""

    manual_step_size: float | None = None


def app_dt() -> float:
    """The application's frame length: the rate limit's when it is on (Kit's 120 Hz unless set), else the loop
    runner's, else the timeline's frame (``1 / time codes per second``)."""
    if settings.get(RATE_LIMIT_ENABLED, False):
        frequency = float(settings.get(RATE_LIMIT_FREQUENCY, KIT_RATE_LIMIT_FREQUENCY) or 0.0)
        return 1.0 / frequency if frequency else 0.0
    if _LoopRunner.manual_step_size is not None:
        return _LoopRunner.manual_step_size
    return get_timeline_interface().frame_duration


def set_app_dt(dt: float) -> None:
    """Make every app update ``dt`` seconds long: the stage's and the timeline's time codes per second are
    ``1 / dt`` (so a playing timeline advances ``dt`` per update), the loop runner's manual step is ``dt`` and
    an enabled rate limit runs at ``1 / dt``."""
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"Rendering dt must be a positive number of seconds, got {dt!r}")
    frequency = 1.0 / float(dt)
    if settings.get(RATE_LIMIT_ENABLED, False):
        settings.set(RATE_LIMIT_FREQUENCY, frequency)
    stage = get_stage()
    with Usd.EditContext(stage, stage.GetRootLayer()):
        stage.SetTimeCodesPerSecond(frequency)
    get_timeline_interface().set_time_codes_per_second(frequency)
    _LoopRunner.manual_step_size = float(dt)


def render_only_update() -> None:
    """One app update in which physics does not step (``/app/player/playSimulations`` off during it)."""
    previous = settings.get(PLAY_SIMULATIONS_SETTING, True)
    settings.set(PLAY_SIMULATIONS_SETTING, False)
    try:
        get_app().update()
    finally:
        settings.set(PLAY_SIMULATIONS_SETTING, previous)


async def render_only_update_async() -> None:
    """:func:`render_only_update` for coroutines (waits for the next app update)."""
    previous = settings.get(PLAY_SIMULATIONS_SETTING, True)
    settings.set(PLAY_SIMULATIONS_SETTING, False)
    try:
        await get_app().next_update_async()
    finally:
        settings.set(PLAY_SIMULATIONS_SETTING, previous)


class RenderingEvent(enum.Enum):
    """``isaacsim.core.rendering_manager.RenderingEvent``."""

    NEW_FRAME = "isaacsim.rendering.new_frame"


class RenderingManager:
    """``isaacsim.core.rendering_manager.RenderingManager`` (class methods, as in Isaac; see the module docstring)."""

    _callbacks: dict[int, Any] = {}
    _callback_registry = 0

    @classmethod
    def render(cls) -> None:
        """An app update without physics: the timeline ticks (when playing), captures happen, physics waits."""
        render_only_update()

    @classmethod
    async def render_async(cls) -> None:
        """:meth:`render` for coroutines."""
        await render_only_update_async()

    @classmethod
    def set_dt(cls, dt: float) -> None:
        """Make every app update ``dt`` seconds long (time codes per second ``1 / dt``; physics' step is
        ``SimulationManager.setup_simulation(dt=...)``'s)."""
        set_app_dt(dt)

    @classmethod
    def get_dt(cls) -> float:
        """The application's frame length in seconds."""
        return app_dt()

    @classmethod
    def register_callback(cls, event: RenderingEvent, *, callback: Callable, order: int = 0) -> int:
        """Call ``callback(event)`` on ``event``; returns the id :meth:`deregister_callback` takes."""
        if not isinstance(event, RenderingEvent):
            raise ValueError(f"Invalid rendering event: {event!r}. Supported events are: {list(RenderingEvent)}")
        if not callable(callback):
            raise TypeError(f"callback must be callable, got {callback!r}")
        if hasattr(callback, "__self__") and hasattr(callback, "__func__"):   # a method: held weakly, as Isaac
            method = weakref.WeakMethod(callback)

            def on_event(e: Any) -> Any:
                fn = method()
                return None if fn is None else fn(e)
        else:
            on_event = callback
        uid = cls._callback_registry
        cls._callback_registry += 1
        cls._callbacks[uid] = get_eventdispatcher().observe_event(
            order=order, event_name=stage_rendering_event_name(StageRenderingEventType.NEW_FRAME, True),
            on_event=on_event, observer_name=f"isaacsim.core.rendering_manager:callback.{event.value}.{uid}")
        return uid

    @classmethod
    def deregister_callback(cls, uid: int) -> None:
        """End callback ``uid`` (a warning is logged if there is none)."""
        guard = cls._callbacks.pop(uid, None)
        if guard is None:
            log.warning(f"Unable to deregister callback with uid '{uid}'. It might have been already deregistered")
            return
        guard.reset()

    @classmethod
    def deregister_all_callbacks(cls) -> None:
        """End every callback."""
        for guard in cls._callbacks.values():
            guard.reset()
        cls._callbacks.clear()


# ---- camera views ---------------------------------------------------------------------------------------------
def _camera_prim(camera: Any) -> Usd.Prim:
    if isinstance(camera, UsdGeom.Camera):
        camera = camera.GetPrim()
    prim = camera if isinstance(camera, Usd.Prim) else get_stage().GetPrimAtPath(str(camera))
    if not prim or not prim.IsValid() or not prim.IsA(UsdGeom.Camera):
        raise ValueError(f"The camera ({camera}) is not a valid USD Camera prim")
    return prim


def _vec3(value: Any, what: str) -> np.ndarray:
    arr = np.asarray(value.numpy() if hasattr(value, "numpy") and not isinstance(value, np.ndarray) else value,
                     dtype=np.float64).reshape(-1)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must be 3 finite numbers, got {value!r}")
    return arr


def _world(prim: Usd.Prim) -> tuple[np.ndarray, np.ndarray]:
    m = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default()), dtype=np.float64)
    t, r, _ = decompose(m)
    return t, r


def _up_vector() -> np.ndarray:
    return np.array([0.0, 1.0, 0.0]) if UsdGeom.GetStageUpAxis(get_stage()) == UsdGeom.Tokens.y else \
        np.array([0.0, 0.0, 1.0])


def camera_edit_context(prim: Usd.Prim) -> Usd.EditContext:
    """Where a camera's pose is authored: the session layer for a camera defined there (Kit's viewport cameras,
    whose session opinions would hide a root-layer edit), else the stage's edit target."""
    stage = prim.GetStage()
    session = stage.GetSessionLayer()
    target = session if session.GetPrimAtPath(prim.GetPath()) is not None else stage.GetEditTarget()
    return Usd.EditContext(stage, target)


def aim_camera(prim: Usd.Prim, eye: np.ndarray | None, target: np.ndarray | None) -> None:
    """Move the camera to world ``eye`` (orientation kept) and / or turn it to look at world ``target`` with the
    stage's up axis up; a target straight along the up axis is nudged 1e-5 sideways, as Kit does."""
    with camera_edit_context(prim):
        _aim(prim, eye, target)


def _aim(prim: Usd.Prim, eye: np.ndarray | None, target: np.ndarray | None) -> None:
    if eye is not None:
        set_world_pose(prim, position=eye)
    if target is not None:
        position, _ = _world(prim)
        up = _up_vector()
        if np.linalg.norm(np.cross(position - target, up)) < 1e-5:
            target = target + np.array([1e-5, 0.0, 0.0])
        set_world_pose(prim, orientation=matrix_to_quat_wxyz(look_at_matrix(position, target, up)))


class ViewportManager:
    """``isaacsim.core.rendering_manager.ViewportManager`` over graphsdg's one viewport (class methods)."""

    @classmethod
    def get_viewport_api(cls, render_product_or_viewport: Any = None) -> viewport.ViewportAPI | None:
        """The viewport: the active one (None, ``"Viewport"`` or the viewport itself); None for anything else."""
        if render_product_or_viewport is None or render_product_or_viewport is viewport.get_active_viewport():
            return viewport.get_active_viewport()
        if isinstance(render_product_or_viewport, str) and render_product_or_viewport == "Viewport":
            return viewport.get_active_viewport()
        return None

    @classmethod
    def get_render_product(cls, render_product_or_viewport: Any = None) -> RenderProduct | None:
        """The render product of the viewport, or the one named by a path, name or render product (graphsdg's
        ``RenderProduct``: render products are not USD prims here)."""
        vp = cls.get_viewport_api(render_product_or_viewport)
        if vp is not None:
            return registry.find(vp.render_product_path)
        if isinstance(render_product_or_viewport, RenderProduct):
            return render_product_or_viewport
        if isinstance(render_product_or_viewport, (str, Sdf.Path)):
            try:
                return registry.find(str(render_product_or_viewport))
            except ValueError:
                return None
        return None

    @classmethod
    def _target(cls, render_product_or_viewport: Any, what: str) -> tuple[Any, RenderProduct | None]:
        vp = cls.get_viewport_api(render_product_or_viewport)
        if vp is not None:
            return vp, None
        rp = cls.get_render_product(render_product_or_viewport)
        if rp is None:
            raise ValueError(f"Unable to {what}: unknown render product or viewport {render_product_or_viewport!r}")
        return None, rp

    @classmethod
    def set_camera(cls, camera: Any, *, render_product_or_viewport: Any = None) -> None:
        """Make ``camera`` the viewport's (or a render product's) camera."""
        path = str(_camera_prim(camera).GetPath())
        vp, rp = cls._target(render_product_or_viewport, "set camera")
        if vp is not None:
            vp.camera_path = path
        else:
            rp.camera = path

    @classmethod
    def get_camera(cls, render_product_or_viewport: Any = None) -> UsdGeom.Camera:
        """The viewport's (or a render product's) camera."""
        vp, rp = cls._target(render_product_or_viewport, "get camera")
        path = str(vp.camera_path) if vp is not None else rp.camera
        return UsdGeom.Camera(get_stage().GetPrimAtPath(path))

    @classmethod
    def get_resolution(cls, render_product_or_viewport: Any = None) -> tuple[int, int]:
        """The viewport's (or a render product's) resolution (width, height)."""
        vp, rp = cls._target(render_product_or_viewport, "get resolution")
        return tuple(vp.resolution) if vp is not None else tuple(rp.resolution)

    @classmethod
    def set_resolution(cls, resolution: tuple[int, int], *, render_product_or_viewport: Any = None) -> None:
        """Set the viewport's (or a render product's) resolution (width, height)."""
        width, height = (int(v) for v in resolution)
        if width <= 0 or height <= 0:
            raise ValueError(f"resolution must be two positive integers, got {resolution!r}")
        vp, rp = cls._target(render_product_or_viewport, "set resolution")
        if vp is not None:
            vp.resolution = (width, height)
        else:
            rp.resolution = (width, height)

    @classmethod
    def wait_for_viewport(cls, *, viewport: Any = None, max_frames: int = 60, sleep_time: float = 0.02
                          ) -> tuple[bool, int]:
        """``(True, 0)``: graphsdg's viewport has no window to wait for; it renders when a capture needs it."""
        return cls.get_viewport_api(viewport) is not None, 0

    @classmethod
    async def wait_for_viewport_async(cls, *, viewport: Any = None, max_frames: int = 60,
                                      sleep_time: float = 0.02) -> tuple[bool, int]:
        """:meth:`wait_for_viewport` for coroutines."""
        return cls.wait_for_viewport(viewport=viewport, max_frames=max_frames, sleep_time=sleep_time)

    @classmethod
    def get_viewport_windows(cls, *, include: list[str] | None = None, exclude: list[str] | None = None) -> list:
        """Not mapped: graphsdg has no viewport windows (raises naming it)."""
        raise CompatError("isaacsim.core.rendering_manager.ViewportManager.get_viewport_windows is not available in "
                          "graphsdg's compat mode: there are no viewport windows (one headless viewport, "
                          "ViewportManager.get_viewport_api()). See docs/porting.md.")

    create_viewport_window = destroy_viewport_windows = get_viewport_windows

    @classmethod
    def set_camera_view(cls, camera: Any, *, eye: Any = None, target: Any = None,
                        relative_tracking: bool = False) -> None:
        """Place ``camera`` by Isaac's rules: ``eye`` moves it (orientation kept), ``target`` turns it to look
        there; with an ``omni:kit:centerOfInterest`` attribute (a world point) a missing target is the centre of
        interest, ``relative_tracking`` moves the camera with the target, and a given target becomes the new
        centre of interest."""
        prim = _camera_prim(camera)
        eye = None if eye is None else _vec3(eye, "eye")
        target = None if target is None else _vec3(target, "target")
        coi = prim.GetAttribute("omni:kit:centerOfInterest") if prim.HasAttribute("omni:kit:centerOfInterest") \
            else None
        update_coi = False
        if coi is None:
            if eye is None and target is None:
                log.warning("Neither the 'eye' nor the 'target' was provided. As the 'omni:kit:centerOfInterest' "
                            "attribute was not authored, the camera view will not change.")
        elif eye is None and target is None:
            target = np.array(coi.Get(), dtype=np.float64)
        elif eye is None:
            update_coi = True
            if relative_tracking:
                position, _ = _world(prim)
                eye = position - np.array(coi.Get(), dtype=np.float64) + target
        elif target is None:
            target = np.array(coi.Get(), dtype=np.float64)
        else:
            update_coi = True
        aim_camera(prim, eye, target)
        if update_coi:
            with camera_edit_context(prim):
                coi.Set(Gf.Vec3d(*target.tolist()))


def modules() -> list[types.ModuleType]:
    """``isaacsim.core.rendering_manager``."""
    return [CompatModule("isaacsim.core.rendering_manager", RenderingManager=RenderingManager,
                         RenderingEvent=RenderingEvent, ViewportManager=ViewportManager)]


EXTENSIONS = {"isaacsim.core.rendering_manager": ("isaacsim.core.rendering_manager",)}


def uninstall() -> None:
    """Called by :func:`graphsdg.compat.isaac.uninstall`: rendering callbacks end, the loop runner leaves manual mode."""
    RenderingManager.deregister_all_callbacks()
    _LoopRunner.manual_step_size = None
