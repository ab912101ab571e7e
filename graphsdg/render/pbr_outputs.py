"""mujoco-warp-pbr's raw output buffers -> host arrays in the classic layout, converted on the GPU.

The renderer leaves one camera's pixels in three device buffers: colour packed as
``0xAARRGGBB`` words (8-bit sRGB), the hit distance along each ray, and
``(object id, object type)`` pairs. Annotators want RGBA bytes, planar depth with
``inf`` on misses and past the far plane, and the geom drawn at each pixel as the
classic path reads it back: id codes (geom id + 1, 0 for background) in the fewest
bytes that hold them, with their code -> geom table
(:class:`~graphsdg.render.backend.RenderOutputs`), and each code's pixel bounds (the
tight boxes' and drawn-geom lists' input, :class:`HostFrame`). One kernel converts all three
where the pixels already are (one launch per camera of a batched render); a camera's outputs
share one device allocation, so its asked-for arrays come back in one copy into page-locked
host memory, all cameras' copies behind one event, waited for when the pixels are first used
(a pipelined step's go on copying while the script randomizes the next frame). The host arrays
are views of that page-locked buffer, not copies of it: a layout keeps a few buffers and reads
into one that no array of an earlier frame still uses (:class:`HostBuffers`). About a quarter
of the bytes the renderer's own float
``get_rgb`` readback moves, and no per-pixel numpy work on the CPU (scenes under 255
geoms: one byte of ids a pixel instead of four, and no int32 -> code pass on the host). A layout may
also colour class masks from the ids with palettes the annotators will look up, and compress the colour's
and the masks' PNG rows (:mod:`graphsdg.render.device_png`), read back in the same copy.

Imports Warp (``graphsdg[gpu]``); :mod:`graphsdg.render.pbr` loads it on construction.
"""
from __future__ import annotations

import ctypes
import weakref
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np
import warp as wp

from graphsdg.imaging.label_image import label_image
from graphsdg.imaging.precompressed import precompressed
from graphsdg.render import device_png
from graphsdg.render.polling import wait_until

GEOM_TYPE = 5          # mujoco.mjtObj.mjOBJ_GEOM, as the renderer writes it into segmentation pairs


@wp.kernel(enable_backward=False)
def _classic_layout(packed: wp.array2d[wp.uint32], distance: wp.array2d[wp.float32], seg: wp.array2d[wp.vec2i],
                    rgb_adr: int, depth_adr: int, seg_adr: int, cosines: wp.array[wp.float32], near: float,
                    far: float, rgba: wp.array[wp.uint32], depth: wp.array[wp.float32], codes: wp.array(dtype=Any)):
    p = wp.tid()
    word = packed[0, rgb_adr + p]
    # 0xAARRGGBB -> bytes R, G, B, A in memory (little endian 0xAABBGGRR)
    rgba[p] = (word & wp.uint32(0xFF00FF00)) | ((word >> wp.uint32(16)) & wp.uint32(0xFF)) \
        | ((word & wp.uint32(0xFF)) << wp.uint32(16))
    pair = seg[0, seg_adr + p]
    geom = wp.where(pair[1] == GEOM_TYPE, pair[0], -1)
    codes[p] = codes.dtype(geom + 1)      # one instance of the kernel per code type (uint8, uint16, uint32)
    z = near + distance[0, depth_adr + p] * cosines[p]
    if geom < 0 or z > far:
        z = wp.inf
    depth[p] = z


@wp.kernel(enable_backward=False)
def _colour_codes(codes: wp.array(dtype=Any), palettes: wp.array2d[wp.uint32], palette: int,
                  colours: wp.array[wp.uint32]):
    # a class mask: each pixel's code through one palette (code -> packed RGBA)
    p = wp.tid()
    colours[p] = palettes[palette, int(codes[p])]


@wp.kernel(enable_backward=False)
def _clear_boxes(boxes: wp.array2d[wp.int32]):
    i = wp.tid()
    boxes[i, 0] = 2147483647
    boxes[i, 1] = 2147483647
    boxes[i, 2] = -1
    boxes[i, 3] = -1


#: page-locked buffers a layout lends out as frames' arrays before it copies them instead (HostBuffers): a
#: pipelined step holds one frame's, its writer threads the few frames they have not written yet; fewer where
#: that many would lock more than HOST_BUFFER_BYTES of host memory (large frames), but at least one
HOST_BUFFERS = 6
HOST_BUFFER_BYTES = 256 << 20

