"""The heap setting ``graphsdg view --rerun`` makes: glibc serves large blocks from the heap, not fresh mappings."""
from __future__ import annotations

import platform
import subprocess
import sys

import pytest

# malloc 4 MiB and print whether glibc mapped it on its own (the IS_MMAPPED bit of the chunk's size word)
PROBE = """
import ctypes, ctypes.util, sys
from graphsdg.base.heap import keep_freed_buffers
applied = keep_freed_buffers() if sys.argv[1] == "keep" else None
libc = ctypes.CDLL(ctypes.util.find_library("c"))
libc.malloc.restype, libc.malloc.argtypes = ctypes.c_void_p, [ctypes.c_size_t]
block = libc.malloc(4 << 20)
print(applied, bool(ctypes.c_size_t.from_address(block - ctypes.sizeof(ctypes.c_size_t)).value & 2))
"""


def _probe(mode: str) -> str:
    return subprocess.run([sys.executable, "-c", PROBE, mode], capture_output=True, text=True, check=True).stdout.split()


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="mallopt and the chunk layout are glibc's")
def test_a_large_block_comes_from_the_heap_once_freed_buffers_are_kept():
    assert _probe("default") == ["None", "True"]     # glibc's default: a 4 MiB block is a mapping of its own
    assert _probe("keep") == ["True", "False"]       # kept: from the heap, reused once freed
