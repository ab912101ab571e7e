"""A real S3-compatible server on the loopback address. For tests, benchmarks and trying S3 output offline.

:class:`LocalS3Server` runs moto's server (``python -m moto.server``, from ``pip install 'moto[server]'``)
as a child process on ``127.0.0.1``, makes an IAM user with an access key allowed ``s3:*`` and then
switches the server's authentication on: from then on every request must carry a valid SigV4 signature
of that key, so wrong credentials fail as they do on AWS. :meth:`LocalS3Server.environment` is what
points boto3 (and so graphsdg) at it through the standard AWS variables.

Example:
    >>> with LocalS3Server() as server:                                  # doctest: +SKIP
    ...     server.create_bucket("data")
    ...     os.environ.update(server.environment())
    ...     # graphsdg run job.py --out s3://data/run1 ...
"""
from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

from graphsdg.io.object_store import import_boto3

REGION = "us-east-1"
USER = "graphsdg"
_ALLOW_S3 = {"Version": "2012-10-17", "Statement": [{"Effect": "Allow", "Action": "s3:*", "Resource": "*"}]}


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _die_with_parent() -> None:
    """In the child, before exec: Linux sends it SIGTERM when the process that started it dies, so a killed
    test run leaves no server behind (elsewhere nothing is done)."""
    try:
        import ctypes
        import signal
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGTERM)     # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


class LocalS3Server:
    """moto's S3 server in a child process on ``127.0.0.1:port``, with credentials checked."""

    def __init__(self, port: int | None = None, start_timeout_s: float = 60.0) -> None:
        self.port = port or free_port()
        self.endpoint = f"http://127.0.0.1:{self.port}"
        self.start_timeout_s = start_timeout_s
        self.access_key_id = ""
        self.secret_access_key = ""
        self._proc: subprocess.Popen | None = None
        self._log = tempfile.TemporaryFile()

    def start(self) -> "LocalS3Server":
        """Start the server, make the user and its key, switch authentication on."""
        try:
            import moto.server  # noqa: F401 - only to fail early with the install hint
        except ImportError as exc:
            raise ImportError("LocalS3Server needs moto's server: pip install 'moto[server]'") from exc
        env = {k: v for k, v in os.environ.items() if not k.startswith("AWS_")}
        env["AWS_EC2_METADATA_DISABLED"] = "true"
        self._proc = subprocess.Popen([sys.executable, "-m", "moto.server", "-H", "127.0.0.1", "-p", str(self.port)],
                                      stdout=self._log, stderr=subprocess.STDOUT, env=env,
                                      preexec_fn=_die_with_parent)
        deadline = time.monotonic() + self.start_timeout_s
        while True:
            if self._proc.poll() is not None:
                raise RuntimeError(f"the moto server exited with {self._proc.returncode}: {self.output()[-2000:]}")
            try:
                with socket.create_connection(("127.0.0.1", self.port), timeout=0.5):
                    break
            except OSError:
                if time.monotonic() > deadline:
                    self.stop()
                    raise TimeoutError(f"the moto server did not listen on port {self.port} within "
                                       f"{self.start_timeout_s:.0f} s")
                time.sleep(0.1)
        # before authentication is on, any signature is accepted: make the user that will sign from now on
        iam = self._client("iam", "bootstrap", "bootstrap")
        iam.create_user(UserName=USER)
        iam.put_user_policy(UserName=USER, PolicyName="s3", PolicyDocument=json.dumps(_ALLOW_S3))
        key = iam.create_access_key(UserName=USER)["AccessKey"]
        self.access_key_id, self.secret_access_key = key["AccessKeyId"], key["SecretAccessKey"]
        request = urllib.request.Request(f"{self.endpoint}/moto-api/reset-auth", data=b"0", method="POST",
                                         headers={"Content-Type": "text/plain"})   # a form body would be parsed away
        with urllib.request.urlopen(request, timeout=10) as reply:
            reply.read()
        return self

    def _client(self, service: str, key_id: str | None = None, secret: str | None = None):
        boto3 = import_boto3()
        return boto3.session.Session().client(service, endpoint_url=self.endpoint, region_name=REGION,
                                              aws_access_key_id=key_id or self.access_key_id,
                                              aws_secret_access_key=secret or self.secret_access_key)

    def s3(self):
        """A boto3 S3 client signed with the server's key."""
        return self._client("s3")

    def create_bucket(self, name: str) -> None:
        self.s3().create_bucket(Bucket=name)

    def environment(self) -> dict[str, str]:
        """The standard AWS variables that send boto3 here with the server's credentials."""
        return {"AWS_ENDPOINT_URL_S3": self.endpoint, "AWS_ACCESS_KEY_ID": self.access_key_id,
                "AWS_SECRET_ACCESS_KEY": self.secret_access_key, "AWS_DEFAULT_REGION": REGION,
                # the credential chain must never ask a cloud's instance metadata service from here
                "AWS_EC2_METADATA_DISABLED": "true"}

    def objects(self, bucket: str, prefix: str = "") -> dict[str, bytes]:
        """Every object under ``prefix`` (key relative to it -> bytes)."""
        s3 = self.s3()
        out = {}
        for page in s3.get_paginator("list_objects_v2").paginate(Bucket=bucket, Prefix=prefix):
            for item in page.get("Contents", []):
                rel = item["Key"][len(prefix):].lstrip("/")
                out[rel] = s3.get_object(Bucket=bucket, Key=item["Key"])["Body"].read()
        return out

    def cpu_seconds(self) -> float:
        """CPU time the server process used so far (Linux ``/proc``): what serving the requests cost."""
        if self._proc is None:
            return 0.0
        with open(f"/proc/{self._proc.pid}/stat", encoding="ascii") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")     # utime + stime

    def output(self) -> str:
        """What the server printed so far."""
        self._log.seek(0)
        return self._log.read().decode(errors="replace")

    def stop(self) -> None:
        if self._proc is not None and self._proc.poll() is None:
            self._proc.terminate()
            try:
                self._proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        self._proc = None

    def __enter__(self) -> "LocalS3Server":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()
