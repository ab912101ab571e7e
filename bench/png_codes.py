"""How small a PNG made by a GPU-parallel deflate can be: parses a GPU can make, sized against ISA-L level 1.

A GPU encoder finds each byte's longest match among a few fixed distances back (one thread a byte), parses
segments of the filtered lines on their own (one thread a segment: no match runs past its segment's end) and
joins the segments' bits into one deflate block. This script makes exactly that parse on the CPU for a few
distance sets and segment lengths and counts its bits with the fixed Huffman codes (RFC 1951, 3.2.6) and with
codes built for the image (a dynamic block's, lengths at most 15 bits by package-merge, with the header
:func:`dynamic_header` writes). The files would be the zlib stream's bytes plus the PNG's 57 bytes of chunks,
as ISA-L's are. ``bench/gpu_png.py`` encodes with these codes on a Warp device.

Usage:
    python bench/png_codes.py FRAME.png [FRAME.png ...] [--segments 64 256] [--distances 5 9 12]
"""
from __future__ import annotations

import argparse
import heapq
import zlib

import numpy as np
from isal import isal_zlib

from graphsdg.io.png import filtered_lines

MAX_MATCH = 258
# length symbols 257..285 and distance symbols 0..29: base values and extra bits (RFC 1951, 3.2.5)
LENGTH_BASE = np.array([3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115,
                        131, 163, 195, 227, 258])
LENGTH_EXTRA = np.array([0] * 8 + [1] * 4 + [2] * 4 + [3] * 4 + [4] * 4 + [5] * 4 + [0])
DISTANCE_BASE = np.array([1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025,
                          1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577])
DISTANCE_EXTRA = np.array([0, 0, 0, 0] + [k for k in range(1, 14) for _ in range(2)])
# the order a dynamic block sends its code-length code's lengths in (RFC 1951, 3.2.7)
CODE_LENGTH_ORDER = [16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15]
# the fixed literal/length code's lengths (RFC 1951, 3.2.6): all 288, as its canonical codes count 286 and 287
FIXED_LENGTHS = np.concatenate([np.full(144, 8), np.full(112, 9), np.full(24, 7), np.full(8, 8)])
ZLIB_WRAPPER = 2 + 4          # the zlib header and the Adler-32


def distance_set(name: str, pixel: int, line: int) -> list[int]:
    """The candidate distances of set ``name`` ("5", "9" or "12") for ``pixel`` bytes a pixel and ``line``
    bytes a filtered line: the byte and pixels before, the line above and its neighbours."""
    sets = {"5": [1, pixel, 2 * pixel, line, line + pixel],
            "9": [1, 2, 3, pixel, 2 * pixel, 3 * pixel, line, line + pixel, line - pixel],
            "12": [1, 2, 3, pixel, 2 * pixel, 3 * pixel, 4 * pixel, line, line + pixel, line - pixel, 2 * line,
                   2 * line + pixel]}
    if name not in sets:
        raise ValueError(f"unknown distance set {name!r}; expected one of {sorted(sets)}")
    return sorted({d for d in sets[name] if 0 < d <= 32768}, key=sets[name].index)


