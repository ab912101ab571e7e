"""omni.client over local files, the asset pack (omniverse:// URLs) and a Nucleus mirror: Omniverse's Result
codes, ListEntry flags, URL parts, the async and callback forms."""
from __future__ import annotations

import asyncio
import hashlib
import os

import pytest

from graphsdg.assets import builtin_pack_root
from graphsdg.assets.nucleus import NUCLEUS_MIRROR_ENV
from graphsdg.compat import isaac

GRID = "/Isaac/Environments/Grid/default_environment.usd"
GRID_URL = "omniverse://localhost/NVIDIA/Assets/Isaac/4.5" + GRID


@pytest.fixture
def client():
    isaac.install()
    import omni.client
    yield omni.client
    isaac.uninstall()


def test_write_read_stat_list(client, tmp_path):
    target = tmp_path / "deep" / "folder" / "data.bin"
    payload = bytes(range(256)) * 3
    assert client.write_file(str(target), payload) == client.Result.OK   # folders are made
    result, version, content = client.read_file(str(target))
    assert result == client.Result.OK and version == ""
    assert memoryview(content).tobytes() == payload == target.read_bytes()
    result, entry = client.stat("file:" + str(target))
    assert result == client.Result.OK
    assert entry.relative_path == "data.bin" and entry.size == len(payload)
    assert entry.flags & client.ItemFlags.READABLE_FILE and entry.flags & client.ItemFlags.WRITEABLE_FILE
    assert not entry.flags & client.ItemFlags.CAN_HAVE_CHILDREN
    assert entry.access == client.AccessFlags.READ | client.AccessFlags.WRITE
    assert abs(entry.modified_time.timestamp() - os.path.getmtime(target)) < 1e-3
    (tmp_path / "deep" / "b.txt").write_text("b")
    result, entries = client.list(str(tmp_path / "deep"))
    assert result == client.Result.OK
    assert [(e.relative_path, bool(e.flags & client.ItemFlags.CAN_HAVE_CHILDREN)) for e in entries] == [
        ("b.txt", False), ("folder", True)]
    assert client.list(str(target)) == (client.Result.OK, ())   # a file has no children
    result, info = client.write_file_ex(str(target), b"x")
    assert result == client.Result.OK and info.hash == hashlib.sha256(b"x").hexdigest()


def test_missing_items_and_folder_results(client, tmp_path):
    missing = str(tmp_path / "nope.usd")
    assert client.stat(missing) == (client.Result.ERROR_NOT_FOUND, None)
    assert client.read_file(missing)[0] == client.Result.ERROR_NOT_FOUND
    assert client.list(missing) == (client.Result.ERROR_NOT_FOUND, ())
    assert client.delete(missing) == client.Result.ERROR_NOT_FOUND
    assert client.read_file(str(tmp_path))[0] == client.Result.ERROR_WRONG_TYPE
    folder = str(tmp_path / "made" / "inner")
    assert client.create_folder(folder) == client.Result.OK and os.path.isdir(folder)
    assert client.create_folder(folder) == client.Result.ERROR_ALREADY_EXISTS
    (tmp_path / "made" / "inner" / "f").write_text("f")
    assert client.delete_single(str(tmp_path / "made")) == client.Result.ERROR_FOLDER_NOT_EMPTY
    assert client.delete(str(tmp_path / "made")) == client.Result.OK and not (tmp_path / "made").exists()


def test_copy_and_move_behaviours(client, tmp_path):
    src = tmp_path / "src"
    (src / "sub").mkdir(parents=True)
    (src / "a.txt").write_text("a")
    (src / "sub" / "b.txt").write_text("b")
    dst = str(tmp_path / "out" / "copy")
    assert client.copy(str(src), dst) == client.Result.OK
    assert sorted(os.path.relpath(os.path.join(r, f), dst) for r, _, fs in os.walk(dst) for f in fs) == [
        "a.txt", os.path.join("sub", "b.txt")]
    assert client.copy(str(src), dst) == client.Result.ERROR_ALREADY_EXISTS
    (src / "a.txt").write_text("A")
    assert client.copy(str(src), dst, client.CopyBehavior.OVERWRITE) == client.Result.OK
    assert open(os.path.join(dst, "a.txt")).read() == "A"
    assert client.copy(str(src), str(src / "sub" / "inside")) == client.Result.ERROR_SOURCE_IS_DEST
    assert client.copy_file(str(src), str(tmp_path / "x")) == client.Result.ERROR_WRONG_TYPE
    assert client.copy_folder(str(src / "a.txt"), str(tmp_path / "x")) == client.Result.ERROR_WRONG_TYPE
    assert client.copy("omniverse://localhost/NoServer/a.usd", str(tmp_path / "y")) == client.Result.ERROR_CONNECTION
    result, copied = client.move(str(src / "a.txt"), str(tmp_path / "moved.txt"))
    assert result == client.Result.OK and copied is False
    assert (tmp_path / "moved.txt").read_text() == "A" and not (src / "a.txt").exists()


