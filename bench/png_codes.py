"""How small a PNG made by a GPU-parallel deflate can be: parses a GPU can make, sized against ISA-L level 1.

A GPU encoder finds each byte's longest match among a few fixed distances back (one thread a byte), parses
segments of the filtered lines on their own (one thread a segment: no match runs past its segment's end) and
joins the segments' bits into one deflate block. This script makes exactly that parse on the CPU for a few
distance sets and segment lengths and counts its bits with the fixed Huffman codes (RFC 1951, 3.2.6) and with
codes built for the image (a dynamic block's, lengths at most 15 bits by package-merge; its header is counted
at its largest, every code length sent as a 7-bit code-length code). The files would be the zlib stream's
bytes plus the PNG's 57 bytes of chunks, as ISA-L's are.

Usage:
    python bench/png_codes.py FRAME.png [FRAME.png ...] [--segments 64 256] [--distances 5 9 12]
"""
from __future__ import annotations

import argparse
import heapq

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
# the largest dynamic-block header: BFINAL and BTYPE, HLIT/HDIST/HCLEN, 19 3-bit code-length-code lengths,
# then each of 286 + 30 code lengths as a code-length code of at most 7 bits
DYNAMIC_HEADER_BITS = 3 + 14 + 19 * 3 + (286 + 30) * 7
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
    code_length = np.concatenate([np.full(144, 8), np.full(112, 9), np.full(24, 7), np.full(6, 8)])
    return 3 + int(lit_len @ code_length) + 5 * int(distance.sum()) + extra


def dynamic_bits(lit_len: np.ndarray, distance: np.ndarray, extra: int) -> int:
    """Bits of one dynamic block of these symbols with codes built for them, its header counted at its
    largest (:data:`DYNAMIC_HEADER_BITS`)."""
    return (DYNAMIC_HEADER_BITS + int(lit_len @ limited_code_lengths(lit_len))
            + int(distance @ limited_code_lengths(distance)) + extra)


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
