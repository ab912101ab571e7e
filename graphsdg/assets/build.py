"""Regenerate the built-in asset pack: ``python -m graphsdg.assets.build [--out DIR]``.

Without ``--out`` the pack is written in place (``graphsdg/assets/pack``), which
is what gets committed and shipped. The output is a pure function of the code:
running it twice gives the same files.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys

from graphsdg.assets.catalog import build_all
from graphsdg.assets.root import builtin_pack_root


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m graphsdg.assets.build", description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=builtin_pack_root(), help="pack root to (re)write (default: in place)")
    parser.add_argument("--clean", action="store_true", help="delete the output folder first")
    args = parser.parse_args(argv)
    if args.clean and os.path.isdir(args.out):
        shutil.rmtree(args.out)
    written = build_all(args.out)
    total = sum(os.path.getsize(os.path.join(args.out, p.lstrip("/"))) for p in written)
    for p in written:
        print(p)
    print(f"{len(written)} files, {total / 1e6:.2f} MB under {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
