"""Replicator's reference time: the capture's simulation time as a fraction with a bounded denominator."""
import random
from fractions import Fraction

import numpy as np
import pytest

from graphsdg.maths.reference_time import reference_time


def _times() -> list[float]:
    rng = random.Random(7)
    return ([rng.uniform(-1e3, 1e3) for _ in range(3000)] + [i / 60 for i in range(600)] +
            [i * 0.001 for i in range(600)] + [rng.random() * 1e-7 for _ in range(200)] + [0.0, 3.0, 1e9 + 0.5])


@pytest.mark.parametrize("max_denominator", [1_000_000, 1000, 7, 1])
def test_it_is_the_closest_fraction_the_standard_library_finds(max_denominator):
    for t in _times():
        f = Fraction(t).limit_denominator(max_denominator)
        assert reference_time(t, max_denominator) == (f.numerator, f.denominator), t


def test_frame_times_come_out_as_frames_over_the_rate_and_numpy_floats_alike():
    assert reference_time(7 / 60) == (7, 60)
    assert reference_time(np.float64(0.1)) == (1, 10)
    assert reference_time(2) == (2, 1)
    assert reference_time(0.25) == reference_time(0.25) == (1, 4)   # the second answer is the kept one


def test_a_denominator_bound_below_one_is_refused():
    with pytest.raises(ValueError, match="max_denominator must be at least 1, got 0"):
        reference_time(0.5, 0)