#: pixels of a row one thread of :func:`_code_boxes` walks: a row a thread left 512 threads for a 512x512 frame,
#: each walking 512 pixels one after another
BOX_SPAN = 32


@wp.kernel(enable_backward=False)
def _code_boxes(codes: wp.array(dtype=Any), width: int, boxes: wp.array2d[wp.int32]):
    # one thread a span of BOX_SPAN pixels of a row, walking its runs of equal code: only a run's ends can be a
    # code's extremes in x, and every run gives its row to y, so the atomics are per run, not per pixel
    y, part = wp.tid()
    row = y * width
    first = part * BOX_SPAN
    end = wp.min(first + BOX_SPAN, width)
    start = first
    code = int(codes[row + first])
    for x in range(first + 1, end + 1):
        here = int(-1)
        if x < end:
            here = int(codes[row + x])
        if here != code:
            wp.atomic_min(boxes, code, 0, start)
            wp.atomic_min(boxes, code, 1, y)
            wp.atomic_max(boxes, code, 2, x - 1)
            wp.atomic_max(boxes, code, 3, y)
            start = x
            code = here


# Every code type's instance of both generic kernels, declared before the first launch: an instance added at
# a launch changes the module, which Warp then compiles again whole (it did, once per process, for the boxes).
for _code in (wp.uint8, wp.uint16, wp.uint32):
    wp.overload(_classic_layout, {"codes": wp.array(dtype=_code)})
    wp.overload(_code_boxes, {"codes": wp.array(dtype=_code)})
    wp.overload(_colour_codes, {"codes": wp.array(dtype=_code)})


def code_format(ngeom: int) -> tuple[type, int]:
    """(NumPy type of the id codes, length of their code -> geom table) for a model of ``ngeom`` geoms: codes
    run from 0 (background) to ``ngeom``, in uint8 or uint16 when they fit, as the classic path reads them."""
    if ngeom + 1 < 1 << 8:
        return np.uint8, 1 << 8
    if ngeom + 1 < 1 << 16:
        return np.uint16, 1 << 16
    return np.uint32, ngeom + 2


def code_table(ngeom: int) -> np.ndarray:
    """The code -> geom id table of :func:`code_format`: code ``c`` is geom ``c - 1``, code 0 and codes past
    the model -1 (every code of the type indexes it)."""
    _, size = code_format(ngeom)
    table = np.full(size, -1, dtype=np.int32)
    table[1:ngeom + 1] = np.arange(ngeom, dtype=np.int32)
    return table


_WARP_CODE_TYPES = {np.uint8: wp.uint8, np.uint16: wp.uint16, np.uint32: wp.uint32}
_ALIGN = 256           # bytes: each output's start in the layout's one allocation
_QUEUED = lambda: True   # noqa: E731  a buffer's lease while a read into it is queued and not yet taken


