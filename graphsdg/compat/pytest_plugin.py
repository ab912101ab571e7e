"""A pytest plugin that runs test files written for Isaac Sim (``omni.kit.test.AsyncTestCase``) in compat mode.

Usage::

    pytest -p graphsdg.compat.pytest_plugin tests_written_for_isaac/

It installs the Isaac module names (:func:`graphsdg.compat.isaac.install`)
before test collection, so ``import omni.kit.test`` and
``import omni.replicator.core as rep`` at the top of a test file work, and
removes them when the session ends. It is opt-in: a plain ``pytest`` run never
installs them.
"""
from __future__ import annotations


def pytest_configure(config) -> None:
    from graphsdg.compat import isaac
    isaac.install()


def pytest_unconfigure(config) -> None:
    from graphsdg.compat import isaac
    isaac.uninstall()
