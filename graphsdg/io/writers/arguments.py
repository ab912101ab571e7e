"""Checks and conversions of the arguments that every dataset writer takes.

Each raises an error naming the writer, the bad value and what was expected.

Example:
    >>> semantic_filter_text("KittiWriter", ["class", "shape"], None)
    'class:*; shape:*'
    >>> image_extension("CocoWriter", "JPEG")
    'jpg'
"""
from __future__ import annotations

import datetime as _dt
import os
from typing import Any, Sequence

from graphsdg.annotate.semantic_filter import SemanticFilter
from graphsdg.io.backends import BackendDispatch, BackendGroup, BaseBackend

IMAGE_FORMATS = ("png", "jpg", "jpeg")


def output_backend(writer: str, output_dir: Any = None, backend: BaseBackend | None = None,
                   overwrite: bool = True, s3_bucket: str | None = None, s3_region: str | None = None,
                   s3_endpoint: str | None = None, use_s3: bool | None = None) -> BaseBackend:
    """The backend a writer writes through: ``backend``, the backend of ``output_dir``, or both grouped.

    ``s3_bucket`` (with ``s3_region`` and ``s3_endpoint``) writes to that bucket under the key prefix
    ``output_dir``, as Replicator's ``BackendDispatch(key_prefix=output_dir, bucket=..., region=...,
    endpoint_url=...)``; ``use_s3`` is Isaac's PoseWriter switch for the same. An ``output_dir`` that is an
    ``s3://bucket/prefix`` URL (or relative, under an ``s3://`` ``graphsdg run --out``) writes there too.
    No output at all raises Replicator's ``ValueError``.
    """
    s3 = {"s3_region": s3_region, "s3_endpoint": s3_endpoint}
    if use_s3 is not None and not use_s3 and s3_bucket:
        raise ValueError(f"{writer}: s3_bucket={s3_bucket!r} is given but use_s3 is False; pass use_s3=True to "
                         f"write to S3")
    if use_s3 and not s3_bucket:
        raise ValueError(f"{writer}: use_s3=True needs s3_bucket")
    if not s3_bucket and any(s3.values()):
        given = sorted(k for k, v in s3.items() if v)
        raise ValueError(f"{writer}: {', '.join(given)} given without s3_bucket; S3 output needs the bucket "
                         f"(s3_bucket=...)")
    if output_dir is None and backend is None and not s3_bucket:
        raise ValueError(f"No `backend`, `output_dir` or `s3_` parameter specified; {writer} needs somewhere to "
                         f"write (e.g. output_dir='_out')")
    if output_dir is not None and not isinstance(output_dir, (str, os.PathLike)):
        raise TypeError(f"{writer}: output_dir must be a path (str or os.PathLike), got {output_dir!r}")
    if backend is not None and not isinstance(backend, BaseBackend):
        raise TypeError(f"{writer}: backend must be a backend from rep.backends.get(...), got {backend!r}")
    backends = [backend] if backend is not None else []
    if s3_bucket:
        if not isinstance(s3_bucket, str):
            raise TypeError(f"{writer}: s3_bucket must be a bucket name, got {s3_bucket!r}")
        backends.append(BackendDispatch(key_prefix=os.fspath(output_dir or ""), bucket=s3_bucket, region=s3_region,
                                        endpoint_url=s3_endpoint, overwrite=overwrite))
    elif output_dir is not None:
        backends.append(BackendDispatch(output_dir=output_dir, overwrite=overwrite))
    return backends[0] if len(backends) == 1 else BackendGroup(backends)


def semantic_filter_text(writer: str, semantic_types: Sequence[str] | None, predicate: str | None,
                         default: str = "class:*") -> str:
    """The filter predicate from ``semantic_types`` or ``semantic_filter_predicate`` (mutually exclusive)."""
    if semantic_types is not None and predicate is not None:
        raise ValueError(f"{writer}: `semantic_types` ({semantic_types!r}) and `semantic_filter_predicate` "
                         f"({predicate!r}) are mutually exclusive; pass one")
    if predicate is not None:
        return SemanticFilter.parse(predicate).text
    if semantic_types is not None:
        if isinstance(semantic_types, str) or not all(isinstance(t, str) and t for t in semantic_types) \
                or not len(semantic_types):
            raise ValueError(f"{writer}: semantic_types must be a non-empty list of type names such as ['class'], "
                             f"got {semantic_types!r}")
        return SemanticFilter.from_types(semantic_types).text
    return SemanticFilter.parse(default).text


def frame_padding(writer: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{writer}: frame_padding must be a non-negative integer, got {value!r}")
    return value


def image_extension(writer: str, value: Any) -> str:
    """``"png"`` or ``"jpg"`` from Replicator's ``image_output_format``."""
    ext = str(value).lower().lstrip(".")
    if ext not in IMAGE_FORMATS:
        raise ValueError(f"{writer}: image_output_format must be one of {IMAGE_FORMATS}, got {value!r}")
    return "jpg" if ext == "jpeg" else ext


def creation_time(value: Any = None) -> _dt.datetime:
    """The dataset's creation time: ``value``, else ``$SOURCE_DATE_EPOCH``, else now.

    Setting ``SOURCE_DATE_EPOCH`` (the reproducible-builds convention) makes the
    dates inside COCO files, and so their bytes, reproducible.
    """
    if isinstance(value, _dt.datetime):
        return value
    if isinstance(value, str):
        return _dt.datetime.fromisoformat(value)
    if value is not None:
        raise TypeError(f"date must be a datetime or ISO-8601 string, got {value!r}")
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    if epoch:
        return _dt.datetime.fromtimestamp(int(epoch), tz=_dt.timezone.utc)
    return _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0)


def camera_name(camera_path: str) -> str:
    """Replicator's file-name form of a camera path: ``/Replicator/My_Cam`` -> ``My-Cam``."""
    return camera_path[1:].replace("Replicator/", "").replace("/", "-").replace("_", "-")
