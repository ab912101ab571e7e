"""What compressing a frame's colour PNG on the GPU costs: graphsdg.render.device_png on one frame, timed.

Encodes FRAME (an RGBA PNG, e.g. a bench frame's ``rgb_0003.png``) with :class:`graphsdg.render.device_png.
DevicePng` on a Warp device and reports its stream's size against ISA-L level 1's (what ``encode_png`` makes on
the CPU), the host CPU of queueing one encode with plain launches and, on a GPU, as a recorded graph's replay
(how the pbr backend queues it), and the device time of each kernel and copy (Warp's activity timing).

Usage:
    python bench/png_on_device.py FRAME.png [--device cuda:0] [--frames 300]
"""
from __future__ import annotations

import argparse
import time
import zlib

import numpy as np
import warp as wp

from graphsdg.io.png import encode_png, filtered_lines
from graphsdg.render import device_png


def _per_frame(run, frames: int, device: str) -> tuple[float, float]:
    """Wall and this process's CPU seconds of ``run()`` a frame, the device synchronized around the loop."""
    run()
    wp.synchronize_device(device)
    start, cpu = time.perf_counter(), time.process_time()
    for _ in range(frames):
        run()
    wp.synchronize_device(device)
    return (time.perf_counter() - start) / frames, (time.process_time() - cpu) / frames


def main() -> None:
    import cv2
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("image", help="an RGBA PNG (a frame's rgb)")
    parser.add_argument("--device", default="cuda:0" if wp.get_cuda_device_count() else "cpu")
    parser.add_argument("--frames", type=int, default=300, help="encodes timed")
    args = parser.parse_args()
    image = cv2.imread(args.image, cv2.IMREAD_UNCHANGED)
    if image is None or image.ndim != 3 or image.shape[2] != 4:
        parser.error(f"cannot read {args.image!r} as an RGBA image")
    if args.frames < 1:
        parser.error(f"--frames takes 1 or more, got {args.frames}")
    height, width = image.shape[:2]
    words = wp.zeros(device_png.stream_words(width, height), dtype=wp.uint32, device=args.device)
    meta = wp.zeros(2, dtype=wp.int64, device=args.device)
    png = device_png.DevicePng(width, height, args.device, words, meta)
    rgba = wp.array(np.ascontiguousarray(image).view(np.uint32).reshape(-1), dtype=wp.uint32, device=args.device)
    png.queue(rgba)
    stream = device_png.zlib_stream(meta.numpy(), words.numpy())
    if stream is None:
        parser.error(f"{args.image}'s stream is longer than the room a layout reads back")
    assert zlib.decompress(stream) == filtered_lines(image).tobytes()
    rows = [f"{width}x{height} on {args.device}: {len(stream):,} bytes of stream against ISA-L level 1's "
            f"{len(encode_png(image)) - 57:,}"]
    _, cpu = _per_frame(lambda: png.queue(rgba), args.frames, args.device)
    rows.append(f"host CPU a frame, plain launches: {1000 * cpu:.3f} ms")
    if wp.get_device(args.device).is_cuda:
        with wp.ScopedCapture(device=args.device, force_module_load=False) as capture:
            png.queue(rgba)
        words.zero_()
        wp.capture_launch(capture.graph)
        assert device_png.zlib_stream(meta.numpy(), words.numpy()) == stream
        wall, cpu = _per_frame(lambda: wp.capture_launch(capture.graph), args.frames, args.device)
        rows.append(f"a recorded graph's replay: {1000 * cpu:.3f} ms host CPU, {1000 * wall:.3f} ms wall a frame")
        wp.timing_begin(cuda_filter=wp.TIMING_ALL)
        for _ in range(args.frames):
            png.queue(rgba)
        spent: dict[str, float] = {}
        for result in wp.timing_end():
            spent[result.name] = spent.get(result.name, 0.0) + result.elapsed / args.frames
        rows.append(f"device time a frame {1000 * sum(spent.values()):.1f} us: " + ", ".join(
            f"{name} {1000 * ms:.1f}" for name, ms in sorted(spent.items(), key=lambda kv: -kv[1])))
    start = time.perf_counter()
    for _ in range(args.frames):
        encode_png(image)
    rows.append(f"ISA-L (encode_png) on one core: {1000 * (time.perf_counter() - start) / args.frames:.3f} ms")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
