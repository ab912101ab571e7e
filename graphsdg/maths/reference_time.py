"""A capture's simulation time as Replicator's reference time. A fraction with a denominator of at most 10^6.

The value is ``fractions.Fraction(seconds).limit_denominator(1_000_000)`` (the closest such fraction, the
smaller denominator on a tie), worked out on plain integers: a frame asks for it once or twice, and the
``Fraction`` objects the standard way builds cost many Python calls a frame (docs/performance.md,
"Reference time").

Example:
    >>> reference_time(0.1)
    (1, 10)
    >>> reference_time(1 / 60)
    (1, 60)
"""
from __future__ import annotations

MAX_DENOMINATOR = 1_000_000

_last: tuple[float, tuple[int, int]] = (0.0, (0, 1))   # the previous answer: a frame's callers ask the same


def reference_time(seconds: float, max_denominator: int = MAX_DENOMINATOR) -> tuple[int, int]:
    """``(numerator, denominator)`` of the fraction closest to ``seconds`` whose denominator is at most
    ``max_denominator`` (lowest terms, the denominator positive)."""
    global _last
    if max_denominator == MAX_DENOMINATOR and _last[0] == seconds and type(seconds) is float:
        return _last[1]
    if max_denominator < 1:
        raise ValueError(f"max_denominator must be at least 1, got {max_denominator!r}")
    n, d = float(seconds).as_integer_ratio()
    result = (n, d) if d <= max_denominator else _closest(n, d, max_denominator)
    if max_denominator == MAX_DENOMINATOR and type(seconds) is float:
        _last = (seconds, result)
    return result


def _closest(numerator: int, denominator: int, max_denominator: int) -> tuple[int, int]:
    """The best rational approximation of ``numerator / denominator`` (lowest terms) with a bounded
    denominator: the last convergent of its continued fraction that fits, or the semiconvergent after it
    when that one is closer."""
    p0, q0, p1, q1 = 0, 1, 1, 0
    n, d = numerator, denominator
    while True:
        a = n // d
        q2 = q0 + a * q1
        if q2 > max_denominator:
            break
        p0, q0, p1, q1 = p1, q1, p0 + a * p1, q2
        n, d = d, n - a * d
    k = (max_denominator - q0) // q1
    # p1/q1 is at least as close as the semiconvergent exactly when this holds (the integer comparison
    # CPython's Fraction.limit_denominator makes)
    if 2 * d * (q0 + k * q1) <= denominator:
        return p1, q1
    return p0 + k * p1, q0 + k * q1
