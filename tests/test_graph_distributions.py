"""Distributions against their laws, and their bad-input errors."""
from __future__ import annotations

import math

import numpy as np
import pytest

import graphsdg as rep
from graphsdg.graph import scheduler

N = 20000


def draw(item, n=N, execution=0):
    """``n`` samples of one execution of a distribution item."""
    import networkx as nx
    node = item.node
    graph = rep.graph.current_graph()
    needed = nx.ancestors(graph.dag, node.name) | {node.name}
    for other in graph.order:                 # upstream distributions first, as the scheduler runs them
        if other.name in needed:
            other.exec_count = execution
            scheduler.execute(other, 0)
    return node.output_values["samples"].take(n)


def assert_mean_var(x, mean, var, sigmas=5):
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    assert np.all(np.abs(x.mean(0) - mean) < sigmas * np.sqrt(np.asarray(var) / n)), (x.mean(0), mean)
    # the sample variance's standard error is about var * sqrt(2 / n) for light tails
    assert np.all(np.abs(x.var(0) - var) < sigmas * np.asarray(var) * math.sqrt(2.0 / n) * 1.5), (x.var(0), var)


def test_uniform_scalar_and_tuple_match_the_law():
    x = draw(rep.distribution.uniform(2.0, 5.0))
    assert x.shape == (N,) and x.min() >= 2.0 and x.max() < 5.0
    assert_mean_var(x, 3.5, 9 / 12)
    lo, hi = np.array([0.0, -1.0, 10.0]), np.array([1.0, 1.0, 10.5])
    v = draw(rep.distribution.uniform(tuple(lo), tuple(hi)))
    assert v.shape == (N, 3) and np.all(v >= lo) and np.all(v < hi)
    assert_mean_var(v, (lo + hi) / 2, (hi - lo) ** 2 / 12)


def test_normal_matches_the_law():
    x = draw(rep.distribution.normal(6500, 2000))
    assert_mean_var(x, 6500, 2000 ** 2)
    v = draw(rep.distribution.normal((0, 10), (1, 3)))
    assert v.shape == (N, 2)
    assert_mean_var(v, np.array([0, 10]), np.array([1, 9]))


def test_log_uniform_is_uniform_in_log_space():
    x = draw(rep.distribution.log_uniform(0.01, 100.0))
    assert x.min() >= 0.01 and x.max() < 100.0
    logs = np.log(x)
    assert_mean_var(logs, (math.log(0.01) + math.log(100)) / 2, (math.log(100) - math.log(0.01)) ** 2 / 12)


def test_choice_frequencies_follow_weights_chi_square():
    weights = [1.0, 2.0, 7.0]
    x = draw(rep.distribution.choice(["a", "b", "c"], weights=weights))
    counts = np.array([sum(1 for v in x if v == k) for k in "abc"])
    expected = N * np.asarray(weights) / sum(weights)
    chi2 = float(((counts - expected) ** 2 / expected).sum())
    # df = 2: the chi-square law is exponential with mean 2, so P(chi2 > t) = exp(-t / 2)
    assert chi2 < -2 * math.log(1e-4), (counts, expected, chi2)


def test_choice_of_tuples_without_weights_and_without_replacement():
    palette = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]
    x = draw(rep.distribution.choice(palette), n=3000)
    assert x.shape == (3000, 3)
    counts = np.array([np.all(x == p, axis=1).sum() for p in palette])
    chi2 = float(((counts - 1000) ** 2 / 1000).sum())
    assert counts.sum() == 3000 and chi2 < -2 * math.log(1e-4)
    y = draw(rep.distribution.choice([1, 2, 3, 4], with_replacements=False), n=4)
    assert sorted(y.tolist()) == [1, 2, 3, 4]


def test_sequence_walks_in_order_and_wraps():
    seq = rep.distribution.sequence(["a", "b", "c"])
    assert [draw(seq, 1, execution=k)[0] for k in range(7)] == list("abcabca")
    assert list(draw(seq, 2, execution=1)) == ["b", "b"]          # one item per execution, whatever the targets
    chunks = rep.distribution.sequence(["a", "b", "c"], stride=2)   # stride: that many consecutive items a draw
    assert [list(draw(chunks, 1, execution=k)[0]) for k in range(3)] == [["a", "b"], ["c", "a"], ["b", "c"]]
    shuffled = rep.distribution.sequence(list(range(6)), ordered=False)
    cycle = [int(draw(shuffled, 1, execution=k)[0]) for k in range(12)]
    assert sorted(cycle[:6]) == list(range(6)) and cycle[6:] == cycle[:6]


def test_combine_concatenates_parts():
    v = draw(rep.distribution.combine([rep.distribution.uniform(0, 1), 5.0, rep.distribution.normal((0, 0), (1, 1))]),
             n=100)
    assert v.shape == (100, 4) and np.all(v[:, 1] == 5.0) and np.all((v[:, 0] >= 0) & (v[:, 0] < 1))


def test_executions_and_seeds_give_reproducible_independent_streams():
    u = rep.distribution.uniform(0, 1)
    a0, a1, again = draw(u, 50, 0), draw(u, 50, 1), draw(u, 50, 0)
    assert np.array_equal(a0, again) and not np.array_equal(a0, a1)
    assert np.array_equal(draw(u, 10, 0), a0[:10])              # count-aware draws share their prefix
    rep.set_global_seed(123)
    assert not np.array_equal(draw(u, 50, 0), a0)
    fixed = rep.distribution.uniform(0, 1, seed=5)
    first = draw(fixed, 5, 0)
    rep.set_global_seed(999)
    assert np.array_equal(draw(fixed, 5, 0), first)             # an explicit seed ignores the global seed


@pytest.mark.parametrize("call,needle", [
    (lambda: rep.distribution.uniform((0, 0), (1, 1, 1)), "different shapes"),
    (lambda: rep.distribution.uniform(2, 1), "greater than upper"),
    (lambda: rep.distribution.uniform((0, 3), (1, 1)), "greater than upper"),
    (lambda: rep.distribution.normal(0, -1), "std -1 is negative"),
    (lambda: rep.distribution.log_uniform(0, 1), "must be > 0"),
    (lambda: rep.distribution.choice([]), "choices is empty"),
    (lambda: rep.distribution.choice([1, 2], weights=[1, 2, 3]), "has 3 entries but there are 2 choices"),
    (lambda: rep.distribution.choice([1, 2], weights=[0, 0]), "sum to a positive number"),
    (lambda: rep.distribution.choice([1, 2], weights=[-1, 2]), "non-negative"),
    (lambda: rep.distribution.sequence([]), "items is empty"),
    (lambda: rep.distribution.uniform(0, 1, num_samples=0), "num_samples"),
])
def test_bad_distribution_input_raises_naming_the_value(call, needle):
    with pytest.raises(ValueError, match=needle.replace("(", r"\(")):
        call()


def test_num_samples_must_match_the_target_count():
    u = rep.distribution.uniform(0, 1, num_samples=4)
    assert draw(u, 1).shape == (4,)
    with pytest.raises(ValueError, match="num_samples=4 but its target has 3 prims"):
        draw(u, 3)
