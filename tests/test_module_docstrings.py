"""Module docstrings open with one short sentence saying what the module is, and hold no measurements.

Measurements, and the alternatives they ruled out, live in docs/performance.md (a section per topic); a
module's docstring says what the module is and does.
"""
from __future__ import annotations

import ast
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGES = ("graphsdg", "nodes")
MAX_WORDS = 20
# a sentence ends at . ! or ? before white space, except in e.g. / i.e. / etc. / vs.
SENTENCE_END = re.compile(r"(?<!\be\.g)(?<!\bi\.e)(?<!\betc)(?<!\bvs)[.!?](?=\s|$)")
# a number with a unit of time, rate or share: "3.5 ms", "~40 us", "1,500 fps", "60 %", "25 frames", "0.1 s"
MEASUREMENT = re.compile(r"(?<![\w./^])~?\d+(?:[.,]\d+)*\s*(?:ms|fps|frames|s|us|µs|%|milliseconds|"
                         r"microseconds|seconds)(?![\w/])")


def module_docstrings() -> list[tuple[str, str | None]]:
    found = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")), clean=True)
            found.append((str(path.relative_to(ROOT)), doc))
    return found


def first_sentence(doc: str) -> str:
    """The docstring's first sentence, its white space collapsed (the whole first paragraph if it has no end)."""
    paragraph = " ".join(re.split(r"\n\s*\n", doc.strip(), maxsplit=1)[0].split())
    end = SENTENCE_END.search(paragraph)
    return paragraph[:end.end()] if end else paragraph


def prose(doc: str) -> str:
    """The docstring without its doctest examples (``>>>`` lines and the output lines that follow them)."""
    kept, in_example = [], False
    for line in doc.splitlines():
        stripped = line.strip()
        if stripped.startswith(">>>"):
            in_example = True
        elif not stripped:
            in_example = False
        if not in_example:
            kept.append(line)
    return "\n".join(kept)


DOCSTRINGS = module_docstrings()


def test_every_module_has_a_docstring():
    missing = [path for path, doc in DOCSTRINGS if not doc]
    assert not missing, f"modules without a docstring: {missing}"


def test_first_sentences_are_short():
    long = {path: f"{len(first_sentence(doc).split())} words: {first_sentence(doc)}"
            for path, doc in DOCSTRINGS if doc and len(first_sentence(doc).split()) > MAX_WORDS}
    assert not long, f"first sentences over {MAX_WORDS} words: {long}"


def test_no_module_docstring_holds_a_measurement():
    measured = {path: MEASUREMENT.findall(prose(doc)) for path, doc in DOCSTRINGS if doc}
    measured = {path: found for path, found in measured.items() if found}
    assert not measured, f"measurements in module docstrings (move them to docs/performance.md): {measured}"


@pytest.mark.parametrize("doc, words", [
    ("What it is: a thing.\n\nMore.", 5),
    ("Reads e.g. ``a.b`` files. Then more.", 4),
    ("One paragraph with no end", 5),
])
def test_first_sentence_rule(doc, words):
    assert len(first_sentence(doc).split()) == words


@pytest.mark.parametrize("text, found", [
    ("took 1.9 ms a call", ["1.9 ms"]), ("~40 us a read", ["~40 us"]), ("1,500 fps", ["1,500 fps"]),
    ("cut it by 12 %", ["12 %"]), ("every 25 frames", ["25 frames"]), ("starts in ~0.1 s", ["~0.1 s"]),
    ("5.5 milliseconds", ["5.5 milliseconds"]), ("a 512x512 frame, 16 processes, H100, 3D boxes", []),
    ("steps of 1/60 s", []), ("10^6 steps", []),
])
def test_measurement_rule(text, found):
    assert MEASUREMENT.findall(text) == found


def test_doctest_output_is_not_prose():
    assert prose("Text.\n\n    >>> report()\n    Runtime: 5.0 ms\n\nAfter.") == "Text.\n\n\nAfter."
