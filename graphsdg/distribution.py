"""``rep.distribution``: random values re-sampled on every execution of the trigger that uses them.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_frame():
    ...     spheres = rep.create.sphere(position=rep.distribution.uniform((-1, -1, 0), (1, 1, 0)), count=4)
"""
from __future__ import annotations

import sys
from typing import Any, Callable

from graphsdg.graph.builder import add_node
from graphsdg.graph.node import ReplicatorItem
from graphsdg.graph.registration import register_function
from graphsdg.graph.registry import NodeRegistry


def uniform(lower: Any, upper: Any, num_samples: int = 1, seed: int | None = None,
            name: str | None = None) -> ReplicatorItem:
    """Uniform in [lower, upper), element-wise for tuples."""
    return add_node(NodeRegistry.create("distribution.uniform", name=name, lower=lower, upper=upper,
                                        num_samples=num_samples, seed=seed))


def normal(mean: Any, std: Any, num_samples: int = 1, seed: int | None = None,
           name: str | None = None) -> ReplicatorItem:
    """Gaussian with ``mean`` and standard deviation ``std`` (>= 0), element-wise."""
    return add_node(NodeRegistry.create("distribution.normal", name=name, mean=mean, std=std,
                                        num_samples=num_samples, seed=seed))


def log_uniform(lower: Any, upper: Any, num_samples: int = 1, seed: int | None = None,
                name: str | None = None) -> ReplicatorItem:
    """``exp(uniform(log(lower), log(upper)))`` (lower > 0)."""
    return add_node(NodeRegistry.create("distribution.log_uniform", name=name, lower=lower, upper=upper,
                                        num_samples=num_samples, seed=seed))


def choice(choices: Any, weights: Any = None, num_samples: int = 1, seed: int = -1,
           with_replacements: bool = True, name: str | None = None) -> ReplicatorItem:
    """One of ``choices`` per sample, with probabilities ``weights`` (normalised) if given."""
    return add_node(NodeRegistry.create("distribution.choice", name=name, choices=_as_list(choices),
                                        weights=None if weights is None else list(weights), num_samples=num_samples,
                                        seed=seed, with_replacements=with_replacements))


def sequence(items: Any, ordered: bool = True, seed: int = -1, name: str | None = None,
             stride: int | None = None) -> ReplicatorItem:
    """The next of ``items`` on each execution, wrapping around (a fixed shuffle if ``ordered=False``)."""
    return add_node(NodeRegistry.create("distribution.sequence", name=name, items=_as_list(items),
                                        ordered=ordered, seed=seed, stride=stride))


def combine(distributions: Any, name: str | None = None) -> ReplicatorItem:
    """Samples that concatenate one sample of each part (distributions or plain values)."""
    return add_node(NodeRegistry.create("distribution.combine", name=name, distributions=_as_list(distributions)))


def _as_list(value: Any) -> Any:
    if isinstance(value, (str, ReplicatorItem)) or value is None or not hasattr(value, "__iter__"):
        return value
    return list(value)


def register(fn: Callable[..., Any], override: bool = True, fn_name: str | None = None) -> None:
    """Add ``fn`` as ``rep.distribution.<fn_name>``."""
    register_function(sys.modules[__name__], fn, override, fn_name)


__all__ = ["uniform", "normal", "log_uniform", "choice", "sequence", "combine", "register"]
