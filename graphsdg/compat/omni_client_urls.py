"""``omni.client``'s URL functions and types: parse, build, normalise and combine URLs and local paths.

By Omniverse's client-library contract: a URL with a scheme (``omniverse://host/path``,
``file:/path``, ``https://...``) or a *raw* local path (``/tmp/x.usd``), broken
into a :class:`Url` whose absent parts are None. :func:`local_file_path` says
which local file a ``file:`` URL or raw path names; ``omniverse://`` URLs are
mapped onto local trees by :mod:`graphsdg.compat.omni_client`.

Example:
    >>> from graphsdg.compat.omni_client_urls import break_url, make_url, combine_urls
    >>> url = break_url("omniverse://localhost:3009/NVIDIA/Assets/a%20b.usd?checkpoint=2")
    >>> (url.scheme, url.host, url.port, url.path, url.query)
    ('omniverse', 'localhost', '3009', '/NVIDIA/Assets/a b.usd', 'checkpoint=2')
    >>> make_url(scheme="omniverse", host="localhost", path="/NVIDIA/a b.usd")
    'omniverse://localhost/NVIDIA/a%20b.usd'
    >>> combine_urls("omniverse://localhost/NVIDIA/Assets/scene.usd", "../Materials/m.mdl")
    'omniverse://localhost/NVIDIA/Materials/m.mdl'
"""
from __future__ import annotations

import os
import posixpath
import re
import threading
from dataclasses import dataclass
from urllib.parse import quote, unquote

_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.\-]*):")
_WINDOWS_DRIVE = re.compile(r"^[A-Za-z]:[\\/]")


@dataclass(frozen=True)
class Url:
    """omni.client.Url: a URL's parts (percent-decoded; None where the URL has none)."""

    scheme: str | None = None
    user: str | None = None
    host: str | None = None
    port: str | None = None
    path: str | None = None
    query: str | None = None
    fragment: str | None = None
    is_raw: bool = False


def _is_raw(url: str) -> bool:
    """Whether ``url`` is a raw local path rather than a URL (no scheme, or a Windows drive letter)."""
    return not _SCHEME.match(url) or bool(_WINDOWS_DRIVE.match(url))


def _split(url: str, reference: bool) -> Url:
    match = _SCHEME.match(url)
    scheme = None
    rest = url
    if match and not _WINDOWS_DRIVE.match(url):
        scheme, rest = match.group(1).lower(), url[match.end():]
    elif not reference:
        return Url(path=url, is_raw=True)
    fragment = query = None
    if "#" in rest:
        rest, fragment = rest.split("#", 1)
        fragment = unquote(fragment)
    if "?" in rest:
        rest, query = rest.split("?", 1)
        query = unquote(query)
    user = host = port = None
    if rest.startswith("//"):
        authority, slash, path = rest[2:].partition("/")
        path = slash + path
        if "@" in authority:
            user, authority = authority.rsplit("@", 1)
            user = unquote(user)
        if authority.startswith("["):   # an IPv6 literal
            end = authority.find("]")
            host, after = authority[:end + 1], authority[end + 1:]
            port = after[1:] if after.startswith(":") else None
        elif ":" in authority:
            host, port = authority.rsplit(":", 1)
        else:
            host = authority
        host = host or None
        port = port or None
    else:
        path = rest
    return Url(scheme=scheme, user=user, host=host, port=port, path=unquote(path) if path else None,
               query=query, fragment=fragment)


def break_url(url: str) -> Url:
    """A full URL (``scheme:...``) or a raw local path (then only ``path`` is set and ``is_raw`` is True)."""
    return _split(os.fspath(url), reference=False)


def break_url_reference(url: str) -> Url:
    """As :func:`break_url`, but a string without a scheme is a relative URL reference (``/p?q#f`` splits)."""
    return _split(os.fspath(url), reference=True)


def make_url(scheme: str | None = None, user: str | None = None, host: str | None = None,
             port: str | int | None = None, path: str | None = None, query: str | None = None,
             fragment: str | None = None) -> str:
    """The URL of these parts, percent-encoding each; with nothing but a path, the path as given."""
    if scheme is None and user is None and host is None and port is None and query is None and fragment is None:
        return path or ""
    out = f"{scheme}:" if scheme else ""
    if host is not None or user is not None or port is not None:
        out += "//"
        if user is not None:
            out += quote(user, safe="") + "@"
        out += host or ""
        if port is not None:
            out += f":{port}"
    if path:
        out += quote(path.replace("\\", "/"), safe="/:@!$&'()*+,;=-._~")
    if query is not None:
        out += "?" + quote(query, safe="/:@!$&'()*+,;=-._~?")
    if fragment is not None:
        out += "#" + quote(fragment, safe="/:@!$&'()*+,;=-._~?")
    return out


