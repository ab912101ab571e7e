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


# a child started after the setting: the environment glibc reads at start decides where its 4 MiB block comes from
CHILD = """
import ctypes, ctypes.util
libc = ctypes.CDLL(ctypes.util.find_library("c"))
libc.malloc.restype, libc.malloc.argtypes = ctypes.c_void_p, [ctypes.c_size_t]
block = libc.malloc(4 << 20)
print(bool(ctypes.c_size_t.from_address(block - ctypes.sizeof(ctypes.c_size_t)).value & 2))
"""
PARENT = """
import os, subprocess, sys
from graphsdg.base.heap import keep_freed_buffers_here_and_in_children
if sys.argv[1] == "user":
    os.environ["MALLOC_MMAP_THRESHOLD_"] = str(1 << 20)     # the user's own setting: 1 MiB, kept as it is
keep_freed_buffers_here_and_in_children()
child = subprocess.run([sys.executable, "-c", sys.argv[2]], capture_output=True, text=True, check=True)
print(os.environ["MALLOC_MMAP_THRESHOLD_"], child.stdout.strip())
"""


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="glibc's environment tunables and chunk layout")
def test_processes_started_after_the_setting_keep_large_blocks_too():
    def parent(mode: str) -> list[str]:
        return subprocess.run([sys.executable, "-c", PARENT, mode, CHILD], capture_output=True, text=True,
                              check=True).stdout.split()

    assert parent("default") == [str(64 << 20), "False"]    # the child's 4 MiB block comes from its heap
    assert parent("user") == [str(1 << 20), "True"]          # the user's 1 MiB threshold stands: a mapping
