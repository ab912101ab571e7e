"""The SDG throughput benchmark (``graphsdg bench``: :mod:`graphsdg.benchmark.throughput`) and the named
per-phase time accumulators that it and ``rep.orchestrator.get_profile()`` report
(:mod:`graphsdg.base.profiling`)."""