def make_file_url(path: str) -> str:
    """The ``file:`` URL of the local path ``path`` (made absolute)."""
    return "file:" + quote(os.path.abspath(os.fspath(path)).replace("\\", "/"), safe="/:@!$&'()*+,;=-._~")


def _normalize_path(path: str) -> str:
    if not path:
        return path
    trailing = path.endswith("/")
    normal = posixpath.normpath(path)
    if path.startswith("//") and not normal.startswith("//"):
        normal = "/" + normal.lstrip("/")
    return normal + ("/" if trailing and not normal.endswith("/") else "")


def normalize_url(url: str) -> str:
    """``url`` with a lower-case scheme, ``/`` separators and ``.`` / ``..`` segments resolved."""
    url = os.fspath(url).replace("\\", "/")
    parts = break_url(url)
    if parts.is_raw:
        return _normalize_path(url)
    return make_url(parts.scheme, parts.user, parts.host, parts.port, _normalize_path(parts.path or ""),
                    parts.query, parts.fragment)


def combine_urls(base_url: str, other_url: str) -> str:
    """``other_url`` resolved against ``base_url`` (RFC 3986 style; a URL or absolute path in ``other_url`` wins)."""
    base_url, other_url = os.fspath(base_url), os.fspath(other_url)
    if not base_url:
        return normalize_url(other_url)
    other = break_url_reference(other_url)
    if other.scheme is not None or _WINDOWS_DRIVE.match(other_url):
        return normalize_url(other_url)
    base = break_url(base_url)
    base_path = base.path or ""
    if other.host is not None:   # //host/path: keep only the scheme
        return make_url(base.scheme, other.user, other.host, other.port, _normalize_path(other.path or "/"),
                        other.query, other.fragment)
    if other.path and other.path.startswith("/"):
        path = other.path
    elif other.path:
        path = posixpath.join(base_path.rsplit("/", 1)[0] + "/" if "/" in base_path else "", other.path)
    else:
        path = base_path
    path = _normalize_path(path)
    if base.is_raw:
        return path
    query = other.query if other.path or other.query is not None else base.query
    return make_url(base.scheme, base.user, base.host, base.port, path, query, other.fragment)


def make_relative_url(base_url: str, other_url: str) -> str:
    """The shortest reference to ``other_url`` from ``base_url`` (``other_url`` itself where they share no root)."""
    base, other = break_url(base_url), break_url(other_url)
    if (base.scheme, base.host, base.port) != (other.scheme, other.host, other.port) or not other.path:
        return other_url
    start = posixpath.dirname(base.path or "/")
    relative = posixpath.relpath(other.path, start or "/")
    return relative if relative.startswith("../") else "./" + relative


def local_file_path(url: str) -> str | None:
    """The local file a raw path or ``file:`` URL names (absolute), or None for any other scheme."""
    url = os.fspath(url)
    parts = break_url(url)
    if parts.is_raw:
        return os.path.abspath(url)
    if parts.scheme == "file" and parts.host in (None, "", "localhost"):
        return os.path.abspath(parts.path or "/")
    return None


class _BaseUrls(threading.local):
    def __init__(self) -> None:
        self.stack: list[str] = []


_base_urls = _BaseUrls()


def push_base_url(base_url: str) -> None:
    """Put ``base_url`` on this thread's base-URL stack (:func:`combine_with_base_url` resolves against it)."""
    _base_urls.stack.append(os.fspath(base_url))


def pop_base_url(base_url: str | None = None) -> bool:
    """Take the top URL off this thread's stack; False (nothing popped) when ``base_url`` is given and is not it."""
    stack = _base_urls.stack
    if not stack or (base_url is not None and stack[-1] != base_url):
        return False
    stack.pop()
    return True


def get_base_url() -> str | None:
    """The top of this thread's base-URL stack, or None."""
    return _base_urls.stack[-1] if _base_urls.stack else None


def combine_with_base_url(other_url: str) -> str:
    """``other_url`` resolved against this thread's top base URL (unchanged when the stack is empty)."""
    base = get_base_url()
    return combine_urls(base, other_url) if base else normalize_url(other_url)


__all__ = ["Url", "break_url", "break_url_reference", "combine_urls", "combine_with_base_url", "get_base_url",
           "local_file_path", "make_file_url", "make_relative_url", "make_url", "normalize_url", "pop_base_url",
           "push_base_url"]
