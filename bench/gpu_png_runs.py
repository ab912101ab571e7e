"""What a PNG encoder on the GPU costs when every step is a kernel of a thread a pixel: pixel-run deflate, timed.

``bench/gpu_png.py`` parses segments of the filtered lines one thread a segment; on an H200 its parse took
over a millisecond a 512x512 frame (docs/performance.md, round 25), most of it threads walking their segment
byte by byte. This encoder makes a coarser parse in which no thread walks anything (``png_codes.
pixel_run_parse`` is the same parse on the CPU): every pixel of a line takes the first of a few distances back
at which the stream's 4 bytes equal its own, a run of pixels taking the same distance is matches of up to 64
pixels, the rest are literals, and each line's filter byte is a literal. Kernels of a thread a pixel find each
pixel's distance and whether a run starts or ends there, a prefix sum numbers the runs, a scatter records each
run's ends, a kernel counts each pixel's bits, a prefix sum places them, and a last kernel writes them (words
two pixels share are or-ed atomically), behind a dynamic block header of code lengths given once (codes built
from another frame of the kind: the codes of a frame's own symbols would need a wait for their counts). The
Adler-32 is summed a 64-byte chunk a thread into per-line totals, added on the host.

Usage:
    python bench/gpu_png_runs.py FRAME.png [--device cuda:0] [--frames 300] [--codes OTHER.png]
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np
import warp as wp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import png_codes  # noqa: E402  (a bench script beside this one)

from graphsdg.io.png import encode_png, filtered_lines, png_file  # noqa: E402

ADLER = 65521
PIECE = wp.constant(64)        # pixels a match covers at most (256 bytes; deflate's longest is 258)
CHUNK = wp.constant(64)        # stream bytes a thread of the Adler-32 sums


@wp.kernel(enable_backward=False)
def _filter(rgba: wp.array(dtype=wp.uint8), width: int, lines: wp.array(dtype=wp.uint8)):
    # a thread a byte of the filtered lines: the filter type (1, Sub), then each byte minus the pixel's before
    i = wp.tid()
    line = 4 * width + 1
    y = i // line
    k = i - y * line
    if k == 0:
        lines[i] = wp.uint8(1)
    else:
        source = y * 4 * width + k - 1
        value = wp.int32(rgba[source])
        if k > 4:
            value = value - wp.int32(rgba[source - 4])
        lines[i] = wp.uint8(value & 255)


@wp.func
def _word(lines: wp.array(dtype=wp.uint8), b: int) -> wp.uint32:
    return wp.uint32(lines[b]) | (wp.uint32(lines[b + 1]) << wp.uint32(8)) \
        | (wp.uint32(lines[b + 2]) << wp.uint32(16)) | (wp.uint32(lines[b + 3]) << wp.uint32(24))


@wp.kernel(enable_backward=False)
def _modes(lines: wp.array(dtype=wp.uint8), width: int, distances: wp.array(dtype=wp.int32),
           modes: wp.array(dtype=wp.int32)):
    # a thread a pixel: the first distance whose 4 bytes back equal the pixel's, -1 for none
    p = wp.tid()
    y = p // width
    b = y * (4 * width + 1) + 1 + 4 * (p - y * width)
    own = _word(lines, b)
    mode = int(-1)
    for k in range(distances.shape[0]):
        d = distances[k]
        if mode < 0 and b - d >= 0:
            if _word(lines, b - d) == own:
                mode = k
    modes[p] = mode


@wp.func
def _run_starts(modes: wp.array(dtype=wp.int32), width: int, p: int) -> int:
    if modes[p] < 0:
        return 0
    if p % width == 0:
        return 1
    if modes[p - 1] != modes[p]:
        return 1
    return 0


@wp.kernel(enable_backward=False)
def _starts(modes: wp.array(dtype=wp.int32), width: int, starts: wp.array(dtype=wp.int32)):
    p = wp.tid()
    starts[p] = _run_starts(modes, width, p)


@wp.kernel(enable_backward=False)
def _bounds(modes: wp.array(dtype=wp.int32), width: int, runs: wp.array(dtype=wp.int32),
            first: wp.array(dtype=wp.int32), last: wp.array(dtype=wp.int32)):
    # runs: the inclusive prefix sum of the starts, so a run's pixels hold its number + 1
    p = wp.tid()
    if modes[p] < 0:
        return
    if _run_starts(modes, width, p) == 1:
        first[runs[p] - 1] = p
    if p % width == width - 1:
        last[runs[p] - 1] = p
    elif modes[p + 1] != modes[p]:
        last[runs[p] - 1] = p


@wp.func
def _match_pixels(modes: wp.array(dtype=wp.int32), runs: wp.array(dtype=wp.int32), first: wp.array(dtype=wp.int32),
                  last: wp.array(dtype=wp.int32), p: int) -> int:
    """Pixels of the match that starts at pixel ``p`` (0: none starts there)."""
    if modes[p] < 0:
        return 0
    run = runs[p] - 1
    if (p - first[run]) % PIECE != 0:
        return 0
    return wp.min(PIECE, last[run] - p + 1)


@wp.kernel(enable_backward=False)
def _bits(lines: wp.array(dtype=wp.uint8), width: int, modes: wp.array(dtype=wp.int32),
          runs: wp.array(dtype=wp.int32), first: wp.array(dtype=wp.int32), last: wp.array(dtype=wp.int32),
          lengths: wp.array(dtype=wp.int32), match_bits: wp.array(dtype=wp.int32),
          distance_bits: wp.array(dtype=wp.int32), bits: wp.array(dtype=wp.int32)):
    # a thread a pixel: the bits it writes (the line's filter byte with the line's first pixel)
    p = wp.tid()
    y = p // width
    x = p - y * width
    b = y * (4 * width + 1) + 1 + 4 * x
    count = int(0)
    if x == 0:
        count += lengths[int(lines[b - 1])]
    if modes[p] < 0:
        for i in range(4):
            count += lengths[int(lines[b + i])]
    else:
        n = _match_pixels(modes, runs, first, last, p)
        if n > 0:
            count += match_bits[n] + distance_bits[modes[p]]
    bits[p] = count


@wp.func
def _put(words: wp.array(dtype=wp.uint32), bit: int, value: int, count: int) -> int:
    """Or ``count`` bits of ``value`` (fewer than 32) into the stream at bit ``bit``, least significant first;
    the bit after them."""
    if count > 0:
        shifted = wp.uint64(wp.uint32(value)) << wp.uint64(bit & 31)
        wp.atomic_or(words, bit >> 5, wp.uint32(shifted & wp.uint64(0xFFFFFFFF)))
        if (bit & 31) + count > 32:
            wp.atomic_or(words, (bit >> 5) + 1, wp.uint32(shifted >> wp.uint64(32)))
    return bit + count


@wp.kernel(enable_backward=False)
def _write(lines: wp.array(dtype=wp.uint8), width: int, modes: wp.array(dtype=wp.int32),
           runs: wp.array(dtype=wp.int32), first: wp.array(dtype=wp.int32), last: wp.array(dtype=wp.int32),
           lengths: wp.array(dtype=wp.int32), codes: wp.array(dtype=wp.int32), match_codes: wp.array(dtype=wp.int32),
           match_bits: wp.array(dtype=wp.int32), distance_codes: wp.array(dtype=wp.int32),
           distance_bits: wp.array(dtype=wp.int32), header_bits: int, offsets: wp.array(dtype=wp.int32),
           words: wp.array(dtype=wp.uint32)):
    # a thread a pixel: its codes at its offset (the exclusive prefix sum of _bits) after the header
    p = wp.tid()
    y = p // width
    x = p - y * width
    b = y * (4 * width + 1) + 1 + 4 * x
    bit = header_bits + offsets[p]
    if x == 0:
        symbol = int(lines[b - 1])
        bit = _put(words, bit, codes[symbol], lengths[symbol])
    if modes[p] < 0:
        for i in range(4):
            symbol = int(lines[b + i])
            bit = _put(words, bit, codes[symbol], lengths[symbol])
    else:
        n = _match_pixels(modes, runs, first, last, p)
        if n > 0:
            bit = _put(words, bit, match_codes[n], match_bits[n])
            _put(words, bit, distance_codes[modes[p]], distance_bits[modes[p]])


@wp.kernel(enable_backward=False)
def _adler_parts(lines: wp.array(dtype=wp.uint8), line: int, sums: wp.array(dtype=wp.int64),
                 weighted: wp.array(dtype=wp.int64)):
    # a thread a chunk of the stream: its bytes' sum and the sum of position x byte, added to its line's totals
    c = wp.tid()
    start = c * CHUNK
    end = wp.min(start + CHUNK, lines.shape[0])
    total = wp.int64(0)
    moment = wp.int64(0)
    for i in range(start, end):
        value = wp.int64(lines[i])
        total += value
        moment += wp.int64(i) * value
    y = start // line
    wp.atomic_add(sums, y, total)
    wp.atomic_add(weighted, y, moment)


def _match_tables(lengths: np.ndarray, distance_lengths: np.ndarray,
                  distances: list[int]) -> tuple[np.ndarray, ...]:
    """Sent bits and bit counts of a match of n pixels (index n, 1-64: length code and extra bits) and of each
    candidate distance (distance code and extra bits)."""
    codes, distance_codes = png_codes.sent_codes(lengths), png_codes.sent_codes(distance_lengths)
    match_codes, match_bits = np.zeros(PIECE + 1, np.int64), np.zeros(PIECE + 1, np.int64)
    for n in range(1, PIECE + 1):
        slot = int(np.searchsorted(png_codes.LENGTH_BASE, 4 * n, side="right")) - 1
        extra = int(png_codes.LENGTH_EXTRA[slot])
        match_codes[n] = int(codes[257 + slot]) | (4 * n - int(png_codes.LENGTH_BASE[slot])) << int(lengths[257 + slot])
        match_bits[n] = int(lengths[257 + slot]) + extra
    d_codes, d_bits = [], []
    for d in distances:
        slot = int(np.searchsorted(png_codes.DISTANCE_BASE, d, side="right")) - 1
        d_codes.append(int(distance_codes[slot]) | (d - int(png_codes.DISTANCE_BASE[slot])) << int(distance_lengths[slot]))
        d_bits.append(int(distance_lengths[slot]) + int(png_codes.DISTANCE_EXTRA[slot]))
    return match_codes, match_bits, np.array(d_codes, np.int64), np.array(d_bits, np.int64)


def candidate_distances(width: int) -> list[int]:
    """The pixel before, the line above, its pixels before and after, two pixels before (bytes back)."""
    line = 4 * width + 1
    return [d for d in (4, line, line + 4, line - 4, 8) if 0 < d <= 32768]


class PixelRunDeflate:
    """Deflates RGBA uint8 images of one shape on a Warp device, a pixel a thread, with given code lengths."""

    def __init__(self, height: int, width: int, lengths: np.ndarray, distance_lengths: np.ndarray,
                 device: str) -> None:
        self.shape, self.device = (height, width), device
        self.distances = candidate_distances(width)
        self.line = 4 * width + 1
        n, total = height * width, height * self.line
        lengths, distance_lengths = np.asarray(lengths, np.int64), np.asarray(distance_lengths, np.int64)
        header, self.header_bits = png_codes.dynamic_header(lengths, distance_lengths)
        self.end_code, self.end_bits = int(png_codes.sent_codes(lengths)[256]), int(lengths[256])

        def device_array(values, dtype=wp.int32):
            return wp.array(np.asarray(values), dtype=dtype, device=device)
        tables = _match_tables(lengths, distance_lengths, self.distances)
        self.tables = [device_array(t) for t in (lengths[:286], png_codes.sent_codes(lengths)[:286], *tables)]
        self.header = device_array(np.frombuffer(header.to_bytes((self.header_bits + 31) // 32 * 4, "little"),
                                                 np.uint32), wp.uint32)
        self.distance_array = device_array(self.distances)
        self.lines = wp.empty(total, dtype=wp.uint8, device=device)
        self.modes, self.starts, self.runs, self.first, self.last, self.bits, self.offsets = (
            wp.empty(n, dtype=wp.int32, device=device) for _ in range(7))
        self.sums = wp.zeros(height, dtype=wp.int64, device=device)
        self.weighted = wp.zeros(height, dtype=wp.int64, device=device)
        self.words = wp.zeros(total * 15 // 32 + 64, dtype=wp.uint32, device=device)   # 15 bits a byte at most

    def encode(self, rgba: wp.array) -> bytes:
        """The zlib stream of the filtered lines of ``rgba`` (the image's bytes, uint8, on the device)."""
        height, width = self.shape
        n, d = height * width, self.device
        lengths, codes, match_codes, match_bits, distance_codes, distance_bits = self.tables
        wp.launch(_filter, dim=self.lines.shape[0], inputs=[rgba, width, self.lines], device=d)
        wp.launch(_modes, dim=n, inputs=[self.lines, width, self.distance_array, self.modes], device=d)
        wp.launch(_starts, dim=n, inputs=[self.modes, width, self.starts], device=d)
        wp.utils.array_scan(self.starts, self.runs, inclusive=True)
        wp.launch(_bounds, dim=n, inputs=[self.modes, width, self.runs, self.first, self.last], device=d)
        run_inputs = [self.lines, width, self.modes, self.runs, self.first, self.last, lengths]
        wp.launch(_bits, dim=n, inputs=[*run_inputs, match_bits, distance_bits, self.bits], device=d)
        wp.utils.array_scan(self.bits, self.offsets, inclusive=False)
        self.words.zero_()
        wp.copy(self.words, self.header, count=self.header.shape[0])
        wp.launch(_write, dim=n, inputs=[*run_inputs, codes, match_codes, match_bits, distance_codes, distance_bits,
                                         self.header_bits, self.offsets, self.words], device=d)
        self.sums.zero_()
        self.weighted.zero_()
        wp.launch(_adler_parts, dim=-(-self.lines.shape[0] // CHUNK), inputs=[self.lines, self.line, self.sums,
                                                                               self.weighted], device=d)
        end = self.header_bits + int(self.offsets[n - 1:].numpy()[0]) + int(self.bits[n - 1:].numpy()[0])
        last = self.words[end >> 5:(end >> 5) + 1].numpy()
        last |= np.uint32((self.end_code << (end & 31)) & 0xFFFFFFFF)
        body = np.concatenate([self.words[:end >> 5].numpy(), last,
                               np.array([(self.end_code << (end & 31)) >> 32], np.uint32)]).view(np.uint8)
        body = body[:(end + self.end_bits + 7) // 8]
        total, moment = int(self.sums.numpy().sum()), int(self.weighted.numpy().sum())
        size = self.lines.shape[0]
        a, b = (1 + total) % ADLER, (size + size * total - moment) % ADLER
        return b"\x78\x01" + body.tobytes() + ((b << 16) | a).to_bytes(4, "big")

    def png(self, image: np.ndarray) -> bytes:
        """PNG bytes of an (H, W, 4) uint8 image, encoded on the device."""
        height, width = self.shape
        rgba = wp.array(np.ascontiguousarray(image, np.uint8).reshape(-1), dtype=wp.uint8, device=self.device)
        return png_file(width, height, 8, 4, self.encode(rgba))


def codes_of_frames(images: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Code lengths built from the pixel-run parse of other frames, every symbol given a code (counts plus one)."""
    lit_len, distance = np.ones(286, np.int64), np.ones(30, np.int64)
    for image in images:
        lines = filtered_lines(image)
        counts = png_codes.histograms(png_codes.pixel_run_parse(lines, candidate_distances(image.shape[1])))
        lit_len, distance = lit_len + counts[0], distance + counts[1]
    return png_codes.block_code_lengths(lit_len, distance)


def main() -> None:
    import cv2
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("image", help="an RGBA PNG to encode (a frame's rgb or class mask)")
    parser.add_argument("--device", default="cuda:0" if wp.get_cuda_device_count() else "cpu")
    parser.add_argument("--frames", type=int, default=300, help="encodes timed")
    parser.add_argument("--codes", nargs="+", help="PNGs whose parse builds the codes (default: the image's own)")
    args = parser.parse_args()
    image = cv2.imread(args.image, cv2.IMREAD_UNCHANGED)
    if image is None or image.ndim != 3 or image.shape[2] != 4:
        parser.error(f"cannot read {args.image!r} as an RGBA image")
    others = [cv2.imread(p, cv2.IMREAD_UNCHANGED) for p in (args.codes or [args.image])]
    encoder = PixelRunDeflate(*image.shape[:2], *codes_of_frames(others), device=args.device)
    data = encoder.png(image)
    rgba = wp.array(image.reshape(-1), dtype=wp.uint8, device=args.device)
    encoder.encode(rgba)
    wp.synchronize_device(args.device)
    start, cpu_start = time.perf_counter(), time.process_time()
    for _ in range(args.frames):
        encoder.encode(rgba)
    seconds = (time.perf_counter() - start) / args.frames
    host_seconds = (time.process_time() - cpu_start) / args.frames
    device_ms: dict[str, float] = {}
    if wp.get_device(args.device).is_cuda:
        wp.timing_begin(cuda_filter=wp.TIMING_KERNEL | wp.TIMING_MEMCPY | wp.TIMING_MEMSET)
        for _ in range(args.frames):
            encoder.encode(rgba)
        for result in wp.timing_end():
            device_ms[result.name] = device_ms.get(result.name, 0.0) + result.elapsed / args.frames
    start = time.perf_counter()
    for _ in range(args.frames):
        reference = encode_png(image)
    cpu_seconds = (time.perf_counter() - start) / args.frames
    print(f"{image.shape[1]}x{image.shape[0]} RGBA on {args.device}, codes of {len(others)} frame(s): "
          f"{len(data):,} bytes, {1000 * seconds:.3f} ms an encode ({1000 * host_seconds:.3f} ms of this process's "
          f"CPU); ISA-L level 1 {len(reference):,} bytes, {1000 * cpu_seconds:.3f} ms of one core")
    if device_ms:
        print(f"  device time an encode {1000 * sum(device_ms.values()):.1f} us: " + ", ".join(
            f"{name} {1000 * ms:.1f}" for name, ms in sorted(device_ms.items(), key=lambda kv: -kv[1])))


if __name__ == "__main__":
    main()
