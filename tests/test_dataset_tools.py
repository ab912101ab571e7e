"""graphsdg validate / view on a small dataset, and on deliberately broken copies of it."""
from __future__ import annotations

import os
import shutil

import numpy as np
import pytest
from PIL import Image

from graphsdg.jobs.cli import main, run_demo
from graphsdg.dataset.validate import validate
from graphsdg.dataset.view import write_view


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("ds") / "demo")
    run_demo(out, frames=3, resolution=(96, 96), seed=3)
    return out


def test_clean_dataset_validates(dataset, capsys):
    assert validate(dataset) == []
    assert main(["validate", dataset]) == 0
    assert "0 violation(s)" in capsys.readouterr().out


def test_validate_reports_each_problem(dataset, tmp_path):
    broken = str(tmp_path / "broken")
    shutil.copytree(dataset, broken)
    os.remove(os.path.join(broken, "semantic_segmentation_labels_0001.json"))
    boxes_path = os.path.join(broken, "bounding_box_2d_tight_0002.npy")
    rows = np.load(boxes_path)
    rows[0]["x_max"] = 500                                  # outside the 96 px image
    np.save(boxes_path, rows)
    shutil.copy(os.path.join(broken, "rgb_0000.png"), os.path.join(broken, "rgb_0001.png"))
    open(os.path.join(broken, ".rgb_0003.png.abc.tmp"), "wb").write(b"x")
    text = "\n".join(str(v) for v in validate(broken))
    assert "semantic_segmentation_labels_0001.json" in text
    assert "leaves the 96x96 image" in text
    assert "rgb identical to frame 0000" in text
    assert "temporary or hidden file" in text
    assert main(["validate", broken]) == 1


def test_view_draws_boxes(dataset, tmp_path):
    result = write_view(dataset, str(tmp_path / "view"), html_gallery=True)
    sheet = np.array(Image.open(result["contact_sheet"]))
    assert sheet.shape[1] == 4 * 320
    assert os.path.exists(result["html"])
    assert sum(result["boxes per class"].values()) > 3
    raw = np.array(Image.open(os.path.join(dataset, "rgb_0000.png")).convert("RGB").resize((320, 320)))
    tile = sheet[:320, :320]
    assert (np.abs(tile.astype(int) - raw).sum(-1) > 60).mean() > 0.01    # drawn boxes and masks


def test_cli_error_is_one_line(capsys):
    assert main(["validate", "/no/such/dir"]) == 1
    err = capsys.readouterr().err
    assert "does not exist" in err and "Traceback" not in err
