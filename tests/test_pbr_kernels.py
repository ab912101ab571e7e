"""The pbr backend's own kernels on Warp's CPU device, and how it has mujoco-warp-pbr build its megakernel."""
from __future__ import annotations

import numpy as np
import pytest

wp = pytest.importorskip("warp")

from graphsdg.base import settings_store  # noqa: E402
from graphsdg.render import pbr_kernel  # noqa: E402
from graphsdg.render import pbr_outputs as po  # noqa: E402


def _numpy_bounds(codes: np.ndarray, n: int) -> np.ndarray:
    bounds = np.tile(np.array([2**31 - 1, 2**31 - 1, -1, -1], dtype=np.int32), (n, 1))   # _clear_boxes' rows
    for code in np.unique(codes):
        ys, xs = np.nonzero(codes == code)
        bounds[code] = (xs.min(), ys.min(), xs.max(), ys.max())
    return bounds


@pytest.mark.parametrize("width", [1, po.BOX_SPAN - 1, po.BOX_SPAN, 3 * po.BOX_SPAN + 7])
def test_code_boxes_are_every_codes_pixel_bounds_whatever_the_row_spans(width):
    rng = np.random.default_rng(width)
    height, ncode = 23, 9
    codes = np.zeros((height, width), dtype=np.uint8)
    for code in range(1, ncode):          # rectangles that cross span boundaries, overlapping each other
        x0, y0 = rng.integers(0, width), rng.integers(0, height)
        codes[y0:y0 + rng.integers(1, height), x0:x0 + rng.integers(1, width + 1)] = code
    codes[rng.integers(0, height), rng.integers(0, width)] = ncode - 1    # a lone pixel
    device_codes = wp.array(codes.ravel(), dtype=wp.uint8, device="cpu")
    boxes = wp.zeros((ncode, 4), dtype=wp.int32, device="cpu")
    wp.launch(po._clear_boxes, dim=ncode, inputs=[boxes], device="cpu")
    wp.launch(po._code_boxes, dim=(height, -(-width // po.BOX_SPAN)), inputs=[device_codes, width, boxes],
              device="cpu")
    assert np.array_equal(boxes.numpy(), _numpy_bounds(codes, ncode))


def test_compact_build_loops_lights_and_bakes_what_a_context_holds_fixed():
    default = frozenset({"samples_per_axis", "nlight", "has_env", "render_order"})
    compact = pbr_kernel.baked_groups("compact", default)
    assert "nlight" not in compact and {"samples_per_axis", "has_env", "render_order"} <= compact
    assert pbr_kernel.FIXED_GROUPS <= compact
    # what depends on a product's size stays a runtime value, so products of other sizes share the kernel
    assert not {"total_rays", "clip", "inv_texel_angle"} & compact
    assert pbr_kernel.baked_groups("inlined", default) == default


def test_the_kernel_build_is_a_validated_setting():
    assert pbr_kernel.requested_kind() == "compact"
    with pytest.raises(ValueError, match="inlined"):
        settings_store.set(pbr_kernel.KIND_KEY, "fast")
    with pytest.raises(ValueError, match="'fast'"):
        pbr_kernel.baked_groups("fast", frozenset())
    settings_store.set(pbr_kernel.KIND_KEY, "inlined")
    try:
        assert pbr_kernel.requested_kind() == "inlined"
    finally:
        settings_store.set(pbr_kernel.KIND_KEY, "compact")


def test_fixed_groups_are_mujoco_warp_pbr_bake_groups():
    kernel_inputs = pytest.importorskip("mujoco_warp_pbr._src.kernel_inputs")
    assert pbr_kernel.FIXED_GROUPS <= kernel_inputs.BAKE_GROUPS.keys()


def test_a_compact_build_calls_each_traversals_geom_test_and_inlines_the_traversals():
    traverse = pytest.importorskip("mujoco_warp_pbr._src.traverse")
    trace = pytest.importorskip("mujoco_warp_pbr._src.trace")
    types = (6, 7)     # boxes and meshes

    def hints(kind):
        with pbr_kernel.building(kind):
            closest, any_hit = trace.make_trace(types, True, True)
            shadow, camera = traverse.make_ordered_cast(types, True), traverse.make_ordered_cast(types, False)
        return (closest.inline_hint, any_hit.inline_hint, pbr_kernel._geom_test(shadow).inline_hint,
                pbr_kernel._geom_test(camera).inline_hint)

    assert hints("compact") == (None, None, "noinline", "noinline")
    assert hints("inlined") == (None, None, None, None)
    assert pbr_kernel._geom_test(traverse.make_ordered_cast(types, True)).inline_hint is None   # outside a build
    with pytest.raises(ValueError, match="'fast'"):
        with pbr_kernel.building("fast"):
            pass


def _nested_functions():
    @wp.func
    def shadow_test(x: float) -> float:
        return x * 2.0

    @wp.func
    def shade(x: float) -> float:
        return shadow_test(x) + 1.0

    @wp.func
    def pixel(x: float) -> float:
        return shade(x)

    return pixel, shade, shadow_test


def test_nested_function_finds_a_function_called_through_closures_and_only_those():
    pixel, shade, shadow_test = _nested_functions()
    assert pbr_kernel.nested_function(pixel, "shadow_test") is shadow_test
    assert pbr_kernel.nested_function(pixel, "shade") is shade
    assert pbr_kernel.nested_function(pixel, "pixel") is None          # the root is not its own callee
    assert pbr_kernel.nested_function(shadow_test, "shade") is None    # callers are not searched


def test_gathered_uploads_go_in_one_copy_and_keep_what_was_not_put():
    from graphsdg.render.pbr_uploads import PinnedUploads
    uploads = PinnedUploads("cpu")
    poses = wp.array(np.arange(6, dtype=np.float32).reshape(2, 3), dtype=wp.vec3, device="cpu")
    ids = wp.array(np.array([7, 8], dtype=np.int32), device="cpu")
    empty = wp.zeros((1, 0), dtype=wp.vec3, device="cpu")
    moved = uploads.gather({"poses": poses, "ids": ids, "empty": empty})
    assert sorted(moved) == ["ids", "poses"]                  # the empty array stays where it is
    assert moved["poses"].numpy().tolist() == [[0, 1, 2], [3, 4, 5]] and moved["ids"].numpy().tolist() == [7, 8]
    copies = []
    original = wp.copy
    wp.copy = lambda *a, **k: (copies.append(a), original(*a, **k))[1]
    try:
        uploads.begin()
        uploads.put("poses", moved["poses"], [[1, 1, 1], [2, 2, 2]])
        assert moved["poses"].numpy()[0].tolist() == [0, 1, 2]   # sent at the round's end, not before
        uploads.end()
        assert len(copies) == 1
        uploads.begin()
        uploads.put("ids", moved["ids"], [5, 6])
        uploads.put("own", ids, [1, 2])                          # not gathered: a copy of its own
        uploads.end()
    finally:
        wp.copy = original
    assert len(copies) == 3
    assert moved["poses"].numpy().tolist() == [[1, 1, 1], [2, 2, 2]] and moved["ids"].numpy().tolist() == [5, 6]
    assert ids.numpy().tolist() == [1, 2]
    with pytest.raises(ValueError, match="'poses': 3 values"):
        uploads.put("poses", moved["poses"], [1, 2, 3])
    with pytest.raises(RuntimeError, match="already"):
        uploads.gather({"ids": ids})


def _fill_layout(layout: po.ClassicLayout, value: int) -> None:
    """Fill ``layout``'s device outputs with ``value`` (what a conversion of a frame leaves there)."""
    layout.rgba.fill_(value)
    layout.depth.fill_(float(value))
    layout.codes.fill_(value % 5)
    layout.queue_boxes()                   # as convert(..., boxes=True) queues them after the conversion


def _layout_frame(layout: po.ClassicLayout, value: int, reads: list | None = None) -> po.HostFrame:
    """Fill ``layout``'s device outputs with ``value`` and read them back as a host frame (the read appended
    to ``reads``)."""
    _fill_layout(layout, value)
    read = layout.queue_read(colour=True, depth=True, ids=True)
    if reads is not None:
        reads.append(read)
    return layout.take(read)


def test_host_frames_are_lent_views_that_no_later_read_overwrites():
    h, w = 3, 5
    layout = po.ClassicLayout(w, h, np.ones((h, w)), 0.0, 100.0, "cpu", ngeom=4)
    kept = [_layout_frame(layout, v) for v in range(po.HOST_BUFFERS + 3)]   # more than the buffers: copies too
    for v, frame in enumerate(kept):
        assert np.all(frame.rgba.view(np.uint32) == v) and np.all(frame.depth == v)
        assert np.all(frame.codes == v % 5) and frame.codes.shape == (h, w)
        assert frame.code_boxes[v % 5].tolist() == [0, 0, w - 1, h - 1]
        assert np.all(np.delete(frame.code_boxes, v % 5, axis=0) == -1)
    assert layout.host.lent() == po.HOST_BUFFERS
    lent = kept[0].rgba
    assert not lent.flags.owndata and kept[-1].rgba.base is not None
    del kept, frame
    assert layout.host.lent() == 1                     # only the first frame's rgba still holds its buffer
    for v in range(20):                                # the freed buffers are read into again, no new ones
        frame = _layout_frame(layout, 100 + v)
        assert np.all(frame.depth == 100 + v)
    assert np.all(lent.view(np.uint32) == 0) and len(layout.host._buffers) == po.HOST_BUFFERS


def test_reads_queued_together_each_keep_their_own_frame():
    """Two frames' reads queued before either is taken (a pipelined step's frame still copying when the next
    renders) each read their own frame, in buffers of their own or, with every buffer lent, the later one
    taking the earlier one's spare copy out first."""
    h, w = 3, 5
    layout = po.ClassicLayout(w, h, np.ones((h, w)), 0.0, 100.0, "cpu", ngeom=4)
    queued = []
    for v in (7, 8):
        _fill_layout(layout, v)
        queued.append(po.queue_reads([(layout, True, True, True, False, 0)]))
    first, second = (q.hosts()[0] for q in queued)
    assert np.all(first.depth == 7) and np.all(second.depth == 8) and np.all(first.rgba.view(np.uint32) == 7)
    kept = [_layout_frame(layout, v) for v in range(po.HOST_BUFFERS - 2)]   # every buffer lent now
    _fill_layout(layout, 20)
    earlier = po.queue_reads([(layout, True, True, True, False, 0)])        # into the spare
    assert not earlier.taken
    _fill_layout(layout, 21)
    later = po.queue_reads([(layout, True, True, True, False, 0)])          # the spare again: takes `earlier`
    assert earlier.taken
    assert np.all(earlier.hosts()[0].depth == 20) and np.all(later.hosts()[0].depth == 21)
    assert [int(f.depth[0, 0]) for f in kept] == list(range(po.HOST_BUFFERS - 2))


def test_large_frames_lend_fewer_buffers():
    counts = {}
    for side in (2048, 3000, 4096):       # ~36, ~81 and ~144 MiB a frame (colour, depth, one-byte codes)
        layout = po.ClassicLayout(side, side, np.ones((side, side)), 0.0, 100.0, "cpu", ngeom=4)
        counts[side] = layout.host.count
        assert counts[side] * layout.host.nbytes <= po.HOST_BUFFER_BYTES or counts[side] == 1
    assert counts == {2048: po.HOST_BUFFERS, 3000: 3, 4096: 1}


def test_a_read_with_every_buffer_lent_waits_for_their_release_instead_of_copying():
    """With ``wait_for_release``, a read finding every host buffer lent waits while it says a holder may let go
    (the write queue), reads into the freed buffer, and copies only once nothing more will be released."""
    import threading

    from graphsdg.io.write_queue import WriteQueue

    h, w = 3, 5
    queue = WriteQueue(num_threads=1, max_size=100)
    layout = po.ClassicLayout(w, h, np.ones((h, w)), 0.0, 100.0, "cpu", ngeom=4,
                              wait_for_release=queue.wait_for_progress)
    gate = threading.Event()
    for v in range(po.HOST_BUFFERS):          # every buffer's frame held by a write that has not run yet
        queue.schedule(lambda frame: gate.wait(), _layout_frame(layout, v))
    assert layout.host.lent() == po.HOST_BUFFERS
    threading.Timer(0.05, gate.set).start()
    reads: list = []
    frame = _layout_frame(layout, 50, reads)
    assert not reads[-1].spare                              # read into a freed buffer, not the spare
    assert np.all(frame.rgba.view(np.uint32) == 50) and queue.completed >= 1
    queue.wait_until_done()
    kept = [frame] + [_layout_frame(layout, v, reads) for v in range(po.HOST_BUFFERS)]   # held: nothing to wait for
    assert reads[-1].spare                                  # the last one read into the spare and copied
    assert [int(f.depth[0, 0]) for f in kept] == [50] + list(range(po.HOST_BUFFERS))
    queue.shutdown()
