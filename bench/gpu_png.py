"""What a PNG encoder on the GPU would cost: deflate of Sub-filtered rows in Warp kernels, a segment a thread, timed.

The colour and class-mask PNGs are the largest part of the writing that holds four GPUs of one host back
(docs/performance.md, round 23). This encoder keeps to what runs in parallel: the filtered lines are cut into
segments of a fixed length, and one thread parses each (at every byte the longest match among a few fixed
distances back, never past its segment's end; ``bench/png_codes.py`` sizes these parses on the CPU). A kernel
of a thread a byte first compares each candidate's next 8 bytes, so a segment's thread reads one word where a
match starts and compares further only for the candidates that matched all 8. A first pass counts each
segment's bits (and, for codes built for the image, the symbols), a prefix sum of the counts places every
segment in one deflate block, and a second pass writes the bits there (the words two segments share are or-ed
atomically). The block uses the fixed codes, codes built for this image from the first pass's counts (a copy
back and a wait between the passes), or codes built from another frame. The Adler-32 is summed a segment at a
time and combined on the device.

The bytes equal ``png_codes.zlib_stream`` of the same parse (the tests check it), so the sizes are those of
``bench/png_codes.py``; this script adds the device time, against ISA-L level 1 on one core.

Usage:
    python bench/gpu_png.py FRAME.png [--device cuda:0] [--frames 200] [--segment 256] [--distances 9]
        [--codes fixed|own|OTHER.png]
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

ADLER = wp.constant(65521)
MAX_MATCH = wp.constant(258)
CAP = wp.constant(8)           # match bytes compared a byte a thread; the parse extends matches that reach it


@wp.kernel(enable_backward=False)
def _filter(rows: wp.array2d(dtype=wp.uint8), bpp: int, lines: wp.array(dtype=wp.uint8)):
    """Line byte ``i`` of row ``r``: the filter type (1, Sub), then each byte minus the one a pixel to its left."""
    r, i = wp.tid()
    line = rows.shape[1] + 1
    value = int(1)
    if i > 0:
        j = i - 1
        value = int(rows[r, j])
        if j >= bpp:
            value = (value - int(rows[r, j - bpp])) & 255
    lines[r * line + i] = wp.uint8(value)


@wp.func
def _match(lines: wp.array(dtype=wp.uint8), p: int, distance: int, room: int) -> int:
    n = int(0)
    while n < room and lines[p + n] == lines[p + n - distance]:
        n += 1
    return n


@wp.kernel(enable_backward=False)
def _matches(lines: wp.array(dtype=wp.uint8), segment: int, distances: wp.array(dtype=wp.int32),
             packed: wp.array(dtype=wp.int32)):
    """Byte ``p``'s matches, each cut at :data:`CAP` bytes: the longest's length and candidate (the first of
    equals), and which candidates reached the cut (the parse extends those), packed in one word."""
    p = wp.tid()
    n = lines.shape[0]
    room = wp.min(wp.min(MAX_MATCH, (p // segment + 1) * segment - p), n - p)
    cut = wp.min(room, CAP)
    best = int(0)
    first = int(0)
    capped = int(0)
    for c in range(distances.shape[0]):
        d = distances[c]
        if d <= p:
            length = _match(lines, p, d, cut)
            if length > best:
                best = length
                first = c
            if length == cut:
                capped = capped | (1 << c)
    packed[p] = (best << 20) | (first << 16) | capped


@wp.func
def _put(words: wp.array(dtype=wp.uint32), bit: int, value: int, count: int):
    """Or ``count`` bits of ``value`` (fewer than 32) into the stream at bit ``bit``, least significant first."""
    if count > 0:
        shifted = wp.uint64(value) << wp.uint64(bit & 31)
        wp.atomic_or(words, bit >> 5, wp.uint32(shifted & wp.uint64(0xFFFFFFFF)))
        if (bit & 31) + count > 32:
            wp.atomic_or(words, (bit >> 5) + 1, wp.uint32(shifted >> wp.uint64(32)))


@wp.kernel(enable_backward=False)
def _parse(lines: wp.array(dtype=wp.uint8), packed: wp.array(dtype=wp.int32), segment: int,
           distances: wp.array(dtype=wp.int32), lengths: wp.array(dtype=wp.int32), codes: wp.array(dtype=wp.int32),
           length_slot: wp.array(dtype=wp.int32), length_base: wp.array(dtype=wp.int32),
           length_extra: wp.array(dtype=wp.int32), distance_base: wp.array(dtype=wp.int32),
           distance_extra: wp.array(dtype=wp.int32), write: int, count_symbols: int, header_bits: int,
           offsets: wp.array(dtype=wp.int32), segment_bits: wp.array(dtype=wp.int32),
           symbol_counts: wp.array(dtype=wp.int32), adler: wp.array(dtype=wp.int64),
           words: wp.array(dtype=wp.uint32)):
    """One segment's parse: its bits counted (``write`` 0) or written at its offset (``write`` 1).

    ``lengths`` and ``codes`` hold the 286 literal/length codes, then the 30 distance codes (as sent)."""
    s = wp.tid()
    n = lines.shape[0]
    start = s * segment
    end = wp.min(start + segment, n)
    bit = header_bits
    if write == 1:
        bit = header_bits + offsets[s]
    total = int(0)
    p = start
    while p < end:
        word = packed[p]
        best = int(word >> 20)
        first = int((word >> 16) & 15)
        room = wp.min(MAX_MATCH, end - p)
        if best == CAP and CAP < room:     # cut short: the candidates that reached the cut, in order, in full
            best = int(0)
            for c in range(distances.shape[0]):
                if (word >> c) & 1 == 1 and best < room:
                    length = CAP + _match(lines, p + CAP, distances[c], room - CAP)
                    if length > best:
                        best = length
                        first = c
        distance = distances[first]
        if best >= 3:
            slot = length_slot[best]
            dslot = int(29)
            while distance_base[dslot] > distance:
                dslot -= 1
            symbol = 257 + slot
            bits = lengths[symbol] + length_extra[slot] + lengths[286 + dslot] + distance_extra[dslot]
            if write == 1:
                _put(words, bit, codes[symbol], lengths[symbol])
                _put(words, bit + lengths[symbol], best - length_base[slot], length_extra[slot])
                at = bit + lengths[symbol] + length_extra[slot]
                _put(words, at, codes[286 + dslot], lengths[286 + dslot])
                _put(words, at + lengths[286 + dslot], distance - distance_base[dslot], distance_extra[dslot])
            elif count_symbols == 1:
                wp.atomic_add(symbol_counts, symbol, 1)
                wp.atomic_add(symbol_counts, 286 + dslot, 1)
            bit += bits
            total += bits
            p += best
        else:
            value = int(lines[p])
            if write == 1:
                _put(words, bit, codes[value], lengths[value])
            elif count_symbols == 1:
                wp.atomic_add(symbol_counts, value, 1)
            bit += lengths[value]
            total += lengths[value]
            p += 1
    if write == 0:
        segment_bits[s] = total
        s1 = wp.int64(0)
        s2 = wp.int64(0)
        for k in range(start, end):          # this segment's share of the Adler-32 (RFC 1950, 9)
            s1 += wp.int64(lines[k])
            s2 += wp.int64(end - k) * wp.int64(lines[k])
        wp.atomic_add(adler, 0, s1)
        wp.atomic_add(adler, 1, (s2 + wp.int64(n - end) * s1) % wp.int64(ADLER))
    elif s == (n + segment - 1) // segment - 1:
        _put(words, bit, codes[256], lengths[256])          # the end of the block after the last segment


class SegmentDeflate:
    """Deflates the filtered lines of uint8 images of one shape on a Warp device, a segment a thread."""

    def __init__(self, height: int, width: int, channels: int, device: str, segment: int = 256,
                 distances: str = "9") -> None:
        if segment < 1:
            raise ValueError(f"segment must be 1 byte or more, got {segment}")
        self.size, self.device, self.segment = (width, height, channels), device, segment
        self.line = width * channels + 1
        total = height * self.line
        self.count = (total + segment - 1) // segment
        chosen = png_codes.distance_set(distances, channels, self.line)
        slot = np.searchsorted(png_codes.LENGTH_BASE, np.arange(259), side="right") - 1

        def device_array(values, dtype=wp.int32):
            return wp.array(np.asarray(values), dtype=dtype, device=device)
        self.tables = [device_array(t) for t in (np.maximum(slot, 0), png_codes.LENGTH_BASE,
                                                 png_codes.LENGTH_EXTRA, png_codes.DISTANCE_BASE,
                                                 png_codes.DISTANCE_EXTRA)]
        self.distances = device_array(chosen)
        self.lines = wp.empty(total, dtype=wp.uint8, device=device)
        self.packed = wp.empty(total, dtype=wp.int32, device=device)
        self.offsets = wp.empty(self.count, dtype=wp.int32, device=device)
        self.segment_bits = wp.empty(self.count, dtype=wp.int32, device=device)
        self.symbol_counts = wp.zeros(316, dtype=wp.int32, device=device)
        self.adler = wp.zeros(2, dtype=wp.int64, device=device)
        self.words = wp.zeros(total * 15 // 32 + 2 + 80, dtype=wp.uint32, device=device)   # 15 bits a byte at most
        self._codes: dict[tuple, tuple] = {}

    def encode(self, rows: wp.array2d, codes: str | tuple[np.ndarray, np.ndarray] = "own") -> bytes:
        """The zlib stream of ``rows`` (uint8 device rows of ``width * channels`` bytes): ``codes`` is "fixed",
        "own" (built for these rows from a first count) or (literal/length, distance) code lengths."""
        wp.launch(_filter, dim=(rows.shape[0], self.line), inputs=[rows, self.size[2], self.lines],
                  device=self.device)
        wp.launch(_matches, dim=self.lines.shape[0], inputs=[self.lines, self.segment, self.distances, self.packed],
                  device=self.device)
        if isinstance(codes, str) and codes == "own":
            self.symbol_counts.zero_()
            self._pass(0, 1, self._tables("fixed"))
            counts = self.symbol_counts.numpy()
            codes = png_codes.block_code_lengths(counts[:286] + np.eye(286, dtype=np.int64)[256], counts[286:])
        chosen = self._tables(codes)
        self.adler.zero_()
        self._pass(0, 0, chosen)
        wp.utils.array_scan(self.segment_bits, self.offsets, inclusive=False)
        self.words.zero_()
        header, header_bits = chosen[2], chosen[3]
        wp.copy(self.words, header, count=header.shape[0])
        self._pass(1, 0, chosen)
        last = np.concatenate([self.offsets[self.count - 1:].numpy(), self.segment_bits[self.count - 1:].numpy()])
        bits = header_bits + int(last.sum()) + int(chosen[4])
        body = self.words[:(bits + 31) // 32].numpy().view(np.uint8)[:(bits + 7) // 8]   # the stream's words only
        a, b = (int(v) % ADLER for v in self.adler.numpy())
        b = (b + self.lines.shape[0]) % ADLER                        # Adler's A starts at 1: n more in B
        a = (a + 1) % ADLER
        return b"\x78\x01" + body.tobytes() + ((b << 16) | a).to_bytes(4, "big")

    def png(self, image: np.ndarray, codes: str | tuple[np.ndarray, np.ndarray] = "own") -> bytes:
        """PNG bytes of a uint8 (H, W, C) image, encoded on the device."""
        width, height, channels = self.size
        rows = wp.array(np.ascontiguousarray(image).reshape(height, width * channels), dtype=wp.uint8,
                        device=self.device)
        return png_file(width, height, 8, channels, self.encode(rows, codes))

    def _pass(self, write: int, count_symbols: int, chosen: tuple) -> None:
        lengths, sent, _, header_bits, _ = chosen
        wp.launch(_parse, dim=self.count, inputs=[self.lines, self.packed, self.segment, self.distances, lengths, sent,
                                                  *self.tables, write, count_symbols, header_bits, self.offsets,
                                                  self.segment_bits, self.symbol_counts, self.adler, self.words],
                  device=self.device)

    def _tables(self, codes) -> tuple:
        """Device code lengths and sent codes, the header as device words, its bits and the end-of-block code's
        bits, made once for each choice of codes."""
        key = codes if isinstance(codes, str) else tuple(np.concatenate(codes).tolist())
        if key not in self._codes:
            if isinstance(codes, str):
                lengths, distance_lengths = png_codes.FIXED_LENGTHS, np.full(30, 5)
                header, header_bits = 0b011, 3                   # BFINAL 1, BTYPE 01: the fixed codes
            else:
                lengths, distance_lengths = (np.asarray(c, np.int64) for c in codes)
                header, header_bits = png_codes.dynamic_header(lengths, distance_lengths)
            # the codes come from every length given (the fixed code's 288), the device takes the 286 used
            both = np.concatenate([lengths[:286], distance_lengths])
            sent = np.concatenate([png_codes.sent_codes(lengths)[:286], png_codes.sent_codes(distance_lengths)])
            words = np.frombuffer(header.to_bytes((header_bits + 31) // 32 * 4, "little"), np.uint32)
            self._codes[key] = (wp.array(both, dtype=wp.int32, device=self.device),
                                wp.array(sent, dtype=wp.int32, device=self.device),
                                wp.array(words, dtype=wp.uint32, device=self.device), header_bits,
                                int(lengths[256]))
        return self._codes[key]


def codes_of_frame(path: str, segment: int, distances: str) -> tuple[np.ndarray, np.ndarray]:
    """Code lengths built from another frame's parse, every symbol given a code (counts plus one)."""
    import cv2
    image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    lines = filtered_lines(image)
    stream = lines.reshape(-1)
    chosen = png_codes.distance_set(distances, image.shape[2] if image.ndim == 3 else 1, lines.shape[1])
    symbols = png_codes.greedy_parse(stream, *png_codes.best_matches(stream, chosen, segment))
    lit_len, distance, _ = png_codes.histograms(symbols)
    return png_codes.block_code_lengths(lit_len + 1, distance + 1)