class HostBuffers:
    """Page-locked host buffers of ``nbytes`` for one layout's reads, lent out as the frames' arrays.

    A frame's arrays are views of the buffer its pixels were copied into, kept alive by one lease object
    (their common base); the buffer is read into again only once every array of that frame is gone. So a
    frame costs no host copy while annotators and writers let go of its arrays within ``count`` frames,
    and one copy a frame (into arrays of its own, from one more buffer kept for that) while they do not.
    ``wait_for_release`` (optional) is called while every buffer is lent, before settling for the copy: it
    waits for something that may let go of a frame (a queued write finishing) and says whether it did, so
    frames held only by writes that are still running cost a wait instead of a copy.

    Example (Warp's CPU device)::

        buffers = HostBuffers(16, "cpu", count=2)
        index = buffers.acquire()           # a free buffer, or None: read into buffers.spare and copy
        arrays = buffers.lend(index)        # a uint8 view of it; the buffer is free once views are gone
    """

    def __init__(self, nbytes: int, device: str, count: int,
                 wait_for_release: Callable[[], bool] | None = None) -> None:
        self.nbytes, self.count, self.wait_for_release = nbytes, count, wait_for_release
        self._pinned = wp.get_device(device).is_cuda
        self._lease_type = ctypes.c_uint8 * nbytes    # a lease: the buffer's bytes as an object of their own
        self._buffers: list[Any] = []                 # Warp host arrays
        self._leases: list[Callable[[], Any]] = []    # per buffer: its lease (a weak reference) or _QUEUED
        self._spare: Any = None

    @property
    def spare(self) -> Any:
        """The buffer read into when none is free (its contents are copied out by the taker)."""
        if self._spare is None:
            self._spare = self._allocate()
        return self._spare

    def buffer(self, index: int) -> Any:
        """Buffer ``index`` (a Warp host array of uint8)."""
        return self._buffers[index]

    def acquire(self) -> int | None:
        """A buffer no frame's arrays use (made while fewer than ``count`` exist), marked queued; None if none
        is free and ``wait_for_release`` has nothing more to wait for."""
        index = self._free()
        while index is None and self.wait_for_release is not None and self.wait_for_release():
            index = self._free()
        return index

    def _free(self) -> int | None:
        for index, lease in enumerate(self._leases):
            if lease() is None:
                self._leases[index] = _QUEUED
                return index
        if len(self._buffers) < self.count:
            self._buffers.append(self._allocate())
            self._leases.append(_QUEUED)
            return len(self._buffers) - 1
        return None

    def lend(self, index: int) -> np.ndarray:
        """Buffer ``index`` as a uint8 array whose base is a fresh lease: the buffer is free again once that
        array and every view of it are gone."""
        buffer = self._buffers[index]
        lease = self._lease_type.from_address(buffer.ptr)
        lease.buffer = buffer          # the page-locked memory outlives the arrays, whatever becomes of the layout
        self._leases[index] = weakref.ref(lease)
        return np.frombuffer(lease, dtype=np.uint8)

    def lent(self) -> int:
        """Buffers whose arrays are still in use or whose read is queued."""
        return sum(lease() is not None for lease in self._leases)

    def _allocate(self) -> Any:
        return wp.empty(self.nbytes, dtype=wp.uint8, device="cpu", pinned=self._pinned)


@dataclass
class HostFrame:
    """One render's host arrays (None: not asked for)."""

    rgba: np.ndarray | None       # (H, W, 4) uint8
    depth: np.ndarray | None      # (H, W) float32 planar z, inf on misses and beyond the far plane
    codes: np.ndarray | None      # (H, W) id codes (:func:`code_format`): geom id + 1, 0 background
    code_boxes: np.ndarray | None = None   # (ngeom + 1, 4) int32 inclusive pixel bounds x_min, y_min, x_max,
    #                                        y_max of each code (row = code), -1 rows for codes not drawn
    id_colours: tuple = ()        # (H, W, 4) uint8 label images, one per palette (ClassicLayout.set_palettes)


