"""BasicWriter's layout table: the files each stem writes, and the dataset reader grouping them by the same table."""
from __future__ import annotations

import doctest

from graphsdg.dataset.basic_writer import BasicWriterDataset
from graphsdg.io import basic_writer_layout as layout

STEMS = sorted({stem for _, stem in layout.FLAGS.values()})


def _names(stem: str, frame: str = "0003") -> list[str]:
    return [f"{stem}{f.suffix}_{frame}.{'png' if f.ext == layout.IMAGE else f.ext}"
            for f in layout.files_of(stem, {"colorize_depth"})]


def test_files_of_stems_prefixes_and_options():
    assert [(f.suffix, f.ext) for f in layout.files_of("bounding_box_3d")] == \
        [("", "npy"), ("_labels", "json"), ("_prim_paths", "json")]
    assert [(f.suffix, f.ext) for f in layout.files_of("distance_to_camera")] == [("", "npy")]
    assert [(f.suffix, f.ext) for f in layout.files_of("distance_to_camera", {"colorize_depth"})] == \
        [("", "npy"), ("", "png")]
    assert [(f.suffix, f.ext) for f in layout.files_of("some_custom_annotator")] == [("", "npy")]
    assert layout.json_companions("instance_segmentation") == ("_mapping", "_semantics_mapping")


def test_contents_come_from_the_payload():
    payload = {"data": [1], "idToLabels": {"1": "a"}, "idToSemantics": {"1": "b"}, "primPaths": ("/A",),
               "pointRgb": list(range(8)), "pointNormals": list(range(8)), "pointSemantic": [3],
               "pointInstance": [4]}
    boxes = {f.suffix: f.content(payload) for f in layout.files_of("bounding_box_2d_tight")}
    assert boxes == {"": [1], "_labels": {"1": "a"}, "_prim_paths": ["/A"]}
    cloud = {f.suffix: f.content(payload) for f in layout.files_of("pointcloud")}
    assert cloud["_rgb"].shape == (2, 4) and cloud["_instance"] == [4]
    assert layout.files_of("camera_params")[0].content(payload) is payload


def test_the_reader_groups_every_stem_by_the_writers_table(tmp_path):
    written = [name for stem in STEMS for name in _names(stem)]
    assert len(set(written)) == len(written)
    for name in written:
        (tmp_path / name).write_bytes(b"")
    ds = BasicWriterDataset(str(tmp_path))
    frame = ds.frame(("", "0003"))
    for stem in STEMS:
        mains = [n for n, f in zip(_names(stem), layout.files_of(stem, {"colorize_depth"})) if not f.suffix]
        assert frame.files[stem] in mains                         # a main file (.npy or .png), under its stem
        for suffix in layout.json_companions(stem):               # JSON companions are read with it, not as stems
            assert f"{stem}{suffix}" not in frame.files
    assert set(frame.expected_files()) <= set(written)
    assert {n for n in written if n.endswith(".json")} <= set(frame.expected_files())


def test_module_example_runs():
    assert doctest.testmod(layout).failed == 0
