"""Object storage: ``s3://bucket/prefix`` URLs and one S3 client per bucket, through boto3 (the AWS SDK).

An :class:`ObjectStore` is what every S3 reader and writer of graphsdg talks to
(:class:`graphsdg.io.backends.S3Backend`, :mod:`graphsdg.io.location`). It

* takes credentials, region and endpoint from the standard AWS chain (``AWS_ACCESS_KEY_ID`` /
  ``AWS_SECRET_ACCESS_KEY`` / ``AWS_PROFILE``, ``~/.aws/credentials`` and ``config``, an instance role;
  ``AWS_DEFAULT_REGION``; ``AWS_ENDPOINT_URL_S3`` or ``AWS_ENDPOINT_URL`` for an S3-compatible server),
  unless ``region`` / ``endpoint_url`` are given;
* checks the bucket when it is made (``HeadBucket`` with a short connect timeout and few attempts), so a
  bucket that does not exist, credentials that are wrong or missing and an endpoint that does not answer
  are each one clear error within seconds, before anything is written;
* retries throttling (``SlowDown``, 503) and dropped connections with exponential backoff
  (botocore's "standard" retry mode);
* writes every object whole or not at all: one ``PutObject`` (atomic in S3, with its MD5 checked by the
  server), or above :data:`MULTIPART_THRESHOLD` a multipart upload that is completed only when every part
  arrived and aborted on any failure;
* reports every failure as :class:`ObjectStoreError` (an ``OSError``) naming ``s3://bucket/key`` and the
  endpoint.

boto3 is optional: ``pip install 'graphsdg[s3]'``.

Example:
    >>> S3Url.parse("s3://bucket/runs/7").join("basic/rgb_0000.png")
    'runs/7/basic/rgb_0000.png'
    >>> str(S3Url.parse("s3://bucket/runs/7/").child("basic"))
    's3://bucket/runs/7/basic'
"""
from __future__ import annotations

import base64
import hashlib
import os
import posixpath
import re
import threading
from dataclasses import dataclass
from typing import Any, Iterator

S3_HINT = "pip install 'graphsdg[s3]'"
SCHEME = "s3://"
CONNECT_TIMEOUT_S = 3.0        # a reachable endpoint answers a TCP connect in milliseconds
READ_TIMEOUT_S = 60.0
MAX_ATTEMPTS = 6               # writes: throttling and dropped connections are retried with backoff
CHECK_ATTEMPTS = 2             # the up-front bucket check: a wrong endpoint must fail within seconds
MULTIPART_THRESHOLD = 64 << 20
PART_SIZE = 16 << 20
_BUCKET = re.compile(r"^[a-z0-9][a-z0-9.\-_]{1,61}[a-z0-9]$")


class S3MissingError(ImportError):
    """S3 output or input without boto3 installed."""


class ObjectStoreError(OSError):
    """A request to the object store failed; the message names ``s3://bucket/key`` and the endpoint."""


def is_s3_url(value: Any) -> bool:
    """Whether ``value`` is an ``s3://`` URL (a string)."""
    return isinstance(value, str) and value.startswith(SCHEME)


@dataclass(frozen=True)
class S3Url:
    """A bucket and a key prefix (no leading or trailing ``/``; empty for the bucket's root)."""

    bucket: str
    prefix: str = ""

    @classmethod
    def parse(cls, url: str) -> "S3Url":
        """``s3://bucket/a/b`` -> ``S3Url("bucket", "a/b")``; a clear error for anything else."""
        if not is_s3_url(url):
            raise ValueError(f"expected an s3://bucket/prefix URL, got {url!r}")
        bucket, _, prefix = url[len(SCHEME):].partition("/")
        check_bucket_name(bucket)
        return cls(bucket, clean_key(prefix, what=url))

    def join(self, rel: str) -> str:
        """The object key of ``rel`` (a ``/``-separated path) under this prefix."""
        rel = clean_key(rel, what=rel)
        return f"{self.prefix}/{rel}" if self.prefix and rel else (self.prefix or rel)

    def child(self, rel: str) -> "S3Url":
        """The URL of the folder ``rel`` under this one."""
        return S3Url(self.bucket, self.join(rel))

    def relative(self, key: str) -> str:
        """``key`` relative to this prefix (``key`` must lie under it)."""
        if not self.prefix:
            return key
        if not key.startswith(self.prefix + "/"):
            raise ValueError(f"s3://{self.bucket}/{key} is not under {self}")
        return key[len(self.prefix) + 1:]

    def __str__(self) -> str:
        return f"{SCHEME}{self.bucket}/{self.prefix}" if self.prefix else f"{SCHEME}{self.bucket}"


