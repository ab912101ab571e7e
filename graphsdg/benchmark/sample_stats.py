"""Summary statistics of a list of timing samples, rounded as benchmark metrics report them.

Mean, median, sample standard deviation, minimum, maximum and the 99th
percentile (linear interpolation between the two nearest ranks), each rounded to
two decimals. With ``trim_outliers`` and at least 100 samples the lowest and
highest tenth are left out first.

Example:
    >>> SampleStats.from_samples([1.0, 2.0, 3.0, 4.0])
    SampleStats(mean=2.5, median=2.5, stdev=1.29, min=1.0, max=4.0, p99=3.97)
"""
from __future__ import annotations

import math
import statistics
from dataclasses import dataclass


def percentile(sorted_samples: list[float], fraction: float) -> float:
    """The ``fraction`` (0..1) percentile of ascending samples, interpolating between neighbouring ranks."""
    if not sorted_samples:
        return 0.0
    rank = (len(sorted_samples) - 1) * fraction
    low, high = math.floor(rank), math.ceil(rank)
    if low == high:
        return sorted_samples[low]
    return sorted_samples[low] * (high - rank) + sorted_samples[high] * (rank - low)


@dataclass
class SampleStats:
    """Mean, median, standard deviation, min, max and 99th percentile of samples (two decimals)."""

    mean: float
    median: float
    stdev: float
    min: float
    max: float
    p99: float

    @classmethod
    def from_samples(cls, samples: list[float], trim_outliers: bool = True) -> "SampleStats":
        """The statistics of ``samples`` (all zero for none); ``trim_outliers`` drops each end's tenth from 100
        samples on."""
        if not samples:
            return cls(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        kept = sorted(samples)
        if trim_outliers and len(kept) >= 100:
            cut = len(kept) // 10
            kept = kept[cut:-cut]
        return cls(mean=round(statistics.mean(kept), 2), median=round(statistics.median(kept), 2),
                   stdev=round(statistics.stdev(kept), 2) if len(kept) > 1 else 0.0,
                   min=round(kept[0], 2), max=round(kept[-1], 2), p99=round(percentile(kept, 0.99), 2))

    def to_dict(self) -> dict[str, float]:
        """The statistics by name; the 99th percentile is called ``one_percent`` (the slowest 1 %)."""
        return {"mean": self.mean, "median": self.median, "stdev": self.stdev, "min": self.min, "max": self.max,
                "one_percent": self.p99}
