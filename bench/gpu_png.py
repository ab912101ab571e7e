"""What a PNG encoder on the GPU would cost: fixed-code deflate of Sub-filtered rows in a Warp kernel, timed.

The colour and class-mask PNGs are the largest part of the writing that holds four GPUs of one host back
(docs/performance.md, round 23). A GPU encoder keeps to what runs in parallel: each image row is its own
deflate block with the fixed Huffman codes (RFC 1951, 3.2.6), its matches limited to five distances (the byte,
the pixel and two pixels before, the row above and its pixel before), and ends byte-aligned with an empty stored
block, so every row is encoded by one thread into a slot of its own and the slots are joined by a prefix sum of
their lengths. The zlib checksum is summed a row at a time on the device and combined on the host.

This script measures that design: the bytes it makes of a frame against ISA-L level 1's (graphsdg's PNG writer),
and the device time of encoding it (the kernel, the prefix sum, the gathering copy and the read back). It is a
prototype for deciding whether to build it into the pbr path, not part of graphsdg.

Usage:
    python bench/gpu_png.py [--image PNG] [--device cuda:0] [--frames 200]
"""
from __future__ import annotations

import argparse
import struct
import time

import numpy as np
import warp as wp

from graphsdg.io.png import encode_png, png_file

ADLER = wp.constant(65521)
MAX_MATCH = wp.constant(258)
# fixed-code length symbols 257..285: base length and extra bits (RFC 1951, 3.2.5)
LENGTH_BASE = np.array([3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115,
                        131, 163, 195, 227, 258], dtype=np.int32)
LENGTH_EXTRA = np.array([0] * 8 + [1] * 4 + [2] * 4 + [3] * 4 + [4] * 4 + [5] * 4 + [0], dtype=np.int32)
DISTANCE_BASE = np.array([1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025,
                          1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577], dtype=np.int32)
DISTANCE_EXTRA = np.array([0, 0, 0, 0] + [k for k in range(1, 14) for _ in range(2)], dtype=np.int32)


@wp.func
def _reversed(code: int, bits: int) -> int:
    out = int(0)
    for k in range(bits):
        out = (out << 1) | ((code >> k) & 1)
    return out


@wp.func
def _filtered(rows: wp.array2d(dtype=wp.uint8), r: int, i: int, bpp: int) -> int:
    """Byte ``i`` of row ``r``'s filtered line: the filter type (1, Sub) and then each byte minus the one a pixel
    to its left; ``i`` < 0 reaches into the row above."""
    width = rows.shape[1]
    if i < 0:
        r = r - 1
        i = i + width + 1
    if i == 0:
        return 1
    j = i - 1
    if j < bpp:
        return int(rows[r, j])
    return (int(rows[r, j]) - int(rows[r, j - bpp])) & 255


@wp.func
def _match(rows: wp.array2d(dtype=wp.uint8), r: int, i: int, distance: int, bpp: int) -> int:
    """How many bytes from line position ``i`` repeat those ``distance`` bytes back (at most the line's rest)."""
    width = rows.shape[1]
    limit = wp.min(MAX_MATCH, width + 1 - i)
    n = int(0)
    while n < limit and _filtered(rows, r, i + n, bpp) == _filtered(rows, r, i + n - distance, bpp):
        n += 1
    return n