def check_bucket_name(bucket: str) -> None:
    """Raise ``ValueError`` unless ``bucket`` is a valid S3 bucket name (3-63 lower-case letters, digits, ``.-``)."""
    if not isinstance(bucket, str) or not _BUCKET.match(bucket):
        raise ValueError(f"{bucket!r} is not an S3 bucket name (3-63 characters: lower-case letters, digits, "
                         f"'.', '-')")


def clean_key(path: str, what: str) -> str:
    """A ``/``-separated key part without empty, ``.`` or leading/trailing parts; ``..`` is refused."""
    parts = [p for p in str(path).replace("\\", "/").split("/") if p not in ("", ".")]
    if ".." in parts:
        raise ValueError(f"{what!r}: '..' is not allowed in an S3 key")
    return posixpath.join(*parts) if parts else ""


def import_boto3():
    """The ``boto3`` module, or an error saying how to install it."""
    try:
        import boto3
    except ImportError as exc:
        raise S3MissingError(f"S3 output and s3:// URLs need boto3, which is not installed; {S3_HINT}") from exc
    return boto3


def _config(attempts: int, pool: int):
    from botocore.config import Config
    return Config(connect_timeout=CONNECT_TIMEOUT_S, read_timeout=READ_TIMEOUT_S, max_pool_connections=pool,
                  retries={"max_attempts": attempts, "mode": "standard"},
                  # the server checks each body against our MD5; no extra CRC trailers (not every S3-compatible
                  # server reads them)
                  request_checksum_calculation="when_required", response_checksum_validation="when_required")


