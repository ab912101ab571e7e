"""carb.tokens, carb.profiler (real timing into graphsdg's profiling tables), carb.logging, carb.get_framework."""
from __future__ import annotations

import asyncio
import logging
import os
import sys
import time

import pytest

from graphsdg.base import profiling
from graphsdg.compat import isaac
from graphsdg.compat.modules import CompatError


@pytest.fixture
def carb():
    isaac.install()
    import carb
    import carb.logging
    import carb.profiler
    import carb.tokens
    yield carb
    isaac.uninstall()


def test_tokens_resolve(carb, caplog):
    tokens = carb.tokens.get_tokens_interface()
    temp = tokens.resolve("${temp}")
    assert os.path.isdir(temp) and tokens.resolve("${temp}/rgb") == os.path.join(temp, "rgb")
    assert tokens.resolve("${temp}") == temp   # one folder per process
    import graphsdg
    assert tokens.resolve("${app}") == tokens.resolve("${kit}") == os.path.dirname(graphsdg.__file__)
    assert tokens.resolve("${python}") == sys.executable
    assert tokens.resolve("cost: $$5, ${app}") == f"cost: $5, {tokens.resolve('${app}')}"
    with caplog.at_level(logging.WARNING, logger="carb"):
        assert tokens.resolve("[${no_such_token}]") == "[]"
        assert tokens.resolve("[${no_such_token}]", carb.tokens.RESOLVE_FLAG_LEAVE_TOKEN_IF_NOT_FOUND) == \
            "[${no_such_token}]"
    assert sum("${no_such_token}" in r.getMessage() for r in caplog.records) == 1   # warned once
    assert tokens.set_value("root", "/data/${leaf}") and tokens.set_value("leaf", "run")
    assert tokens.resolve("${root}/x") == "/data/run/x" and tokens.exists("root")
    tokens.set_initial_value("root", "/other")
    assert tokens.resolve("${root}") == "/data/run"
    assert tokens.remove_token("root") and not tokens.exists("root") and not tokens.remove_token("root")


def test_profiler_times_zones_into_the_profiling_tables(carb):
    profiling.reset()

    @carb.profiler.profile
    def work():
        time.sleep(0.03)

    @carb.profiler.profile(zone_name="named", add_args=True)
    def add(a, b=1):
        return a + b

    @carb.profiler.profile(zone_name="awaited")
    async def later():
        await asyncio.sleep(0.02)

    work()
    work()
    assert add(2, b=3) == 5
    asyncio.run(later())
    carb.profiler.begin(1, "manual")
    time.sleep(0.01)
    carb.profiler.end(1)
    table = profiling.snapshot()
    assert 0.06 <= table["carb:" + work.__qualname__] < 0.5
    assert "carb:named(2, b=3)" in table
    assert 0.02 <= table["carb:awaited"] < 0.5 and 0.01 <= table["carb:manual"] < 0.5
    profiler = carb.profiler.acquire_profiler_interface(plugin_name="carb.profiler-tracy.plugin")
    previous = profiler.set_capture_mask(2)
    try:
        carb.profiler.begin(1, "masked_out")
        carb.profiler.end(1)
        assert "carb:masked_out" not in profiling.snapshot()
        profiler.value_float(2, 1.5, "fps")
        profiler.value_int(1, 7, "dropped")   # not captured
    finally:
        profiler.set_capture_mask(previous)
    from graphsdg.compat.carb_services import profiler_samples
    assert profiler_samples()["fps"] == [1.5] and "dropped" not in profiler_samples()
    with pytest.raises(RuntimeError, match="without an open zone"):
        carb.profiler.end(1)


def test_logging_interface(carb):
    logging_interface = carb.logging.acquire_logging()
    received = []
    handle = logging_interface.add_logger(lambda *record: received.append(record))
    try:
        carb.log_warn("watch out")
        carb.log_error("broken")
        carb.log_fatal("gone")
        logging.getLogger("someone.else").error("also seen")
    finally:
        logging_interface.remove_logger(handle)
    carb.log_error("after removal")
    levels = {message: level for source, level, filename, line, message in received}
    assert levels == {"watch out": carb.logging.LEVEL_WARN, "broken": carb.logging.LEVEL_ERROR,
                      "gone": carb.logging.LEVEL_FATAL, "also seen": carb.logging.LEVEL_ERROR}
    assert carb.logging.LEVEL_VERBOSE < carb.logging.LEVEL_INFO < carb.logging.LEVEL_WARN < carb.logging.LEVEL_ERROR
    try:
        logging_interface.set_level_threshold(carb.logging.LEVEL_ERROR)
        assert logging_interface.get_level_threshold() == carb.logging.LEVEL_ERROR
        assert not logging.getLogger("carb").isEnabledFor(logging.WARNING)
        logging_interface.set_log_enabled(False)
        assert not logging_interface.is_log_enabled()
    finally:
        logging_interface.set_log_enabled(True)
        logging.getLogger("carb").setLevel(logging.NOTSET)


def test_framework(carb):
    framework = carb.get_framework()
    assert framework.get_plugins() == []
    with pytest.raises(CompatError, match="isaacsim.ros2.bridge.plugin.*no native Carbonite plugins"):
        framework.load_plugins(loaded_file_wildcards=["isaacsim.ros2.bridge.plugin"])