@wp.kernel
def _encode_rows(rows: wp.array2d(dtype=wp.uint8), bpp: int, length_base: wp.array(dtype=wp.int32),
                 length_extra: wp.array(dtype=wp.int32), distance_base: wp.array(dtype=wp.int32),
                 distance_extra: wp.array(dtype=wp.int32), slots: wp.array2d(dtype=wp.uint8),
                 lengths: wp.array(dtype=wp.int32), sums: wp.array2d(dtype=wp.int64)):
    r = wp.tid()
    width = rows.shape[1]
    line = width + 1
    acc = wp.uint64(2)             # block header: BFINAL 0, BTYPE 01 (fixed codes)
    nbits = int(3)
    pos = int(0)
    s1 = wp.int64(0)
    s2 = wp.int64(0)
    for k in range(line):          # the checksum's sums of this line (combined on the host)
        byte = wp.int64(_filtered(rows, r, k, bpp))
        s1 += byte
        s2 += wp.int64(line - k) * byte
    sums[r, 0] = s1 % wp.int64(ADLER)
    sums[r, 1] = s2 % wp.int64(ADLER)
    i = int(0)
    while i < line:
        best = int(0)
        distance = int(0)
        for c in range(5):         # the distances: byte, pixel, two pixels, row, row and pixel back
            d = int(1)
            if c == 1:
                d = bpp
            elif c == 2:
                d = 2 * bpp
            elif c == 3:
                d = line
            elif c == 4:
                d = line + bpp
            if (c == 1 and d == 1) or d > 32768 or i - d < -line or (r == 0 and i - d < 0):
                continue
            n = _match(rows, r, i, d, bpp)
            if n > best:
                best = n
                distance = d
        code = int(0)
        bits = int(0)
        if best >= 3:
            slot = int(28)
            while length_base[slot] > best:
                slot -= 1
            symbol = 257 + slot
            if symbol < 280:
                code = _reversed(symbol - 256, 7)
                bits = 7
            else:
                code = _reversed(0xC0 + symbol - 280, 8)
                bits = 8
            code = code | ((best - length_base[slot]) << bits)
            bits += length_extra[slot]
            dslot = int(29)
            while distance_base[dslot] > distance:
                dslot -= 1
            code = code | (_reversed(dslot, 5) << bits)
            bits += 5
            code = code | ((distance - distance_base[dslot]) << bits)
            bits += distance_extra[dslot]
            i += best
        else:
            value = _filtered(rows, r, i, bpp)
            if value < 144:
                code = _reversed(0x30 + value, 8)
                bits = 8
            else:
                code = _reversed(0x190 + value - 144, 9)
                bits = 9
            i += 1
        acc = acc | (wp.uint64(code) << wp.uint64(nbits))
        nbits += bits
        while nbits >= 8:
            slots[r, pos] = wp.uint8(acc & wp.uint64(255))
            acc = acc >> wp.uint64(8)
            nbits -= 8
            pos += 1
    nbits += 7 + 3                 # end of block (code 0, 7 bits), then an empty stored block's header (3 zero bits)
    while nbits > 0:               # ... padded to the byte
        slots[r, pos] = wp.uint8(acc & wp.uint64(255))
        acc = acc >> wp.uint64(8)
        nbits -= 8
        pos += 1
    slots[r, pos] = wp.uint8(0)    # the stored block's LEN 0 and NLEN 0xFFFF
    slots[r, pos + 1] = wp.uint8(0)
    slots[r, pos + 2] = wp.uint8(255)
    slots[r, pos + 3] = wp.uint8(255)
    lengths[r] = pos + 4


@wp.kernel
def _gather(slots: wp.array2d(dtype=wp.uint8), lengths: wp.array(dtype=wp.int32),
            offsets: wp.array(dtype=wp.int32), stream: wp.array(dtype=wp.uint8)):
    r, k = wp.tid()
    if k < lengths[r]:
        stream[offsets[r] + k] = slots[r, k]


