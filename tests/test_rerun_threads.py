"""graphsdg view --rerun reads frames on a thread pool: the recording read back with Rerun's reader is the same
for any number of reader threads, and class and instance ids are those of reading the frames one by one (the
box classes sorted, then every other name numbered in the order the frames meet it)."""
from __future__ import annotations

import json
import os
import threading

import numpy as np
import pytest

from graphsdg.dataset.class_table import STAND_IN, ClassTable, DeferredIds
from graphsdg.dataset.rerun_recording import record
from graphsdg.jobs.demo_scene import DEMO_ANNOTATORS, run_demo

FRAMES = 10
NOTHING = ("BACKGROUND", "UNLABELLED")


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("threads") / "demo")
    run_demo(out, FRAMES, (64, 64), 3, {**DEMO_ANNOTATORS, "camera_params": True, "bounding_box_2d_loose": True,
                                         "instance_segmentation": True})
    return out


def read_back(path: str) -> dict:
    """{entity: {component: {frame: [values]}}} of the recording, without the wall-clock start time."""
    pytest.importorskip("rerun")
    from rerun.chunk import RrdReader
    out: dict = {}
    for chunk in RrdReader(path).stream().to_chunks():
        columns = chunk.to_record_batch().to_pydict()
        frames = columns.get("frame", [None] * chunk.num_rows)
        for name, values in columns.items():
            if name in ("frame", "rerun.controls.RowId", "RecordingInfo:start_time"):
                continue
            for frame, value in zip(frames, values):
                if value is not None:
                    out.setdefault(chunk.entity_path, {}).setdefault(name, {}).setdefault(frame, []).append(value)
    return out


@pytest.fixture(scope="module")
def recordings(dataset, tmp_path_factory):
    folder = tmp_path_factory.mktemp("rrd")
    out = {}
    for workers in (1, 3, 6):
        path = str(folder / f"w{workers}.rrd")
        record(dataset, path, workers=workers)
        out[workers] = read_back(path)
    return out


def context(rec: dict, entity: str) -> dict[int, str]:
    """The entity's annotation context as the viewer shows it: the last one logged (static)."""
    (entries,) = rec[entity]["AnnotationContext:context"][None][-1]
    return {e["class_id"]: e["class_description"]["info"]["label"] for e in entries}


def test_the_recording_is_the_same_for_any_number_of_reader_threads(recordings):
    one = recordings[1]
    assert "/world/cameras/camera/image/instance" in one and len(one["/world/cameras/camera/image/semantic"]
                                                                   ["SegmentationImage:buffer"]) == FRAMES
    for workers in (3, 6):
        assert recordings[workers] == one, f"{workers} reader threads log another recording than one"


def _json(dataset: str, name: str):
    return json.load(open(os.path.join(dataset, name)))


def test_ids_are_numbered_in_the_order_the_frames_meet_the_names(recordings, dataset):
    boxes, met_classes, met_instances = set(), [], []
    for i in range(FRAMES):
        for kind in ("tight", "loose"):
            boxes |= {v["class"] for v in _json(dataset, f"bounding_box_2d_{kind}_labels_{i:04d}.json").values()}
        for value in _json(dataset, f"semantic_segmentation_labels_{i:04d}.json").values():
            if value["class"] not in NOTHING and value["class"] not in met_classes:
                met_classes.append(value["class"])
        mapping = _json(dataset, f"instance_segmentation_mapping_{i:04d}.json")
        semantics = _json(dataset, f"instance_segmentation_semantics_mapping_{i:04d}.json")
        for key, path in mapping.items():
            name = f"{path} ({semantics[key]['class']})" if key in semantics else path
            if path not in NOTHING and name not in met_instances:
                met_instances.append(name)
    classes = sorted(boxes) + [c for c in met_classes if c not in boxes]
    assert len(classes) >= 5 and len(met_instances) >= 5
    for rec in recordings.values():
        assert context(rec, "/") == dict(enumerate(classes, 1))
        assert context(rec, "/world/cameras/camera/image/instance") == dict(enumerate(met_instances, 1))


def test_deferred_ids_number_new_names_in_frame_order_whatever_thread_reads_first():
    table = ClassTable(["cube"])
    first, second = DeferredIds(table), DeferredIds(table)
    # the second frame is read first, on another thread, and meets "ball" before the first frame meets "cone"
    reader = threading.Thread(target=lambda: [second(n) for n in ("ball", "cube", "cone")])
    reader.start()
    reader.join()
    assert [first(n) for n in ("cone", "cube")] == [STAND_IN, 1]
    a = first.settle((np.array([[STAND_IN, 1, 0]], np.uint32), {STAND_IN: "cone", 1: "cube"}))
    b = second.settle((np.array([[STAND_IN, 1, STAND_IN + 1]], np.uint32),
                       {STAND_IN: "ball", 1: "cube", STAND_IN + 1: "cone"}))
    assert table.names == ["cube", "cone", "ball"]           # cone met by the first frame: id 2
    assert a[0].tolist() == [[2, 1, 0]] and a[1] == {2: "cone", 1: "cube"} and a[0].dtype == np.uint8
    assert b[0].tolist() == [[3, 1, 2]] and b[1] == {3: "ball", 1: "cube", 2: "cone"} and b[0].dtype == np.uint8
    wide = DeferredIds(table)                                # 64-bit masks (grey id images) stay 64-bit
    assert [wide(n) for n in ("cylinder", "ball")] == [STAND_IN, 3]
    found = wide.settle((np.array([STAND_IN, 3], np.int64), {STAND_IN: "cylinder", 3: "ball"}))
    assert found[0].tolist() == [4, 3] and found[0].dtype == np.int64
    known = DeferredIds(table)                               # a frame of known names only: nothing to settle
    mask = (np.array([1, 2], np.uint8), {1: "cube", 2: "cone"})
    assert [known(n) for n in ("cube", "cone")] == [1, 2] and known.settle(mask) is mask
