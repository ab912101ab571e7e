"""The ground floor: leaves every room may import (settings, profiling, interrupts, core counts).

Nothing here imports another graphsdg room but ``graphsdg.errors``.
"""
