"""How the pbr backend has mujoco-warp-pbr build its render megakernel: ``compact`` or ``inlined``.

mujoco-warp-pbr specialises one render megakernel on each scene (geom types, light count, the settings it
bakes in as constants) and NVRTC compiles it on the first frame. NVRTC's optimiser works on a kernel as
one function, so its time grows with every copy of the scene traversal inlined into it: the camera ray,
each light's shadow ray (the light loop is unrolled), the headlight's shadow ray. On a fresh machine that
compile was nearly all of the first frame (docs/performance.md, "Cold start"). Two builds:

* ``compact`` (the default): each traversal's test of one geom (spheres, boxes, meshes, ...: the camera
  rays' closest hit and the shadow rays' any hit) and a light's shadow test (the shadow traversal inlined
  into it once) are compiled once as called functions, the camera traversal's loop stays inlined
  (:data:`CALLED_TRAVERSALS`); lights are shaded in a loop; and every setting a graphsdg render context
  holds fixed for its life (:data:`FIXED_GROUPS`: shadows, headlight, tone mapper, ...) is compiled in as
  a constant, so code for features a scene does not use is dropped before optimisation. Calling whole
  traversals compiles faster still but draws twice as slow (docs/performance.md, "Cold start").
* ``inlined``: mujoco-warp-pbr's own build (its ``DEFAULT_BAKED`` settings): every traversal inlined,
  lights unrolled up to six. It compiles several times longer.

Both are deterministic, and a run uses one: the choice is read when a render context is made (the
setting :data:`KIND_KEY`) and is part of the context's key. The two are different binaries: their images
are not promised to be identical, bit for bit.

Example:
    >>> sorted(baked_groups("compact", frozenset({"nlight", "has_env"})) - FIXED_GROUPS)
    ['has_env']
    >>> baked_groups("inlined", frozenset({"nlight"}))
    frozenset({'nlight'})
"""
from __future__ import annotations

import contextlib
import logging
import threading
from typing import Any, Callable, Iterator

from graphsdg.base import settings_store as settings

log = logging.getLogger("graphsdg.render")

KIND_KEY = "/graphsdg/render/pbrKernel"
KINDS = ("compact", "inlined")
#: mujoco-warp-pbr's bake groups whose values a graphsdg render context never changes after it is made (its
#: model, cameras and tier are fixed); resolution-dependent ones (ray counts, clip planes, the environment
#: map's texel angle) stay runtime values so that products of other sizes share the kernel
FIXED_GROUPS = frozenset({"any_rgb", "has_spot", "use_shadows", "shadow_samples", "shadow_light_fraction",
                          "headlight_active", "headlight", "env_background", "specular_aa", "vertex_normals",
                          "tone_mapper", "render_hdr"})
#: what a ``compact`` build compiles as called functions: a whole traversal (``closest``: camera rays, ``any``:
#: shadow rays), a traversal's test of one geom (``closest-geom``, ``any-geom``), whose loop stays inlined, or
#: a light's shadow test (``shadow-visibility``: mujoco-warp-pbr's ``light_visibility``, the shadow traversal
#: inlined into it once)
CALLED_TRAVERSALS: tuple[str, ...] = ("any-geom", "closest-geom", "shadow-visibility")
#: the functions of mujoco-warp-pbr's per-pixel body (``render.make_render_pixel``) a cut names
_PIXEL_FUNCTIONS = {"shadow-visibility": "light_visibility"}
_building = threading.local()
_install_lock = threading.Lock()
_installed = False


def requested_kind() -> str:
    """The build the setting :data:`KIND_KEY` asks for (validated by the settings store)."""
    return str(settings.get(KIND_KEY, "compact"))


def baked_groups(kind: str, default: frozenset[str]) -> frozenset[str]:
    """The bake groups of a context built as ``kind``, from mujoco-warp-pbr's ``default`` set.

    Raises:
        ValueError: ``kind`` is not one of :data:`KINDS`.
    """
    if kind == "inlined":
        return frozenset(default)
    if kind == "compact":
        return (frozenset(default) - {"nlight"}) | FIXED_GROUPS
    raise ValueError(f"unknown pbr kernel build {kind!r}; expected one of {KINDS}")


