"""The SDG throughput benchmark (``graphsdg bench``) and its per-phase time accumulators. The benchmark is
:mod:`graphsdg.benchmark.throughput`; the named accumulators that it and ``rep.orchestrator.get_profile()`` report
are :mod:`graphsdg.base.profiling`."""