def best_matches(stream: np.ndarray, distances: list[int], segment: int) -> tuple[np.ndarray, np.ndarray]:
    """Each byte's longest match (length, distance) among ``distances``, cut at its segment's end and at 258;
    on equal lengths the distance listed first wins."""
    n = stream.size
    position = np.arange(n)
    room = np.minimum(np.minimum((position // segment + 1) * segment, n) - position, MAX_MATCH)
    best = np.zeros(n, np.int64)
    best_distance = np.zeros(n, np.int64)
    for d in distances:
        differs = np.ones(n, bool)
        differs[d:] = stream[d:] != stream[:-d]
        stops = np.flatnonzero(differs)
        following = np.searchsorted(stops, position)          # the first differing byte at or after each
        end = np.where(following < stops.size, stops[np.minimum(following, stops.size - 1)], n)
        length = np.minimum(end - position, room)
        better = length > best
        best = np.where(better, length, best)
        best_distance = np.where(better, d, best_distance)
    return best, best_distance


def greedy_parse(stream: np.ndarray, best: np.ndarray, best_distance: np.ndarray) -> list[tuple[int, int]]:
    """The parse a segment's thread makes: a match of 3 or more bytes where one starts, else a literal; as
    (literal byte, 0) and (length, distance) pairs."""
    symbols = []
    lengths, distances, values = best.tolist(), best_distance.tolist(), stream.tolist()
    i, n = 0, stream.size
    while i < n:
        if lengths[i] >= 3:
            symbols.append((lengths[i], distances[i]))
            i += lengths[i]
        else:
            symbols.append((values[i], 0))
            i += 1
    return symbols


def pixel_run_parse(lines: np.ndarray, piece: int = 64) -> list[tuple[int, int]]:
    """The parse of :mod:`graphsdg.render.device_png`, made here one pixel after another: its reference.

    ``lines``: the filtered lines of an RGBA image (Sub, or unfiltered for a label image), (H, 1 + 4 W) bytes.
    Each line's filter byte is a literal.
    Each pixel takes the first of its neighbours left, above, above-left, above-right and two to the left
    (:data:`~graphsdg.render.device_png.NEIGHBOURS`, those in the image and at most 32,768 bytes back) whose
    filtered bytes equal its own, or none: 4 literals. A match starts at each pixel that takes a neighbour
    where its left pixel takes another (or none) and at each pixel whose x is a multiple of ``piece``, and
    covers the pixels after it that take the same neighbour, up to the next such start.
    """
    height, line = lines.shape
    width = (line - 1) // 4
    if line != 1 + 4 * width or not 1 <= piece <= MAX_MATCH // 4:
        raise ValueError(f"lines of {line} bytes and pieces of {piece} pixels: expected 1 + 4 W bytes and 1-64 pixels")
    pixels = lines[:, 1:].reshape(height, width, 4).view(np.uint32)[..., 0]
    neighbours = [(dy, dx) for dy, dx in ((0, -1), (-1, 0), (-1, -1), (-1, 1), (0, -2))
                  if -dy * line - 4 * dx <= 32768]
    mode = np.full((height, width), -1)
    for k in reversed(range(len(neighbours))):               # the first neighbour that matches wins
        dy, dx = neighbours[k]
        same = np.zeros((height, width), bool)
        ys, xs = slice(max(0, -dy), height), slice(max(0, -dx), min(width, width - dx))
        same[ys, xs] = pixels[ys, xs] == pixels[max(0, -dy) + dy:height + dy, xs.start + dx:xs.stop + dx]
        mode[same] = k
    values, symbols = lines.tolist(), []
    for y in range(height):
        symbols.append((values[y][0], 0))
        x = 0
        while x < width:
            k = mode[y, x]
            if k < 0:
                symbols += [(v, 0) for v in values[y][1 + 4 * x:5 + 4 * x]]
                x += 1
                continue
            end = x + 1
            while end < width and end % piece and mode[y, end] == k:
                end += 1
            dy, dx = neighbours[k]
            symbols.append((4 * (end - x), -dy * line - 4 * dx))
            x = end
    return symbols


def replayed(symbols: list[tuple[int, int]]) -> bytes:
    """The bytes a decoder rebuilds from ``symbols`` (what makes a parse right)."""
    out = bytearray()
    for value, distance in symbols:
        if distance == 0:
            out.append(value)
        else:
            for _ in range(value):
                out.append(out[-distance])
    return bytes(out)


def histograms(symbols: list[tuple[int, int]]) -> tuple[np.ndarray, np.ndarray, int]:
    """Counts of the 286 literal/length symbols (end of block included) and the 30 distance symbols, and the
    extra bits of the lengths and distances."""
    pairs = np.array(symbols, np.int64).reshape(-1, 2)
    literal = pairs[:, 1] == 0
    length_slot = np.searchsorted(LENGTH_BASE, pairs[~literal, 0], side="right") - 1
    distance_slot = np.searchsorted(DISTANCE_BASE, pairs[~literal, 1], side="right") - 1
    lit_len = np.bincount(pairs[literal, 0], minlength=286) + np.bincount(257 + length_slot, minlength=286)
    lit_len[256] += 1
    extra = int(LENGTH_EXTRA[length_slot].sum() + DISTANCE_EXTRA[distance_slot].sum())
    return lit_len, np.bincount(distance_slot, minlength=30), extra


def fixed_bits(lit_len: np.ndarray, distance: np.ndarray, extra: int) -> int:
    """Bits of one fixed-code block of these symbols, its 3-bit header included."""
    return 3 + int(lit_len @ FIXED_LENGTHS[:286]) + 5 * int(distance.sum()) + extra


def dynamic_bits(lit_len: np.ndarray, distance: np.ndarray, extra: int) -> int:
    """Bits of one dynamic block of these symbols with codes built for them (:func:`block_code_lengths`), its
    header included."""
    lengths, distance_lengths = block_code_lengths(lit_len, distance)
    return dynamic_header(lengths, distance_lengths)[1] + int(lit_len @ lengths) + int(distance @ distance_lengths) \
        + extra


def block_code_lengths(lit_len: np.ndarray, distance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Code lengths for a dynamic block of these counts that every inflater takes: two distance codes at
    least (a lone code or none is an incomplete code, which zlib refuses for some alphabets)."""
    distance = np.asarray(distance).copy()
    for symbol in (0, 1):
        if np.count_nonzero(distance) < 2 and distance[symbol] == 0:
            distance[symbol] = 1
    return limited_code_lengths(np.asarray(lit_len)), limited_code_lengths(distance)


def canonical_codes(lengths: np.ndarray) -> np.ndarray:
    """The Huffman code of each symbol for these code lengths (RFC 1951, 3.2.2), most significant bit first."""
    lengths = np.asarray(lengths, np.int64)
    count = np.bincount(lengths, minlength=16)
    count[0] = 0
    next_code = np.zeros(16, np.int64)
    code = 0
    for bits in range(1, 16):
        code = (code + count[bits - 1]) << 1
        next_code[bits] = code
    codes = np.zeros(lengths.size, np.int64)
    for symbol, bits in enumerate(lengths.tolist()):
        if bits:
            codes[symbol] = next_code[bits]
            next_code[bits] += 1
    return codes


def sent_codes(lengths: np.ndarray) -> np.ndarray:
    """The codes as a deflate stream sends them: bit-reversed, since the stream packs bits from the least
    significant up and a Huffman code goes first bit first."""
    codes = canonical_codes(lengths)
    return np.array([int(format(code, f"0{bits}b")[::-1], 2) if bits else 0
                     for code, bits in zip(codes.tolist(), np.asarray(lengths).tolist())], np.int64)


def zlib_stream(symbols: list[tuple[int, int]], data: bytes, lengths: np.ndarray | None = None,
                distance_lengths: np.ndarray | None = None) -> bytes:
    """The zlib stream of ``data`` parsed as ``symbols`` (:func:`greedy_parse`), one final block: with the fixed
    codes when no lengths are given, else a dynamic block with these code lengths (the reference a device
    encoder's bytes are checked against)."""
    fixed = lengths is None
    if fixed:
        lengths, distance_lengths = FIXED_LENGTHS, np.full(30, 5)
        value, count = 0b011, 3                                       # BFINAL 1, BTYPE 01
    else:
        value, count = dynamic_header(lengths, distance_lengths)
    codes, distance_codes = sent_codes(lengths), sent_codes(distance_lengths)
    fields = []
    for first, distance in symbols:
        if distance == 0:
            fields.append((int(codes[first]), int(lengths[first])))
            continue
        slot = int(np.searchsorted(LENGTH_BASE, first, side="right")) - 1
        dslot = int(np.searchsorted(DISTANCE_BASE, distance, side="right")) - 1
        fields += [(int(codes[257 + slot]), int(lengths[257 + slot])),
                   (first - int(LENGTH_BASE[slot]), int(LENGTH_EXTRA[slot])),
                   (int(distance_codes[dslot]), int(distance_lengths[dslot])),
                   (distance - int(DISTANCE_BASE[dslot]), int(DISTANCE_EXTRA[dslot]))]
    fields.append((int(codes[256]), int(lengths[256])))
    for field, bits in fields:
        value |= field << count
        count += bits
    body = value.to_bytes((count + 7) // 8, "little")
    return b"\x78\x01" + body + zlib.adler32(data).to_bytes(4, "big")


def dynamic_header(lengths: np.ndarray, distance_lengths: np.ndarray) -> tuple[int, int]:
    """The header of a final dynamic block (RFC 1951, 3.2.7) with these literal/length and distance code
    lengths, as (bits, how many): the bits packed from the least significant up, as the stream sends them."""
    hlit = max(257, int(np.flatnonzero(lengths)[-1]) + 1)
    hdist = max(1, int(np.flatnonzero(distance_lengths)[-1]) + 1 if np.any(distance_lengths) else 1)
    tokens = _run_length_tokens(np.concatenate([lengths[:hlit], distance_lengths[:hdist]]).tolist())
    counts = np.bincount([symbol for symbol, _, _ in tokens], minlength=19)
    if np.count_nonzero(counts) < 2:                 # a complete code needs two symbols
        counts[0 if counts[0] == 0 else 1] += 1
    cl_lengths = limited_code_lengths(counts, limit=7)
    cl_codes = sent_codes(cl_lengths)
    hclen = max(4, max(k for k, symbol in enumerate(CODE_LENGTH_ORDER) if cl_lengths[symbol]) + 1)
    fields = [(1, 1), (2, 2), (hlit - 257, 5), (hdist - 1, 5), (hclen - 4, 4)]
    fields += [(int(cl_lengths[symbol]), 3) for symbol in CODE_LENGTH_ORDER[:hclen]]
    for symbol, extra, extra_bits in tokens:
        fields += [(int(cl_codes[symbol]), int(cl_lengths[symbol])), (extra, extra_bits)]
    value, count = 0, 0
    for field, bits in fields:
        value |= field << count
        count += bits
    return value, count


def _run_length_tokens(lengths: list[int]) -> list[tuple[int, int, int]]:
    """Code lengths as code-length-code tokens (symbol, extra value, extra bits): 0-15 as they are, 16 to
    repeat the last 3-6 times, 17 and 18 for 3-10 and 11-138 zeros."""
    tokens, i = [], 0
    while i < len(lengths):
        run = 1
        while i + run < len(lengths) and lengths[i + run] == lengths[i]:
            run += 1
        value, left = lengths[i], run
        if value == 0:
            while left >= 11:
                take = min(left, 138)
                tokens.append((18, take - 11, 7))
                left -= take
            if left >= 3:
                tokens.append((17, left - 3, 3))
                left = 0
        else:
            tokens.append((value, 0, 0))
            left -= 1
            while left >= 3:
                take = min(left, 6)
                tokens.append((16, take - 3, 2))
                left -= take
        tokens += [(value, 0, 0)] * left
        i += run
    return tokens


def limited_code_lengths(counts: np.ndarray, limit: int = 15) -> np.ndarray:
    """Optimal prefix-code lengths of at most ``limit`` bits for the symbols counted (package-merge); 0 for a
    symbol never used, 1 for a lone one."""
    used = [int(i) for i in np.flatnonzero(counts)]
    lengths = np.zeros(counts.size, np.int64)
    if len(used) == 1:
        lengths[used[0]] = 1
    if len(used) < 2:
        return lengths
    if len(used) > 1 << limit:
        raise ValueError(f"{len(used)} symbols do not fit codes of at most {limit} bits")
    leaves = sorted((int(counts[i]), (i,)) for i in used)
    items = list(leaves)
    for _ in range(limit - 1):
        packages = [(items[k][0] + items[k + 1][0], items[k][1] + items[k + 1][1])
                    for k in range(0, len(items) - 1, 2)]
        items = list(heapq.merge(leaves, packages))
    for _, members in items[:2 * len(used) - 2]:
        for i in members:
            lengths[i] += 1
    return lengths


def sizes(image: np.ndarray, distance_sets: list[str], segments: list[int]) -> list[dict]:
    """One row a (distance set, segment length): the fixed-code and built-code stream sizes in bytes, with
    ISA-L level 1's."""
    lines = filtered_lines(image)
    stream = lines.reshape(-1)
    pixel = image.shape[2] if image.ndim == 3 else 1
    isal = len(isal_zlib.compress(lines, 1))
    rows = []
    for name in distance_sets:
        distances = distance_set(name, pixel, lines.shape[1])
        for segment in segments:
            counts = histograms(greedy_parse(stream, *best_matches(stream, distances, segment)))
            rows.append({"distances": name, "segment": segment, "isal": isal,
                         "fixed": (fixed_bits(*counts) + 7) // 8 + ZLIB_WRAPPER,
                         "built": (dynamic_bits(*counts) + 7) // 8 + ZLIB_WRAPPER})
    return rows


def main() -> None:
    import cv2
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("images", nargs="+", help="PNG files (a frame's rgb or class mask)")
    parser.add_argument("--distances", nargs="+", default=["5", "9", "12"], help="distance sets: 5, 9, 12")
    parser.add_argument("--segments", nargs="+", type=int, default=[64, 256], help="segment lengths in bytes")
    args = parser.parse_args()
    if any(s < 1 for s in args.segments):
        parser.error(f"--segments takes lengths of 1 byte or more, got {args.segments}")
    print("| image | distances | segment | ISA-L level 1 | fixed codes | codes built for the image |")
    print("|---|---|---|---|---|---|")
    for path in args.images:
        image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
        if image is None:
            parser.error(f"cannot read {path!r} as an image")
        for row in sizes(image, args.distances, args.segments):
            print(f"| {path} | {row['distances']} | {row['segment']} | {row['isal']:,} | {row['fixed']:,} "
                  f"({row['fixed'] / row['isal']:.2f}x) | {row['built']:,} ({row['built'] / row['isal']:.2f}x) |")


if __name__ == "__main__":
    main()