def main() -> None:
    import cv2
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("image", help="a PNG to encode (a frame's rgb or class mask)")
    parser.add_argument("--device", default="cuda:0" if wp.get_cuda_device_count() else "cpu")
    parser.add_argument("--frames", type=int, default=200, help="encodes timed")
    parser.add_argument("--segment", type=int, default=256, help="bytes a thread parses")
    parser.add_argument("--distances", default="9", help="distance set of bench/png_codes.py: 5, 9 or 12")
    parser.add_argument("--codes", default="own", help="fixed, own (built for each image), or a PNG to build "
                                                      "them from")
    args = parser.parse_args()
    image = cv2.imread(args.image, cv2.IMREAD_UNCHANGED)
    if image is None:
        parser.error(f"cannot read {args.image!r} as an image")
    image = image[..., None] if image.ndim == 2 else image
    codes = args.codes if args.codes in ("fixed", "own") else codes_of_frame(args.codes, args.segment,
                                                                              args.distances)
    encoder = SegmentDeflate(*image.shape, device=args.device, segment=args.segment, distances=args.distances)
    data = encoder.png(image, codes)
    rows = wp.array(image.reshape(image.shape[0], -1), dtype=wp.uint8, device=args.device)
    encoder.encode(rows, codes)                                   # compiled and warm
    wp.synchronize_device(args.device)
    start, cpu_start = time.perf_counter(), time.process_time()
    for _ in range(args.frames):
        encoder.encode(rows, codes)
    seconds = (time.perf_counter() - start) / args.frames
    host_seconds = (time.process_time() - cpu_start) / args.frames
    wp.timing_begin(cuda_filter=wp.TIMING_KERNEL | wp.TIMING_MEMCPY | wp.TIMING_MEMSET)
    for _ in range(args.frames):
        encoder.encode(rows, codes)
    device_ms: dict[str, float] = {}
    for result in wp.timing_end():
        device_ms[result.name] = device_ms.get(result.name, 0.0) + result.elapsed / args.frames
    start = time.perf_counter()
    for _ in range(args.frames):
        reference = encode_png(image)
    cpu_seconds = (time.perf_counter() - start) / args.frames
    print(f"{image.shape[1]}x{image.shape[0]}x{image.shape[2]} on {args.device}, segments of {args.segment} "
          f"bytes, distances {args.distances}, codes {args.codes}: {len(data):,} bytes, {1000 * seconds:.3f} ms "
          f"a frame (filter, matches, two passes, prefix sum, read back; {1000 * host_seconds:.3f} ms of this "
          f"process's CPU); ISA-L level 1 {len(reference):,} bytes, {1000 * cpu_seconds:.3f} ms of one core")
    if device_ms:
        print(f"  device time a frame {1000 * sum(device_ms.values()):.1f} us: " + ", ".join(
            f"{name} {1000 * ms:.1f}" for name, ms in sorted(device_ms.items(), key=lambda kv: -kv[1])))


if __name__ == "__main__":
    main()