class ObjectStore:
    """One bucket of an S3 (or S3-compatible) endpoint; safe to share between writer threads.

    ``check=True`` verifies the bucket and the credentials now (see the module docstring).
    """

    def __init__(self, bucket: str, region: str | None = None, endpoint_url: str | None = None,
                 check: bool = True) -> None:
        check_bucket_name(bucket)
        boto3 = import_boto3()
        self.bucket = bucket
        session = boto3.session.Session()
        kwargs = {"region_name": region or None, "endpoint_url": endpoint_url or None}
        self.client = session.client("s3", config=_config(MAX_ATTEMPTS, 32), **kwargs)
        self.endpoint = self.client.meta.endpoint_url
        self._checker = session.client("s3", config=_config(CHECK_ATTEMPTS, 2), **kwargs)
        if check:
            self.check()

    def url(self, key: str = "") -> str:
        return f"{SCHEME}{self.bucket}/{key}" if key else f"{SCHEME}{self.bucket}"

    # ---- errors ------------------------------------------------------------
    def _error(self, action: str, key: str, exc: BaseException) -> OSError:
        """One error naming the object, the endpoint and what went wrong."""
        from botocore.exceptions import ClientError, EndpointConnectionError, NoCredentialsError
        where = f"{self.url(key)} (endpoint {self.endpoint})"
        if isinstance(exc, NoCredentialsError):
            return ObjectStoreError(f"{action} {where}: no AWS credentials found; set AWS_ACCESS_KEY_ID and "
                                    f"AWS_SECRET_ACCESS_KEY, AWS_PROFILE or ~/.aws/credentials")
        if isinstance(exc, EndpointConnectionError):
            return ObjectStoreError(f"{action} {where}: cannot reach the endpoint ({exc}); check "
                                    f"s3_endpoint / AWS_ENDPOINT_URL and the network")
        if isinstance(exc, ClientError):
            err = exc.response.get("Error", {})
            code = str(err.get("Code", "")) or str(exc.response.get("ResponseMetadata", {}).get("HTTPStatusCode"))
            if code in ("NoSuchKey", "404") and key:
                return FileNotFoundError(f"{self.url(key)} does not exist (endpoint {self.endpoint})")
            if code in ("NoSuchBucket", "404"):
                return ObjectStoreError(f"{action} {where}: the bucket {self.bucket!r} does not exist; create it "
                                        f"or check s3_bucket and the endpoint")
            if code in ("403", "AccessDenied", "InvalidAccessKeyId", "SignatureDoesNotMatch", "ExpiredToken",
                        "InvalidToken"):
                return ObjectStoreError(f"{action} {where}: access denied ({code}); check the AWS credentials "
                                        f"(AWS_ACCESS_KEY_ID / AWS_SECRET_ACCESS_KEY, AWS_PROFILE, "
                                        f"~/.aws/credentials) and their permissions on the bucket")
            return ObjectStoreError(f"{action} {where}: {code}: {err.get('Message', exc)}")
        return ObjectStoreError(f"{action} {where}: {type(exc).__name__}: {exc}")

    def _call(self, action: str, key: str, fn, **kwargs):
        from botocore.exceptions import BotoCoreError, ClientError
        try:
            return fn(**kwargs)
        except (BotoCoreError, ClientError) as exc:
            raise self._error(action, key, exc) from exc

    # ---- the bucket ----------------------------------------------------------
    def check(self) -> None:
        """Raise a clear :class:`ObjectStoreError` unless the bucket exists and the credentials may use it."""
        self._call("cannot use bucket", "", self._checker.head_bucket, Bucket=self.bucket)

    # ---- objects -------------------------------------------------------------
    def put(self, key: str, data: bytes) -> None:
        """Write ``data`` to ``key``: the object appears whole or not at all."""
        data = bytes(data)
        if len(data) < MULTIPART_THRESHOLD:
            md5 = base64.b64encode(hashlib.md5(data).digest()).decode()   # the server refuses a torn body
            self._call("cannot write", key, self.client.put_object, Bucket=self.bucket, Key=key, Body=data,
                       ContentMD5=md5)
            return
        upload = self._call("cannot write", key, self.client.create_multipart_upload, Bucket=self.bucket,
                            Key=key)["UploadId"]
        try:
            parts = []
            for number, start in enumerate(range(0, len(data), PART_SIZE), start=1):
                chunk = data[start:start + PART_SIZE]
                md5 = base64.b64encode(hashlib.md5(chunk).digest()).decode()
                etag = self._call("cannot write", key, self.client.upload_part, Bucket=self.bucket, Key=key,
                                  UploadId=upload, PartNumber=number, Body=chunk, ContentMD5=md5)["ETag"]
                parts.append({"PartNumber": number, "ETag": etag})
            self._call("cannot write", key, self.client.complete_multipart_upload, Bucket=self.bucket, Key=key,
                       UploadId=upload, MultipartUpload={"Parts": parts})
        except BaseException:
            # nothing half written: the parts uploaded so far are dropped, no object appears
            try:
                self.client.abort_multipart_upload(Bucket=self.bucket, Key=key, UploadId=upload)
            except Exception:  # noqa: BLE001 - the original failure is what the script must see
                pass
            raise

    def get(self, key: str) -> bytes:
        """The bytes of ``key`` (``FileNotFoundError`` if there is no such object)."""
        return self._call("cannot read", key, self.client.get_object, Bucket=self.bucket, Key=key)["Body"].read()

    def exists(self, key: str) -> bool:
        """Whether the object ``key`` exists."""
        try:
            self._call("cannot look up", key, self.client.head_object, Bucket=self.bucket, Key=key)
        except FileNotFoundError:
            return False
        return True

    def list(self, prefix: str = "") -> Iterator[tuple[str, int]]:
        """``(key, size)`` of every object whose key starts with ``prefix``, in key order."""
        pages = self.client.get_paginator("list_objects_v2").paginate(Bucket=self.bucket, Prefix=prefix)
        from botocore.exceptions import BotoCoreError, ClientError
        try:
            for page in pages:
                for item in page.get("Contents", []):
                    yield item["Key"], int(item["Size"])
        except (BotoCoreError, ClientError) as exc:
            raise self._error("cannot list", prefix, exc) from exc

    def copy(self, src: str, dst: str) -> None:
        """Copy ``src`` to ``dst`` inside the bucket (server side; atomic like a put)."""
        self._call("cannot copy to", dst, self.client.copy_object, Bucket=self.bucket, Key=dst,
                   CopySource={"Bucket": self.bucket, "Key": src})

    def delete(self, keys: list[str]) -> None:
        """Delete ``keys`` (missing ones are fine)."""
        keys = list(keys)
        for i in range(0, len(keys), 1000):     # DeleteObjects takes at most 1000 keys
            batch = keys[i:i + 1000]
            reply = self._call("cannot delete", batch[0], self.client.delete_objects, Bucket=self.bucket,
                               Delete={"Objects": [{"Key": k} for k in batch], "Quiet": True})
            if reply.get("Errors"):
                first = reply["Errors"][0]
                raise ObjectStoreError(f"cannot delete {self.url(first.get('Key', ''))} (endpoint {self.endpoint}): "
                                       f"{first.get('Code')}: {first.get('Message')}")

    def abort_uploads(self, prefix: str) -> int:
        """Abort the unfinished multipart uploads under ``prefix`` (what a killed writer leaves); return how many."""
        reply = self._call("cannot list uploads under", prefix, self.client.list_multipart_uploads,
                           Bucket=self.bucket, Prefix=prefix)
        uploads = reply.get("Uploads", [])
        for up in uploads:
            self._call("cannot abort the upload of", up["Key"], self.client.abort_multipart_upload,
                       Bucket=self.bucket, Key=up["Key"], UploadId=up["UploadId"])
        return len(uploads)


