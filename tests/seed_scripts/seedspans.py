"""Where each vendored seed script comes from, and a check that it is that text.

The Isaac Sim documents in ``../shared/seeds`` are the contract. Their scripts
are vendored here as runnable files; seed 001 kept its indentation, seeds 000
and 002 lost it (002 is also flattened onto long lines), so those files were
re-indented by hand. The only allowed difference is whitespace, which
:func:`verify` proves: a vendored file with every whitespace character removed
equals its span of the seed document with every whitespace character removed.

Where a document flattened a script, a comment runs on into the code after
it, so a restoration could hide code inside a comment without changing the
whitespace-free text; :func:`suspicious_comments` flags comments that look
like code in those scripts.

Usage (from anywhere)::

    python tests/seed_scripts/seedspans.py                 # verify every script
    python tests/seed_scripts/seedspans.py --extract NAME  # print NAME's raw span
"""
from __future__ import annotations

import argparse
import ast
import io
import os
import re
import sys
import tokenize
from dataclasses import dataclass

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))


@dataclass(frozen=True)
class Span:
    """A script's place in a seed document: the first line matching ``start`` at or after the end of the
    previous span of the same document, through the first line after it matching ``end``."""

    name: str
    seed: str    # file name prefix in the seeds folder, e.g. "001"
    start: str   # regex matched against a stripped line
    end: str
    flattened: bool = False   # the document ran the script's lines together

    @property
    def path(self) -> str:
        return os.path.join(HERE, self.name + ".py")


def _gs(n: int) -> list[Span]:
    return [Span(f"sdg_getting_started_{n:02d}_script_editor", "001", r"^import asyncio$",
                 r"^asyncio\.ensure_future\("),
            Span(f"sdg_getting_started_{n:02d}", "001", r"^import os$", r"^simulation_app\.close\(\)$")]


SPANS: list[Span] = [s for n in range(1, 6) for s in _gs(n)] + [
    Span("sdg_workflow_01_script_editor", "000", r'^"""', r"^asyncio\.ensure_future\(run_workflow_async\(\)\)$"),
    Span("sdg_workflow_01", "000", r'^"""', r"^run_workflow\(\)$"),
    Span("sdg_workflow_02_script_editor", "000", r'^"""', r"^asyncio\.ensure_future\(run_workflow_async\(\)\)$"),
    Span("sdg_workflow_02", "000", r'^"""', r"^run_workflow\(\)$"),
    Span("ur10_palletizing_script_editor", "002", r"^import asyncio import json import os$",
         r"^asyncio\.ensure_future\(run_example_async\(\)\)$", flattened=True),
]


def seeds_dir() -> str | None:
    """The seed documents: ``$GRAPHSDG_SEEDS``, ``/work/shared/seeds`` or ``../shared/seeds`` beside the clone."""
    for candidate in (os.environ.get("GRAPHSDG_SEEDS"), os.path.join(os.path.dirname(REPO), "shared", "seeds"),
                      "/work/shared/seeds"):
        if candidate and os.path.isdir(candidate):
            return candidate
    return None


def _seed_lines(seed: str, folder: str) -> list[str]:
    names = [n for n in sorted(os.listdir(folder)) if n.startswith(seed + "_") and n.endswith(".txt")]
    if len(names) != 1:
        raise FileNotFoundError(f"expected one seed document {seed}_*.txt in {folder}, found {names}")
    with open(os.path.join(folder, names[0]), encoding="utf-8") as f:
        return f.read().splitlines()


def extract_all(folder: str) -> dict[str, str]:
    """Each span's raw text, as it stands in its seed document."""
    cursor: dict[str, int] = {}
    lines_of: dict[str, list[str]] = {}
    out = {}
    for span in SPANS:
        lines = lines_of.setdefault(span.seed, _seed_lines(span.seed, folder))
        i = cursor.get(span.seed, 0)
        while i < len(lines) and not re.search(span.start, lines[i].strip()):
            i += 1
        j = i
        while j < len(lines) and not re.search(span.end, lines[j].strip()):
            j += 1
        if j >= len(lines):
            raise ValueError(f"{span.name}: no span /{span.start}/../{span.end}/ in seed {span.seed}")
        out[span.name] = "\n".join(lines[i:j + 1]) + "\n"
        cursor[span.seed] = j + 1
    return out


def squeeze(text: str) -> str:
    return re.sub(r"\s+", "", text)


def suspicious_comments(source: str) -> list[str]:
    """Comments that look like code swallowed by a misplaced line break."""
    code_like = re.compile(r"self\.|\b[A-Za-z_]\w*\(|\s=\s|\breturn\s+\S+\s*$|\bawait\b")
    bad = []
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT and code_like.search(tok.string):
            bad.append(f"line {tok.start[0]}: {tok.string}")
    return bad


def verify(folder: str) -> list[str]:
    """Problems found (empty when every vendored script is its seed span up to whitespace)."""
    problems = []
    spans = extract_all(folder)
    for span in SPANS:
        if not os.path.isfile(span.path):
            problems.append(f"{span.name}: {span.path} is missing")
            continue
        with open(span.path, encoding="utf-8") as f:
            text = f.read()
        a, b = squeeze(text), squeeze(spans[span.name])
        if a != b:
            k = next((i for i, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b)))
            problems.append(f"{span.name}: differs from seed {span.seed} beyond whitespace at "
                            f"vendored ...{a[max(0, k - 40):k + 40]!r} vs seed ...{b[max(0, k - 40):k + 40]!r}")
        try:
            ast.parse(text, span.path)
        except SyntaxError as exc:
            problems.append(f"{span.name}: not valid Python: {exc}")
            continue
        if span.flattened:
            problems += [f"{span.name}: comment looks like code, {c}" for c in suspicious_comments(text)]
    return problems


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--extract", metavar="NAME", help="print the raw seed span of NAME")
    parser.add_argument("--seeds", help="seed documents folder")
    args = parser.parse_args(argv)
    folder = args.seeds or seeds_dir()
    if folder is None:
        print("no seeds folder found (set GRAPHSDG_SEEDS)", file=sys.stderr)
        return 2
    if args.extract:
        sys.stdout.write(extract_all(folder)[args.extract])
        return 0
    problems = verify(folder)
    for p in problems:
        print(p)
    print(f"{len(SPANS)} scripts, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
