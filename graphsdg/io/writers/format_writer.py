"""The base class of graphsdg's dataset-format writers (KITTI, COCO, YOLO, BOP, ...).

It holds the constructor preamble they share: the format's version, the data layout they receive, the output
backend (``output_dir``, ``backend`` or an S3 bucket) and the semantic filter their annotators read.

Example:
    >>> import tempfile
    >>> class LabelCounter(FormatWriter):
    ...     def __init__(self, output_dir=None, semantic_types=None, backend=None):
    ...         super().__init__(output_dir, backend, version="1.0")
    ...         self.filter = self.semantic_filter(semantic_types, default_types=["class"])
    ...     def write(self, data):
    ...         pass
    >>> w = LabelCounter(tempfile.mkdtemp())
    >>> w.version, w.data_structure, w.filter, w.semantic_types
    ('1.0', 'renderProduct', 'class:*', ['class'])
"""
from __future__ import annotations

from typing import Any, Sequence

from graphsdg.io.backends import BaseBackend
from graphsdg.io.writer import Writer
from graphsdg.io.writers import arguments


class FormatWriter(Writer):
    """A dataset-format writer: one output backend, a version, and errors that name the writer."""

    def __init__(self, output_dir: Any = None, backend: BaseBackend | None = None, *, version: str,
                 data_structure: str = "renderProduct", overwrite: bool = True, s3_bucket: str | None = None,
                 s3_region: str | None = None, s3_endpoint: str | None = None, use_s3: bool | None = None) -> None:
        """Set ``version`` and ``data_structure`` and open the output (:func:`arguments.output_backend`)."""
        self.version = version
        self.data_structure = data_structure
        self.backend = arguments.output_backend(type(self).__name__, output_dir, backend, overwrite=overwrite,
                                                s3_bucket=s3_bucket, s3_region=s3_region, s3_endpoint=s3_endpoint,
                                                use_s3=use_s3)
        self.output_dir = getattr(self.backend, "output_dir", None)

    def semantic_filter(self, semantic_types: Sequence[str] | None, predicate: str | None = None,
                        default_types: Sequence[str] | None = None) -> str:
        """The annotators' filter predicate from ``semantic_types`` (else ``default_types``) or ``predicate``.

        Sets ``self.semantic_types`` (None when neither list is given); raises naming the writer when the two
        arguments are both given or the types are not a list of names (:func:`arguments.semantic_filter_text`).
        """
        if semantic_types is None and default_types is not None:
            semantic_types = default_types
        text = arguments.semantic_filter_text(type(self).__name__, semantic_types, predicate)
        self.semantic_types = list(semantic_types) if semantic_types else None
        return text