class ClassicLayout:
    """Device buffers and page-locked host buffers of one camera's outputs at one resolution, for a model of
    ``ngeom`` geoms (the id codes' type, :func:`code_format`).

    ``cosines``: (H, W) cosine between each pixel's ray and the optical axis (planar depth = near + t cos);
    ``wait_for_release``: as :class:`HostBuffers` takes it; ``png``: also compress the colour's PNG rows on the device
    (:mod:`graphsdg.render.device_png`), read back with the colour, so the frame's colour array is a
    :class:`~graphsdg.imaging.precompressed.PrecompressedImage` (where the image fits :func:`device_png.fits`);
    ``masks``: room for that many class masks coloured on the device from the ids (:meth:`set_palettes`), each
    compressed there too with ``png``.
    """

    def __init__(self, width: int, height: int, cosines: np.ndarray, near: float, far: float, device: str,
                 ngeom: int, wait_for_release: Callable[[], bool] | None = None, png: bool = False,
                 masks: int = 0) -> None:
        n = width * height
        self.shape, self.near, self.far, self.device = (height, width), float(near), float(far), device
        self.ngeom = int(ngeom)
        code_type, _ = code_format(self.ngeom)
        self.table = code_table(self.ngeom)
        self.cosines = wp.array(np.ascontiguousarray(cosines, dtype=np.float32).ravel(), dtype=wp.float32,
                                device=device)
        # The outputs lie in one device allocation, mirrored by one page-locked host buffer, so a frame's reads
        # are one copy of the span they cover, not one per array (each copy is a driver call of its own).
        png = png and device_png.fits(width, height)
        # the stream right after the colour: a read of the colour alone is one span without the other passes
        words = device_png.stream_words(width, height)
        stream = [("png_meta", wp.int64, (2,)), ("png_words", wp.uint32, (words,))]
        parts = [("rgba", wp.uint32, (n,)), *(stream if png else []), ("depth", wp.float32, (n,)),
                 ("codes", _WARP_CODE_TYPES[code_type], (n,)), ("boxes", wp.int32, (self.ngeom + 1, 4))]
        self.masks = int(masks)
        for k in range(self.masks):          # after the ids: a read of the ids and masks is one span
            parts += [(f"mask{k}", wp.uint32, (n,)),
                      *([(f"mask{k}_meta", wp.int64, (2,)), (f"mask{k}_words", wp.uint32, (words,))] if png else [])]
        self._spans: dict[str, tuple[int, int, np.dtype, tuple]] = {}
        end = 0
        for name, dtype, shape in parts:
            start = -(-end // _ALIGN) * _ALIGN
            end = start + int(np.prod(shape)) * wp.types.type_size_in_bytes(dtype)
            self._spans[name] = (start, end, np.dtype(wp.dtype_to_numpy(dtype)), shape)
        self._device_bytes = wp.empty(end, dtype=wp.uint8, device=device)
        self.host = HostBuffers(end, device, max(1, min(HOST_BUFFERS, HOST_BUFFER_BYTES // end)), wait_for_release)
        self._spare_read: QueuedReads | None = None   # the reads whose copy into the spare buffer is not taken
        for name, dtype, shape in parts:    # typed views of the allocation, which the layout keeps alive
            setattr(self, name, wp.array(ptr=self._device_bytes.ptr + self._spans[name][0], dtype=dtype,
                                         shape=shape, device=device))
        self.png = device_png.DevicePng(width, height, device, self.png_words, self.png_meta) if png else None
        self._mask_pngs = [device_png.DevicePng(width, height, device, getattr(self, f"mask{k}_words"),
                                                getattr(self, f"mask{k}_meta"), device_png.LABEL_CODES)
                           if png else None for k in range(self.masks)]
        # per mask, the code -> packed RGBA table the ids are coloured with, and the host copy last sent
        self._palettes = wp.zeros((max(1, self.masks), len(self.table)), dtype=wp.uint32, device=device)
        self._sent_palettes: np.ndarray | None = None
        self._palettes_given: tuple = ()
        self._adrs: dict[tuple, int] = {}

    def set_palettes(self, palettes: Sequence[np.ndarray]) -> None:
        """Colour the class masks of the frames converted from now on with ``palettes`` (at most :attr:`masks`
        of them): each a packed RGBA (uint32) per geom id, the background's last (index -1), as
        :meth:`FrameView.colorized_id_image <graphsdg.annotate.frame.FrameView.colorized_id_image>` looks them
        up. Sent to the device only when they change (queued before the conversion that uses them)."""
        if len(palettes) > self.masks:
            raise ValueError(f"{len(palettes)} palettes for a layout with room for {self.masks} class masks")
        if not palettes or (len(palettes) == len(self._palettes_given)
                            and all(a is b for a, b in zip(palettes, self._palettes_given))):
            return                   # the same arrays as last frame (kept by the labels until they change)
        self._palettes_given = tuple(palettes)
        per_code = np.stack([np.asarray(p, dtype=np.uint32)[self.table] for p in palettes])   # code -> geom -> RGBA
        if self._sent_palettes is not None and np.array_equal(per_code, self._sent_palettes[:len(palettes)]):
            return
        sent = np.zeros(self._palettes.shape, dtype=np.uint32)
        sent[:len(palettes)] = per_code
        wp.copy(self._palettes, wp.array(sent, dtype=wp.uint32, device="cpu"))   # pageable: staged before return
        self._sent_palettes = sent

    def convert(self, base, camera: int, boxes: bool = False, png: bool = True, masks: int = 0) -> None:
        """Queue the conversion of camera ``camera``'s pixels of render context ``base`` (world 0), with
        ``boxes`` their codes' pixel bounds (:meth:`queue_boxes`; a read of the ids needs them), with ``png``
        their colour's PNG stream where this layout compresses it (a read of the colour needs it), and the first
        ``masks`` class masks (:meth:`set_palettes`), compressed where this layout compresses."""
        wp.launch(_classic_layout, dim=self.shape[0] * self.shape[1],
                  inputs=[base.rgb_data, base.depth_data, base.seg_data, self._adr(base, "rgb", camera),
                          self._adr(base, "depth", camera), self._adr(base, "seg", camera), self.cosines, self.near,
                          self.far],
                  outputs=[self.rgba, self.depth, self.codes], device=self.device)
        if png and self.png is not None:
            self.png.queue(self.rgba)
        if boxes:
            self.queue_boxes()
        self.queue_masks(masks)

    def queue_masks(self, count: int) -> None:
        """Queue the first ``count`` class masks of the converted ids (:meth:`set_palettes`), each compressed
        where this layout compresses (:attr:`HostFrame.id_colours`)."""
        for k in range(count):
            mask = getattr(self, f"mask{k}")
            wp.launch(_colour_codes, dim=self.shape[0] * self.shape[1], inputs=[self.codes, self._palettes, k],
                      outputs=[mask], device=self.device)
            if self._mask_pngs[k] is not None:
                self._mask_pngs[k].queue(mask)

    def _adr(self, base, kind: str, camera: int) -> int:
        """The camera's first pixel in one of ``base``'s buffers (read from the device once)."""
        key = (id(base), kind, camera)
        if key not in self._adrs:
            self._adrs[key] = int(getattr(base, f"{kind}_adr").numpy()[camera])
        return self._adrs[key]

    def queue_boxes(self) -> None:
        """Queue the pixel bounds of every code of the converted ids (:attr:`HostFrame.code_boxes`), so the
        annotators' tight boxes and drawn-geom lists need no pass over the pixels on the CPU."""
        h, w = self.shape
        wp.launch(_clear_boxes, dim=self.ngeom + 1, inputs=[self.boxes], device=self.device)
        wp.launch(_code_boxes, dim=(h, -(-w // BOX_SPAN)), inputs=[self.codes, w, self.boxes], device=self.device)

    def _parts(self, wanted: tuple[bool, bool, bool, bool, int]) -> list[str]:
        """The arrays a read of ``wanted`` (colour, depth, ids, stream, masks) copies, in allocation order."""
        colour, depth, ids, stream, masks = wanted
        compresses = self.png is not None
        wanted = [("rgba", colour), ("png_meta", colour and stream and compresses),
                  ("png_words", colour and stream and compresses), ("depth", depth), ("codes", ids), ("boxes", ids)]
        for k in range(masks):
            wanted += [(f"mask{k}", True), (f"mask{k}_meta", compresses), (f"mask{k}_words", compresses)]
        return [name for name, want in wanted if want]

    def queue_read(self, colour: bool, depth: bool, ids: bool, stream: bool = False, masks: int = 0) -> LayoutRead:
        """Queue one device copy of the span of the asked-for arrays (with the ids, their codes' pixel bounds:
        converted with ``boxes``; with ``stream``, the colour's PNG stream: converted with ``png``; the first
        ``masks`` class masks, with their streams where this layout compresses: converted with as many) into a
        page-locked host buffer; returns the read, for :meth:`take`. Several reads may be queued at once (a
        pipelined step's frame still copying when the next frame renders), each into a buffer of its own."""
        read = LayoutRead((colour, depth, ids, stream, masks), None, False)
        parts = self._parts(read.wanted)
        if parts:
            read.buffer = self.host.acquire()
            read.spare = read.buffer is None
            if read.spare and self._spare_read is not None:
                self._spare_read.hosts()           # the spare holds an earlier read: its arrays are copied out
            target = self.host.spare if read.spare else self.host.buffer(read.buffer)
            lo, hi = self._spans[parts[0]][0], self._spans[parts[-1]][1]
            wp.copy(target, self._device_bytes, dest_offset=lo, src_offset=lo, count=hi - lo)
        return read

    def hold_spare(self, reads: QueuedReads) -> None:
        """Note that ``reads`` copy into the spare buffer: a later read needing it takes them first."""
        self._spare_read = reads

    def release_spare(self, reads: QueuedReads) -> None:
        """Note that ``reads`` were taken (the spare is free again if they held it)."""
        if self._spare_read is reads:
            self._spare_read = None

    def take(self, read: LayoutRead) -> HostFrame:
        """The copies of ``read`` (done) as arrays: views of the page-locked buffer they were read into, lent
        until every one of them is gone (:class:`HostBuffers`), or copies of their own when no buffer was free.
        Annotators and writer threads may keep them past later renders."""
        parts = self._parts(read.wanted)
        if not parts:
            return HostFrame(rgba=None, depth=None, codes=None)
        if read.spare:
            whole, lent = self.host.spare.numpy(), False
        else:
            whole, lent = self.host.lend(read.buffer), True
        own = {}
        for name in parts:
            start, end, dtype, shape = self._spans[name]
            piece = whole[start:end] if lent else np.array(whole[start:end])   # copies keep no other part alive
            own[name] = piece.view(dtype).reshape(shape)
        h, w = self.shape
        rgba, boxes = own.get("rgba"), own.get("boxes")
        if boxes is not None:
            boxes[boxes[:, 2] < 0] = -1          # codes no pixel has: -1 rows, as the classic path's boxes
        if rgba is not None:
            rgba = _compressed(rgba.view(np.uint8).reshape(h, w, 4), own, "png")
        masks = tuple(_compressed(own[f"mask{k}"].view(np.uint8).reshape(h, w, 4), own, f"mask{k}", labels=True)
                      for k in range(read.wanted[4]))
        return HostFrame(rgba=rgba,
                         depth=own["depth"].reshape(h, w) if "depth" in own else None,
                         codes=own["codes"].reshape(h, w) if "codes" in own else None, code_boxes=boxes,
                         id_colours=masks)


def _compressed(image: np.ndarray, own: dict[str, np.ndarray], name: str, labels: bool = False) -> np.ndarray:
    """``image`` with the PNG stream read back beside it (parts ``<name>_meta`` and ``<name>_words``) as a
    :class:`~graphsdg.imaging.precompressed.PrecompressedImage`; as it is (a label image with ``labels``) where
    none was read or the stream was too long for the room read back (the CPU compresses that frame's)."""
    stream = device_png.zlib_stream(own[f"{name}_meta"], own[f"{name}_words"]) if f"{name}_meta" in own else None
    if stream is not None:
        return precompressed(image, stream, labels=labels)
    return label_image(image) if labels else image


@dataclass
class LayoutRead:
    """One read queued by :meth:`ClassicLayout.queue_read`: what it copies, and into which host buffer."""

    wanted: tuple[bool, bool, bool, bool, int]   # colour, depth, ids, stream, masks
    buffer: int | None                           # the layout's host buffer (None: none, or its spare)
    spare: bool                                  # copied into the layout's spare buffer (none was free)


class QueuedReads:
    """Copies queued by :func:`queue_reads`, behind one event: :meth:`hosts` waits for them and takes the arrays,
    once. Until then their page-locked buffers are in use (a layout reads into others meanwhile)."""

    def __init__(self, reads: list[tuple[ClassicLayout, LayoutRead]], done: Any) -> None:
        self._reads, self._done = reads, done
        self._hosts: list[HostFrame] | None = None
        for layout, read in reads:
            if read.spare:
                layout.hold_spare(self)

    @property
    def taken(self) -> bool:
        """Whether :meth:`hosts` took the arrays (the buffers are the frames' now, no longer the reads')."""
        return self._hosts is not None

    def hosts(self) -> list[HostFrame]:
        """Each layout's :class:`HostFrame`, waiting for the copies the first time (polled: CUDA's own
        synchronize would spin a core in its wait)."""
        if self._hosts is None:
            done = self._done
            if done is not None:
                wait_until(lambda: done.is_complete)
            self._hosts = [layout.take(read) for layout, read in self._reads]
            for layout, _ in self._reads:
                layout.release_spare(self)
        return self._hosts


def queue_reads(reads: list[tuple[ClassicLayout, bool, bool, bool, bool, int]]) -> QueuedReads:
    """Queue each ``(layout, colour, depth, ids, stream, masks)``'s asked-for copies, all behind one event."""
    queued = [(layout, layout.queue_read(colour, depth, ids, stream, masks))
              for layout, colour, depth, ids, stream, masks in reads]
    cuda = bool(reads) and wp.get_device(reads[0][0].device).is_cuda   # CPU copies are done when queued
    return QueuedReads(queued, wp.record_event() if cuda else None)


__all__ = ["ClassicLayout", "HostBuffers", "HostFrame", "LayoutRead", "QueuedReads", "code_format", "code_table",
           "queue_reads"]