class FixedCodeEncoder:
    """Encodes images of one size and channel count on a Warp device into PNG bytes (fixed-code deflate)."""

    def __init__(self, height: int, width: int, channels: int, device: str) -> None:
        self.shape, self.device = (height, width * channels), device
        self.bpp = channels
        slot_bytes = (width * channels + 1) * 9 // 8 + 16        # every byte a 9-bit literal, plus block ends
        self.tables = [wp.array(t, dtype=wp.int32, device=device)
                       for t in (LENGTH_BASE, LENGTH_EXTRA, DISTANCE_BASE, DISTANCE_EXTRA)]
        self.slots = wp.empty((height, slot_bytes), dtype=wp.uint8, device=device)
        self.lengths = wp.empty(height, dtype=wp.int32, device=device)
        self.offsets = wp.empty(height, dtype=wp.int32, device=device)
        self.sums = wp.empty((height, 2), dtype=wp.int64, device=device)
        self.stream = wp.empty(height * slot_bytes, dtype=wp.uint8, device=device)
        self.size = (width, height, channels)

    def encode_device(self, rows: wp.array2d) -> tuple[np.ndarray, np.ndarray]:
        """The joined deflate blocks of ``rows`` (uint8 device rows) and each line's checksum sums, on the host."""
        wp.launch(_encode_rows, dim=self.shape[0], inputs=[rows, self.bpp, *self.tables, self.slots, self.lengths,
                                                            self.sums], device=self.device)
        wp.utils.array_scan(self.lengths, self.offsets, inclusive=False)
        wp.launch(_gather, dim=self.slots.shape, inputs=[self.slots, self.lengths, self.offsets, self.stream],
                  device=self.device)
        total = int(self.lengths.numpy().sum())
        return self.stream[:total].numpy(), self.sums.numpy()

    def png(self, image: np.ndarray) -> bytes:
        """PNG bytes of a uint8 (H, W, C) image."""
        rows = wp.array(np.ascontiguousarray(image).reshape(self.shape), dtype=wp.uint8, device=self.device)
        blocks, sums = self.encode_device(rows)
        idat = b"".join([b"\x78\x01", blocks.tobytes(), b"\x03\x00",
                         struct.pack(">I", _adler(sums, self.shape[1] + 1))])
        width, height, channels = self.size
        return png_file(width, height, 8, channels, idat)


def _adler(sums: np.ndarray, line: int) -> int:
    """Adler-32 of the lines from each line's byte sum and weighted sum (RFC 1950, 9)."""
    a, b = 1, 0
    for s1, s2 in sums.tolist():
        b = (b + line * a + s2) % ADLER
        a = (a + s1) % ADLER
    return (b << 16) | a


def _frame(path: str | None) -> np.ndarray:
    if path:
        import cv2
        image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
        return cv2.cvtColor(image, cv2.COLOR_BGRA2RGBA if image.shape[2] == 4 else cv2.COLOR_BGR2RGB)
    y, x = np.mgrid[0:512, 0:512]
    image = np.zeros((512, 512, 4), np.uint8)        # a sky gradient, a flat floor and a noisy box
    image[..., 2] = 128 + y // 4
    image[..., 3] = 255
    image[300:, :, :3] = 90
    rng = np.random.default_rng(0)
    image[150:280, 180:330, :3] = rng.integers(100, 140, (130, 150, 3), dtype=np.uint8)
    return image


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--image", help="a PNG to encode (default: a made-up 512x512 RGBA frame)")
    parser.add_argument("--device", default="cuda:0" if wp.get_cuda_device_count() else "cpu")
    parser.add_argument("--frames", type=int, default=200, help="encodes timed")
    args = parser.parse_args()
    image = _frame(args.image)
    encoder = FixedCodeEncoder(*image.shape, device=args.device)
    data = encoder.png(image)
    rows = wp.array(image.reshape(encoder.shape), dtype=wp.uint8, device=args.device)
    encoder.encode_device(rows)                       # compiled and warm
    wp.synchronize_device(args.device)
    start = time.perf_counter()
    for _ in range(args.frames):
        encoder.encode_device(rows)
    seconds = (time.perf_counter() - start) / args.frames
    start = time.perf_counter()
    for _ in range(args.frames):
        reference = encode_png(image)
    cpu_seconds = (time.perf_counter() - start) / args.frames
    print(f"{image.shape[1]}x{image.shape[0]}x{image.shape[2]} on {args.device}: fixed-code deflate {len(data):,} "
          f"bytes, {1000 * seconds:.3f} ms a frame (launches, prefix sum, gather, read back); ISA-L level 1 "
          f"{len(reference):,} bytes, {1000 * cpu_seconds:.3f} ms of one core")


if __name__ == "__main__":
    main()