@contextlib.contextmanager
def building(kind: str) -> Iterator[None]:
    """While inside, megakernels this thread has mujoco-warp-pbr build follow ``kind`` (the traversal
    calls of a ``compact`` build are not inlined); wrap every ``mujoco_warp_pbr.render`` call in it."""
    if kind not in KINDS:
        raise ValueError(f"unknown pbr kernel build {kind!r}; expected one of {KINDS}")
    _install()
    previous = getattr(_building, "kind", None)
    _building.kind = kind
    try:
        yield
    finally:
        _building.kind = previous


def _not_inlined(function: Any) -> Any:
    """``function`` (a ``warp.Function``) marked to compile as a called function, in every overload."""
    function.inline_hint = "noinline"
    for overload in getattr(function, "user_overloads", {}).values():
        overload.inline_hint = "noinline"
    return function


def _geom_test(cast: Any) -> Any | None:
    """The per-geom ray test (``intersect``) that mujoco-warp-pbr's ordered traversal ``cast`` calls, or None."""
    return nested_function(cast, "intersect")


def nested_function(root: Any, name: str) -> Any | None:
    """The ``warp.Function`` named ``name`` that ``root`` (a ``warp.Function``) calls through its closure,
    directly or through other such functions; None where it calls none of that name."""
    pending, seen = [root], set()
    while pending:
        function = pending.pop()
        body = getattr(function, "func", None)
        if body is None or id(function) in seen:
            continue
        seen.add(id(function))
        if body.__name__ == name and function is not root:
            return function
        for cell in body.__closure__ or ():
            try:
                value = cell.cell_contents
            except ValueError:          # a free variable not bound yet
                continue
            if hasattr(value, "func") and hasattr(value, "inline_hint"):
                pending.append(value)
    return None


def _install() -> None:
    """Wrap mujoco-warp-pbr's ``trace.make_trace`` (which both tiers' kernel builders call for their two
    traversal functions), ``traverse.make_ordered_cast`` (the traversal they wrap) and
    ``render.make_render_pixel`` (the real-time tier's per-pixel body), once per process (:func:`building`
    runs every frame: after the first, this returns at once)."""
    global _installed
    if _installed:
        return
    from mujoco_warp_pbr._src import render, trace, traverse
    with _install_lock:
        original: Callable = trace.make_trace
        if getattr(original, "graphsdg_kernel_build", False):
            _installed = True
            return
        original_cast: Callable = traverse.make_ordered_cast

        def make_trace(*args, **kwargs):
            closest, any_hit = original(*args, **kwargs)
            if getattr(_building, "kind", None) == "compact":
                closest = _not_inlined(closest) if "closest" in CALLED_TRAVERSALS else closest
                any_hit = _not_inlined(any_hit) if "any" in CALLED_TRAVERSALS else any_hit
            return closest, any_hit

        def make_ordered_cast(geom_ray_types, first_hit):
            cast = original_cast(geom_ray_types, first_hit)
            wanted = "any-geom" if first_hit else "closest-geom"
            if getattr(_building, "kind", None) == "compact" and wanted in CALLED_TRAVERSALS:
                test = _geom_test(cast)
                if test is None:
                    log.warning("mujoco-warp-pbr's traversal has no per-geom test to call; it stays inlined")
                else:
                    _not_inlined(test)
            return cast

        original_pixel: Callable = render.make_render_pixel

        def make_render_pixel(*args, **kwargs):
            pixel = original_pixel(*args, **kwargs)
            if getattr(_building, "kind", None) == "compact":
                for cut, name in _PIXEL_FUNCTIONS.items():
                    if cut not in CALLED_TRAVERSALS:
                        continue
                    function = nested_function(pixel, name)
                    if function is None:
                        log.warning("mujoco-warp-pbr's pixel body has no %s to call; it stays inlined", name)
                    else:
                        _not_inlined(function)
            return pixel

        make_trace.graphsdg_kernel_build = True
        trace.make_trace = make_trace
        traverse.make_ordered_cast = make_ordered_cast
        render.make_render_pixel = make_render_pixel
        _installed = True
