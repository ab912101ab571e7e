"""The PNG of a frame's colour or class mask, compressed on the GPU where the pixels are: pixel-run deflate.

A written frame's colour PNG (rows filtered, then deflated) was the largest CPU cost of its writing, and on a host
feeding four GPUs the cores' shared memory bus runs out first (docs/performance.md, "The CPU a frame").
This module compresses the RGBA colour and class masks of a :class:`~graphsdg.render.pbr_outputs.ClassicLayout`
on its device in kernels of a thread a pixel, so only the zlib stream comes back for the writer to wrap as a PNG.

The stream holds the image's rows as :func:`graphsdg.io.png.encode_png` filters them (``Sub``; a class mask's
rows unfiltered) in one deflate block (RFC 1950/1951) whose Huffman codes are fixed in this module
(:data:`COLOUR_CODES`, :data:`LABEL_CODES`), so a frame needs no count of its symbols and no wait for one.
The parse is made of whole pixels: each line's filter byte is a literal; each pixel takes the first of
:data:`NEIGHBOURS` whose filtered bytes equal its own, or none (four literals); a match starts at each pixel
that takes a neighbour where its left pixel takes another (or none), and at each pixel whose x is a multiple
of :data:`PIECE`, and covers the pixels after it that take the same neighbour, up to the next start.
``bench/png_codes.py`` makes the same parse on the CPU (``pixel_run_parse``), and the tests compare the bytes.
The files are larger than ISA-L's level 1 of the same rows (docs/performance.md); a stream longer than the
room the layout reads back (:func:`stream_words`) is reported as none, and that frame's PNG is compressed on
the CPU as before.

Kernels, one launch each: the pixels' filtered words and neighbours (``_modes``), each pixel's match length
and bits (``_bits``), a prefix sum of the bits, the bits written at their offsets (``_write``, words two pixels
share or-ed atomically), the Adler-32's sums of pieces of lines (``_adler_lines``) and the block's end and
checksum (``_finish``).

Imports Warp (``graphsdg[gpu]``); :mod:`graphsdg.render.pbr` loads it on construction.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

ADLER = 65521
ADLER_CONST = wp.constant(ADLER)
PIECE = wp.constant(64)          # pixels a match covers at most: 256 bytes (deflate's longest is 258)
ADLER_PIECE = 32                 # pixels a thread sums for the Adler-32
ADLER_PIECE_CONST = wp.constant(ADLER_PIECE)
#: the pixels a pixel may repeat, in the order tried, as (dy, dx): left, above, above-left, above-right, two left
NEIGHBOURS = ((0, -1), (-1, 0), (-1, -1), (-1, 1), (0, -2))
_WINDOW = 32768                  # deflate's distances reach this far back


def _lengths(digits: str) -> np.ndarray:
    """Code lengths written one hex digit a symbol."""
    return np.array([int(c, 16) for c in digits], dtype=np.int64)


#: code lengths of the 286 literal/length symbols and the 30 distance symbols, one hex digit each: built (length-
#: limited Huffman codes, every symbol counted once more) from the parse of five colour frames, pbr and classic
#: renders of the bench scene (``bench/png_codes.py``)
LENGTHS = _lengths("2456666777778888888999999999999aaa9aaaaaaa9aaaaaabaaabbbaaabbbbbabbbbbbbbbbbbbbbbbbbbbbbcccdc"
                   "cccccccccccccccccceccccccccccbcccccccbcccccccccbcccccccccbcbccccccccbcccccbcccaabbbbbbbbbbbbba"
                   "bbbbbabbbbbbbabbabbbbbbaaa98aaaaaaaaaaaaaaaaaaa99a9999999988888777665ff3fff5ff7f9f999a99998999"
                   "8884f")
DISTANCE_LENGTHS = _lengths("999194999999999999999329888888")
#: the dynamic block's header for these codes (BFINAL, BTYPE 10, the code lengths' own code), least bit first
HEADER = int("20d5f5d2cc5ba3e92bdcccd2460b24ad59eecfbbb5eecfbef39ce86b164b3331adb41c4ec390ecc3b5b4a53729a6dca6dca"
             "7290cbff332bfb6a6661c876c49db18cb32db462c34385e7ef7e7ffe79e79d8005fded", 16)
HEADER_BITS = 674
#: the same for label images (class masks), whose rows are stored unfiltered: built from the parse of five class
#: masks of the bench scene with every literal counted alike (a mask's literals are its labels' colours, which
#: differ from scene to scene), every symbol once more
LABEL_LENGTHS = _lengths("4dcccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccc"
                         "cccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccc"
                         "ccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccccef2fff6ff6f6f6"
                         "666666655565552e")
LABEL_DISTANCE_LENGTHS = _lengths("999194999999999999999329888888")
LABEL_HEADER = int("11f93df2762793e49b9cccecccef5dbb76ddb4f6f7edb6db6db6db6db6db6db6db6db6db6d7ff3dfb7fd84118e003fded",
                   16)
LABEL_HEADER_BITS = 385
SUB_FILTER, NO_FILTER = 1, 0     # PNG filter types: colour rows Sub-filtered, label images' rows stored as they are


@dataclass(frozen=True)
class Codes:
    """A fixed Huffman code table of the stream (its code lengths and its block header, least bit first) and
    the PNG filter type of the rows it was built for."""

    lengths: np.ndarray
    distance_lengths: np.ndarray
    header: int
    header_bits: int
    filter_type: int


COLOUR_CODES = Codes(LENGTHS, DISTANCE_LENGTHS, HEADER, HEADER_BITS, SUB_FILTER)
LABEL_CODES = Codes(LABEL_LENGTHS, LABEL_DISTANCE_LENGTHS, LABEL_HEADER, LABEL_HEADER_BITS, NO_FILTER)
_LONGEST_HEADER = max(HEADER_BITS, LABEL_HEADER_BITS)

# RFC 1951 3.2.5: the first length / distance of each length symbol 257-285 and distance symbol 0-29, and its
# extra bits
LENGTH_BASE = (3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163,
               195, 227, 258)
LENGTH_EXTRA = (0,) * 8 + (1,) * 4 + (2,) * 4 + (3,) * 4 + (4,) * 4 + (5,) * 4 + (0,)
DISTANCE_BASE = (1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025, 1537, 2049,
                 3073, 4097, 6145, 8193, 12289, 16385, 24577)
DISTANCE_EXTRA = (0, 0, 0, 0) + tuple(k for k in range(1, 14) for _ in range(2))
_MAX_BITS_A_PIXEL = 5 * 15       # four literals and a line's filter byte


def sent_codes(lengths: np.ndarray) -> np.ndarray:
    """The canonical Huffman codes of ``lengths`` (RFC 1951 3.2.2), bit-reversed as a deflate stream sends them
    least significant bit first.

    Example:
        >>> sent_codes(np.array([2, 1, 3, 3])).tolist()   # codes 10, 0, 110, 111
        [1, 0, 3, 7]
    """
    lengths = np.asarray(lengths, dtype=np.int64)
    counts = np.bincount(lengths, minlength=16)
    counts[0] = 0
    code, first = 0, np.zeros(16, np.int64)
    for bits in range(1, 16):
        code = (code + counts[bits - 1]) << 1
        first[bits] = code
    sent = np.zeros(lengths.size, np.int64)
    for symbol, bits in enumerate(lengths.tolist()):
        if bits:
            value = int(first[bits])
            first[bits] += 1
            sent[symbol] = int(format(value, f"0{bits}b")[::-1], 2)
    return sent


def reachable_neighbours(width: int) -> list[tuple[tuple[int, int], int]]:
    """The :data:`NEIGHBOURS` deflate reaches in the filtered lines of an RGBA image ``width`` pixels wide, each
    as ``((dy, dx), bytes back)``, in the order tried."""
    line = 4 * width + 1
    back = [((dy, dx), -dy * line - 4 * dx) for dy, dx in NEIGHBOURS]
    return [(neighbour, d) for neighbour, d in back if d <= _WINDOW]


def stream_words(width: int, height: int) -> int:
    """Words of stream a layout reads back: a quarter of the pixels' bytes (a frame whose stream is longer is
    compressed on the CPU), and at least the header and a line."""
    return max(width * height // 4, (_LONGEST_HEADER + _MAX_BITS_A_PIXEL * width) // 32 + 64)


_HIGH_BITS = wp.constant(wp.uint32(0x80808080))
_LOW_BITS = wp.constant(wp.uint32(0x7F7F7F7F))
_ALL_BITS = wp.constant(wp.uint32(0xFFFFFFFF))


@wp.func
def _sub_bytes(a: wp.uint32, b: wp.uint32) -> wp.uint32:
    # each byte of a minus the same byte of b, mod 256, no borrow between bytes
    return ((a | _HIGH_BITS) - (b & _LOW_BITS)) ^ ((a ^ b ^ _ALL_BITS) & _HIGH_BITS)


@wp.func
def _byte(word: wp.uint32, shift: int) -> int:
    return int((word >> wp.uint32(shift)) & wp.uint32(255))


@wp.func
def _filtered(rgba: wp.array(dtype=wp.uint32), width: int, y: int, x: int, filter_type: int) -> wp.uint32:
    word = rgba[y * width + x]
    if x == 0 or filter_type == 0:
        return word
    return _sub_bytes(word, rgba[y * width + x - 1])


@wp.kernel(enable_backward=False)
def _modes(rgba: wp.array(dtype=wp.uint32), width: int, filter_type: int, dys: wp.array(dtype=wp.int32),
           dxs: wp.array(dtype=wp.int32), filtered: wp.array(dtype=wp.uint32), modes: wp.array(dtype=wp.int32)):
    p = wp.tid()
    y = p // width
    x = p - y * width
    own = _filtered(rgba, width, y, x, filter_type)
    mode = int(-1)
    for k in range(dys.shape[0]):
        ny = y + dys[k]
        nx = x + dxs[k]
        if mode < 0 and ny >= 0 and nx >= 0 and nx < width:
            if _filtered(rgba, width, ny, nx, filter_type) == own:
                mode = k
    filtered[p] = own
    modes[p] = mode


@wp.kernel(enable_backward=False)
def _bits(filtered: wp.array(dtype=wp.uint32), modes: wp.array(dtype=wp.int32), width: int, filter_type: int,
          lengths: wp.array(dtype=wp.int32), match_bits: wp.array(dtype=wp.int32),
          distance_bits: wp.array(dtype=wp.int32), pieces: wp.array(dtype=wp.int32), bits: wp.array(dtype=wp.int32)):
    # a thread a pixel: the pixels of the match it starts (0: none) and its bits (a line's filter byte with the
    # line's first pixel)
    p = wp.tid()
    x = p % width
    mode = modes[p]
    count = int(0)
    piece = int(0)
    if x == 0:
        count += lengths[filter_type]
    if mode < 0:
        word = filtered[p]
        count += lengths[_byte(word, 0)] + lengths[_byte(word, 8)] + lengths[_byte(word, 16)] \
            + lengths[_byte(word, 24)]
    else:
        starts = int(0)
        if x % PIECE == 0:
            starts = 1
        elif modes[p - 1] != mode:
            starts = 1
        if starts == 1:
            end = x + 1
            going = int(1)
            while going == 1:
                if end >= width:
                    going = 0
                elif end % PIECE == 0:
                    going = 0
                elif modes[p + end - x] != mode:
                    going = 0
                else:
                    end += 1
            piece = end - x
            count += match_bits[piece] + distance_bits[mode]
    pieces[p] = piece
    bits[p] = count


@wp.kernel(enable_backward=False)
def _adler_lines(filtered: wp.array(dtype=wp.uint32), width: int, filter_type: int,
                 totals: wp.array(dtype=wp.int64)):
    # a thread a piece of a line (ADLER_PIECE pixels; the piece at x = 0 holds the line's filter byte too): its
    # bytes' sum and the sum of position x byte (RFC 1950's Adler-32 is made of the two), added to the image's
    y, piece = wp.tid()
    line = 4 * width + 1
    start = piece * ADLER_PIECE_CONST
    total = wp.int64(0)
    moment = wp.int64(0)
    if start == 0:                           # the filter byte, at the line's first byte
        total = wp.int64(filter_type)
        moment = wp.int64(y * line) * wp.int64(filter_type)
    for x in range(start, wp.min(start + ADLER_PIECE_CONST, width)):
        word = filtered[y * width + x]
        b0, b1, b2, b3 = wp.int64(_byte(word, 0)), wp.int64(_byte(word, 8)), wp.int64(_byte(word, 16)), \
            wp.int64(_byte(word, 24))
        sum4 = b0 + b1 + b2 + b3
        total += sum4
        moment += wp.int64(y * line + 1 + 4 * x) * sum4 + b1 + wp.int64(2) * b2 + wp.int64(3) * b3
    wp.atomic_add(totals, 0, total)
    wp.atomic_add(totals, 1, moment % wp.int64(ADLER_CONST))


@wp.func
def _put(words: wp.array(dtype=wp.uint32), bit: int, value: int, count: int) -> int:
    # or count bits of value (fewer than 32) into the stream at bit, least significant first; the bit after them
    if count > 0:
        word = bit >> 5
        if word + 1 < words.shape[0]:        # past the room read back: _finish reports the stream as too long
            shifted = wp.uint64(wp.uint32(value)) << wp.uint64(bit & 31)
            wp.atomic_or(words, word, wp.uint32(shifted & wp.uint64(0xFFFFFFFF)))
            if (bit & 31) + count > 32:
                wp.atomic_or(words, word + 1, wp.uint32(shifted >> wp.uint64(32)))
    return bit + count


@wp.kernel(enable_backward=False)
def _write(filtered: wp.array(dtype=wp.uint32), modes: wp.array(dtype=wp.int32), pieces: wp.array(dtype=wp.int32),
           width: int, lengths: wp.array(dtype=wp.int32), codes: wp.array(dtype=wp.int32),
           match_codes: wp.array(dtype=wp.int32), match_bits: wp.array(dtype=wp.int32),
           distance_codes: wp.array(dtype=wp.int32), distance_bits: wp.array(dtype=wp.int32),
           offsets: wp.array(dtype=wp.int32), header_bits: int, filter_type: int, words: wp.array(dtype=wp.uint32)):
    p = wp.tid()
    x = p % width
    bit = header_bits + offsets[p]
    if x == 0:
        bit = _put(words, bit, codes[filter_type], lengths[filter_type])
    mode = modes[p]
    if mode < 0:
        word = filtered[p]
        for shift in range(0, 32, 8):
            symbol = _byte(word, shift)
            bit = _put(words, bit, codes[symbol], lengths[symbol])
    else:
        piece = pieces[p]
        if piece > 0:
            bit = _put(words, bit, match_codes[piece], match_bits[piece])
            _put(words, bit, distance_codes[mode], distance_bits[mode])


@wp.kernel(enable_backward=False)
def _finish(offsets: wp.array(dtype=wp.int32), bits: wp.array(dtype=wp.int32), totals: wp.array(dtype=wp.int64),
            size: int, header_bits: int, end_code: int, end_bits: int, words: wp.array(dtype=wp.uint32),
            meta: wp.array(dtype=wp.int64)):
    # one thread: the end-of-block code after the last pixel's bits, the stream's length in bits (-1: longer than
    # the room read back) and its Adler-32 (RFC 1950: A = 1 + sum of bytes, B = n + sum of (n - i) x byte i)
    last = offsets.shape[0] - 1
    end = _put(words, header_bits + offsets[last] + bits[last], end_code, end_bits)
    modulus = wp.int64(ADLER_CONST)
    n = wp.int64(size) % modulus
    s = totals[0] % modulus
    a = (wp.int64(1) + s) % modulus
    b = (n + n * s - totals[1] % modulus) % modulus
    if b < wp.int64(0):
        b += modulus
    meta[0] = wp.int64(end)
    if end > 32 * (words.shape[0] - 1):
        meta[0] = wp.int64(-1)
    meta[1] = b * wp.int64(65536) + a


def _match_tables(width: int, table: Codes) -> tuple[np.ndarray, ...]:
    """Sent bits and bit counts of a match of n pixels (index n: length code and extra bits) and of each
    neighbour's distance (distance code and extra bits) with ``table``'s codes."""
    lengths, distance_lengths = table.lengths, table.distance_lengths
    codes, distance_codes = sent_codes(lengths), sent_codes(distance_lengths)
    match_codes, match_bits = np.zeros(PIECE + 1, np.int64), np.zeros(PIECE + 1, np.int64)
    for n in range(1, PIECE + 1):
        slot = int(np.searchsorted(LENGTH_BASE, 4 * n, side="right")) - 1
        match_codes[n] = int(codes[257 + slot]) | (4 * n - LENGTH_BASE[slot]) << int(lengths[257 + slot])
        match_bits[n] = int(lengths[257 + slot]) + LENGTH_EXTRA[slot]
    d_codes, d_bits = [], []
    for _, d in reachable_neighbours(width):
        slot = int(np.searchsorted(DISTANCE_BASE, d, side="right")) - 1
        d_codes.append(int(distance_codes[slot]) | (d - DISTANCE_BASE[slot]) << int(distance_lengths[slot]))
        d_bits.append(int(distance_lengths[slot]) + DISTANCE_EXTRA[slot])
    return match_codes, match_bits, np.array(d_codes, np.int64), np.array(d_bits, np.int64)


def fits(width: int, height: int) -> bool:
    """Whether images of this size can be compressed here (the bit offsets are 32-bit)."""
    return width > 0 and height > 0 and width * height * _MAX_BITS_A_PIXEL + _LONGEST_HEADER < 2 ** 31 - 64


class DevicePng:
    """Compresses the RGBA colour words of images ``width`` x ``height`` on ``device`` into ``words`` (uint32)
    and ``meta`` (int64: the stream's bits, -1 when it does not fit ``words``, and its Adler-32), arrays the
    caller reads back (:func:`zlib_stream` makes the stream of them). ``codes``: :data:`COLOUR_CODES` (rows
    ``Sub``-filtered), or :data:`LABEL_CODES` for label images (class masks; rows unfiltered).

    Example (Warp's CPU device)::

        words = wp.zeros(stream_words(64, 48), dtype=wp.uint32, device="cpu")
        meta = wp.zeros(2, dtype=wp.int64, device="cpu")
        png = DevicePng(64, 48, "cpu", words, meta)
        png.queue(rgba)      # rgba: wp.array of 64 * 48 uint32 words, bytes R, G, B, A in memory
        stream = zlib_stream(meta.numpy(), words.numpy())
    """

    def __init__(self, width: int, height: int, device: str, words: wp.array, meta: wp.array,
                 codes: Codes = COLOUR_CODES) -> None:
        if not fits(width, height):
            raise ValueError(f"cannot compress a {width}x{height} image on the device; expected fewer than "
                             f"{(2 ** 31 - 64 - _LONGEST_HEADER) // _MAX_BITS_A_PIXEL} pixels")
        self.width, self.height, self.device = width, height, device
        self.words, self.meta = words, meta
        n = width * height
        neighbours = [neighbour for neighbour, _ in reachable_neighbours(width)]

        def device_array(values, dtype=wp.int32):
            return wp.array(np.asarray(values), dtype=dtype, device=device)
        self._dys = device_array([dy for dy, _ in neighbours])
        self._dxs = device_array([dx for _, dx in neighbours])
        self.codes = codes
        self._lengths = device_array(codes.lengths)
        self._codes = device_array(sent_codes(codes.lengths))
        self._match_codes, self._match_bits, self._distance_codes, self._distance_bits = (
            device_array(t) for t in _match_tables(width, codes))
        header = codes.header.to_bytes((codes.header_bits + 31) // 32 * 4, "little")
        self._header = device_array(np.frombuffer(header, np.uint32), wp.uint32)
        self._filtered = wp.empty(n, dtype=wp.uint32, device=device)
        self._modes, self._pieces, self._bits, self._offsets = (wp.empty(n, dtype=wp.int32, device=device)
                                                                for _ in range(4))
        self._totals = wp.zeros(2, dtype=wp.int64, device=device)
        self._end_code, self._end_bits = int(sent_codes(codes.lengths)[256]), int(codes.lengths[256])

    def queue(self, rgba: wp.array) -> None:
        """Queue the compression of ``rgba`` (``width * height`` uint32 words) into :attr:`words` and
        :attr:`meta` on the device's current stream (graph-safe: no waits, no allocations but the scan's)."""
        n, d, width = self.width * self.height, self.device, self.width
        filter_type, header_bits = self.codes.filter_type, self.codes.header_bits
        wp.launch(_modes, dim=n, inputs=[rgba, width, filter_type, self._dys, self._dxs, self._filtered,
                                          self._modes], device=d)
        wp.launch(_bits, dim=n, inputs=[self._filtered, self._modes, width, filter_type, self._lengths,
                                         self._match_bits, self._distance_bits, self._pieces, self._bits], device=d)
        wp.utils.array_scan(self._bits, self._offsets, inclusive=False)
        self.words.zero_()
        wp.copy(self.words, self._header, count=self._header.shape[0])
        wp.launch(_write, dim=n, inputs=[self._filtered, self._modes, self._pieces, width, self._lengths,
                                          self._codes, self._match_codes, self._match_bits, self._distance_codes,
                                          self._distance_bits, self._offsets, header_bits, filter_type, self.words],
                  device=d)
        self._totals.zero_()
        wp.launch(_adler_lines, dim=(self.height, -(-width // ADLER_PIECE)),
                  inputs=[self._filtered, width, filter_type, self._totals], device=d)
        wp.launch(_finish, dim=1, inputs=[self._offsets, self._bits, self._totals, self.height * (4 * width + 1),
                                           header_bits, self._end_code, self._end_bits, self.words, self.meta],
                  device=d)


def zlib_stream(meta: np.ndarray, words: np.ndarray) -> bytes | None:
    """The zlib stream (RFC 1950) of a :class:`DevicePng`'s read-back ``meta`` and ``words``; None when it did
    not fit the words read back."""
    bits = int(meta[0])
    if bits < 0:
        return None
    body = np.asarray(words).view(np.uint8)[:(bits + 7) // 8].tobytes()
    return b"\x78\x01" + body + int(meta[1]).to_bytes(4, "big")


__all__ = ["COLOUR_CODES", "Codes", "DISTANCE_LENGTHS", "DevicePng", "HEADER", "HEADER_BITS", "LABEL_CODES",
           "LABEL_DISTANCE_LENGTHS", "LABEL_HEADER", "LABEL_HEADER_BITS", "LABEL_LENGTHS", "LENGTHS", "NEIGHBOURS",
           "PIECE", "fits",
           "reachable_neighbours", "sent_codes", "stream_words", "zlib_stream"]