def test_omniverse_urls_read_the_pack_and_the_pack_is_read_only(client, tmp_path):
    pack_file = os.path.normpath(builtin_pack_root() + GRID)
    result, entry = client.stat(GRID_URL)
    assert result == client.Result.OK and entry.size == os.path.getsize(pack_file)
    assert not entry.flags & client.ItemFlags.WRITEABLE_FILE and entry.access == client.AccessFlags.READ
    with open(pack_file, "rb") as f:
        assert memoryview(client.read_file(GRID_URL)[2]).tobytes() == f.read()
    assert client.get_local_file(GRID_URL) == (client.Result.OK, pack_file)
    names = [e.relative_path for e in client.list("omniverse://localhost/Isaac/Environments")[1]]
    assert names == sorted(os.listdir(builtin_pack_root() + "/Isaac/Environments"))
    assert client.write_file(pack_file, b"x") == client.Result.ERROR_ACCESS_DENIED
    assert client.delete(GRID_URL) == client.Result.ERROR_CONNECTION   # writes need a mirror
    assert client.copy(GRID_URL, str(tmp_path / "grid.usd")) == client.Result.OK
    assert (tmp_path / "grid.usd").read_bytes() == open(pack_file, "rb").read()
    # a packed path the pack lacks is missing; a path outside /Isaac and /NVIDIA has no server
    assert client.stat("omniverse://localhost/Isaac/NoSuch/thing.usd")[0] == client.Result.ERROR_NOT_FOUND
    assert client.stat("omniverse://localhost/Projects/thing.usd")[0] == client.Result.ERROR_CONNECTION
    assert client.stat("https://example.com/a.usd")[0] == client.Result.ERROR_NOT_SUPPORTED


def test_mirror_serves_and_takes_writes(client, tmp_path, monkeypatch):
    monkeypatch.setenv(NUCLEUS_MIRROR_ENV, str(tmp_path))
    url = "omniverse://my-server/Projects/run_01/notes.txt"
    assert client.write_file(url, "hello") == client.Result.OK
    assert (tmp_path / "Projects" / "run_01" / "notes.txt").read_text() == "hello"
    assert memoryview(client.read_file(url)[2]).tobytes() == b"hello"
    assert client.stat("omniverse://my-server/Projects/none.txt")[0] == client.Result.ERROR_NOT_FOUND
    assert client.delete("omniverse://my-server/Projects") == client.Result.OK
    assert not (tmp_path / "Projects").exists()
    assert client.stat(GRID_URL)[0] == client.Result.OK   # the pack still serves what the mirror lacks


def test_url_parts(client):
    url = client.break_url("omniverse://user@localhost:3009/NVIDIA/a%20b.usd?checkpoint=2#frag")
    assert (url.scheme, url.user, url.host, url.port, url.path, url.query, url.fragment, url.is_raw) == (
        "omniverse", "user", "localhost", "3009", "/NVIDIA/a b.usd", "checkpoint=2", "frag", False)
    raw = client.break_url("/tmp/some file.usd")
    assert raw.is_raw and raw.path == "/tmp/some file.usd" and raw.scheme is None and raw.host is None
    assert client.break_url("file:/tmp/x.usd").path == "/tmp/x.usd"
    assert client.make_url(scheme="omniverse", host="localhost", port=3009, path="/a b/c.usd") == \
        "omniverse://localhost:3009/a%20b/c.usd"
    assert client.make_url(path="/plain/path.usd") == "/plain/path.usd"
    assert client.normalize_url("OMNIVERSE://h/a/./b/../c.usd") == "omniverse://h/a/c.usd"
    assert client.normalize_url("/a\\b/../c") == "/a/c"
    assert client.combine_urls("omniverse://h/A/B/scene.usd", "../M/m.mdl") == "omniverse://h/A/M/m.mdl"
    assert client.combine_urls("omniverse://h/A/scene.usd", "/X/y.usd") == "omniverse://h/X/y.usd"
    assert client.combine_urls("/local/dir/a.usd", "b.usd") == "/local/dir/b.usd"
    assert client.combine_urls("omniverse://h/A/scene.usd", "file:/abs.usd") == "file:/abs.usd"
    assert client.make_relative_url("omniverse://h/A/B/s.usd", "omniverse://h/A/C/t.usd") == "../C/t.usd"
    client.push_base_url("omniverse://h/Root/")
    try:
        assert client.combine_with_base_url("version.txt") == "omniverse://h/Root/version.txt"
    finally:
        assert client.pop_base_url() is True
    assert client.get_base_url() is None


def test_async_and_callback_forms(client, tmp_path):
    path = str(tmp_path / "f.txt")

    async def run():
        assert await client.write_file_async(path, b"abc") == client.Result.OK
        result, _, content = await client.read_file_async(path)
        stat_result, entry = await client.stat_async(path)
        return result, bytes(content), stat_result, entry.size
    assert asyncio.run(run()) == (client.Result.OK, b"abc", client.Result.OK, 3)
    seen = []
    request = client.stat_with_callback(path, callback=lambda result, entry: seen.append((result, entry.size)))
    assert seen == [(client.Result.OK, 3)] and request.is_finished()
    client.delete_with_callback(path, callback=seen.append)
    assert seen[-1] == client.Result.OK and not os.path.exists(path)
    assert client.get_result_string(client.Result.ERROR_NOT_FOUND) == "ERROR_NOT_FOUND"


def test_live_features_fail_clearly(client):
    from graphsdg.compat.modules import CompatError
    with pytest.raises(CompatError, match="omni.client.live_process is not available.*Nucleus server"):
        client.live_process()


def test_docstring_examples():
    import doctest

    from graphsdg.compat import omni_client, omni_client_urls
    for module in (omni_client, omni_client_urls):
        result = doctest.testmod(module)
        assert result.failed == 0 and result.attempted > 0, module.__name__