_stores: dict[tuple, ObjectStore] = {}
_stores_lock = threading.Lock()


def store(bucket: str, region: str | None = None, endpoint_url: str | None = None) -> ObjectStore:
    """The process's :class:`ObjectStore` of ``bucket`` at ``endpoint_url`` (made and checked on first use).

    One client per bucket and endpoint: building a boto3 client costs tens of milliseconds, and a client
    is safe to share between threads.
    """
    # the credentials are part of the key (hashed): a process whose environment changed gets a new client
    env = "\0".join(os.environ.get(k, "") for k in ("AWS_ACCESS_KEY_ID", "AWS_SECRET_ACCESS_KEY", "AWS_SESSION_TOKEN",
                                                   "AWS_PROFILE", "AWS_ENDPOINT_URL_S3", "AWS_ENDPOINT_URL"))
    key = (bucket, region or None, endpoint_url or None, hashlib.sha256(env.encode()).hexdigest())
    with _stores_lock:
        found = _stores.get(key)
    if found is not None:
        return found
    made = ObjectStore(bucket, region, endpoint_url)     # outside the lock: the check is a network call
    with _stores_lock:
        return _stores.setdefault(key, made)


def forget_stores() -> None:
    """Drop the cached clients (credentials or endpoints changed, e.g. between tests)."""
    with _stores_lock:
        _stores.clear()


#: the environment variables that point boto3 at an endpoint and region (no secrets): forwarded to shards
ENVIRONMENT = ("AWS_ENDPOINT_URL", "AWS_ENDPOINT_URL_S3", "AWS_REGION", "AWS_DEFAULT_REGION", "AWS_PROFILE",
               "AWS_CONFIG_FILE", "AWS_SHARED_CREDENTIALS_FILE")
