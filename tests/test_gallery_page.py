"""graphsdg view --html: the gallery page loaded in headless Chromium (Debian's package, driven over the DevTools
protocol), checked on what the browser draws: no horizontal overflow at 1280 px, every image decoded, and the
switches (boxes, masks, labels, per frame and for all, the class filter) changing exactly the pixels they own."""
from __future__ import annotations

import json
import os

import numpy as np
import pytest
from PIL import Image

from graphsdg.dataset.box_statistics import class_rows
from graphsdg.dataset.class_table import class_colour
from graphsdg.dataset.formats import read_dataset
from graphsdg.dataset.view import write_view
from graphsdg.jobs.cli import main, run_demo

from headless_chromium import HeadlessChromium

ALL_DECODED = ("Array.from(document.images).every(i => i.complete) && "
               "Array.from(document.querySelectorAll('.frame img.rgb')).length > 0")


@pytest.fixture(scope="module")
def browser():
    with HeadlessChromium(1280, 900) as b:
        yield b


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    root = tmp_path_factory.mktemp("gallery")
    out = str(root / "demo")
    run_demo(out, frames=4, resolution=(96, 96), seed=5)
    result = write_view(out, str(root / "view"), html_gallery=True)
    return out, result


def _open(browser, path: str, page: int = 1) -> None:
    browser.goto(f"file://{path}#page={page}")
    browser.wait_for(ALL_DECODED)


def _rect(browser, selector: str) -> dict:
    return browser.evaluate(f"(() => {{ const r = document.querySelector({json.dumps(selector)})"
                            f".getBoundingClientRect(); return {{x: r.x, y: r.y, w: r.width, h: r.height}}; }})()")


def _scroll_to(browser, selector: str) -> None:
    browser.evaluate(f"document.querySelector({json.dumps(selector)}).scrollIntoView({{block: 'center'}})")


def _click(browser, selector: str) -> None:
    browser.evaluate(f"document.querySelector({json.dumps(selector)}).click()")


def test_no_horizontal_overflow_and_every_image_decoded(browser, demo):
    _, result = demo
    _open(browser, result["html"])
    assert browser.evaluate("[document.documentElement.scrollWidth, document.documentElement.clientWidth]") == \
        [1280, 1280]
    frames = browser.evaluate("Array.from(document.querySelectorAll('.frame')).map(f => f.dataset.name)")
    assert frames == ["0000", "0001", "0002", "0003"]
    sizes = browser.evaluate("Array.from(document.querySelectorAll('.frame')).map(f => "
                             "['img.rgb', 'img.mask', '.depth img'].map(s => f.querySelector(s).naturalWidth))")
    assert sizes == [[96, 96, 96]] * 4                    # the image, its class mask and its depth, decoded
    shot = browser.screenshot(full_page=True)
    assert shot.shape[1] == 1280
    text = browser.evaluate("document.querySelector('#page-info').textContent")
    assert text == "page 1 of 1 (4 frames)"


def test_statistics_tables_hold_the_datasets_counts(browser, demo):
    root, result = demo
    _open(browser, result["html"])
    rows = browser.evaluate("Array.from(document.querySelectorAll('#per-class tbody tr')).map(tr => "
                            "Array.from(tr.cells).map(c => c.textContent))")
    counts: dict[str, list] = {}
    for i in range(4):
        rows_npy = np.load(os.path.join(root, f"bounding_box_2d_tight_{i:04d}.npy"))
        labels = json.load(open(os.path.join(root, f"bounding_box_2d_tight_labels_{i:04d}.json")))
        for r in rows_npy:
            counts.setdefault(labels[str(r["semanticId"])]["class"], []).append(i)
    assert [(r[0], int(r[1]), int(r[2])) for r in rows] == \
        [(k, len(v), len(set(v))) for k, v in sorted(counts.items())]
    widths = {r["class"]: r["width px"] for r in class_rows(read_dataset(root)[1])}
    assert all(r[3] == " / ".join(f"{v:g}" for v in widths[r[0]]) for r in rows)


def _pixel(shot: np.ndarray, x: float, y: float) -> np.ndarray:
    return shot[int(y), int(x)].astype(int)


def test_switches_change_what_is_drawn(browser, demo):
    _, result = demo
    _open(browser, result["html"])
    first = ".frame[data-name='0000']"
    _scroll_to(browser, first)
    boxes = browser.evaluate(f"Array.from(document.querySelectorAll(\"{first} .box\")).map(b => "
                             f"{{const r = b.getBoundingClientRect(); return [b.className, r.x, r.y, r.width, r.height,"
                             f" getComputedStyle(b).borderLeftColor]}})")
    assert len(boxes) >= 3
    shot = browser.screenshot()
    cls, x, y, w, h, _ = max(boxes, key=lambda b: b[3] * b[4])           # the largest box: the floor
    names = {c["id"]: c["name"] for c in browser.evaluate("window.GALLERY.classes")}
    name = names[int(cls.split()[1][1:])]
    edge = (x + 1, y + h / 2)                                              # on its 2 px left border
    assert np.abs(_pixel(shot, *edge) - class_colour(name)).max() <= 2

    _click(browser, "input[data-all='boxes']")                            # all boxes off
    off = browser.screenshot()
    assert browser.evaluate(f"getComputedStyle(document.querySelector(\"{first} .box\")).display") == "none"
    assert np.abs(_pixel(off, *edge) - class_colour(name)).max() > 2

    stack = _rect(browser, f"{first} .stack")
    inside = (stack["x"] + stack["w"] / 2, stack["y"] + stack["h"] * 0.93)   # the floor, near the bottom
    _click(browser, "input[data-all='labels']")
    _click(browser, "input[data-all='masks']")                            # masks off: the plain image
    plain = browser.screenshot()
    _click(browser, "input[data-all='masks']")                            # masks on: tinted at 50 %
    tinted = browser.screenshot()
    expected = 0.5 * _pixel(plain, *inside) + 0.5 * np.array(class_colour("floor"))
    assert np.abs(_pixel(tinted, *inside) - expected).max() <= 3

    _click(browser, ".chip[data-class] input")                            # the first class chip: "cone"
    chips = browser.evaluate("Array.from(document.querySelectorAll('.chip')).map(c => [c.textContent, "
                             "c.classList.contains('off')])")
    assert chips[0] == ["cone", True] and not any(off for _, off in chips[1:])
    floor_chip = [i for i, (text, _) in enumerate(chips) if text == "floor"][0]
    _click(browser, f".chip:nth-of-type({floor_chip + 1}) input")         # hide the floor class
    hidden = browser.screenshot()
    assert np.abs(_pixel(hidden, *inside) - _pixel(plain, *inside)).max() <= 2    # its mask is gone
    crop = (slice(int(stack["y"]), int(stack["y"] + stack["h"])), slice(int(stack["x"]), int(stack["x"] + stack["w"])))
    still = np.abs(hidden[crop].astype(int) - plain[crop].astype(int)).max(-1) > 8
    assert still.mean() > 0.02                                            # other classes' masks stay

    _click(browser, "input[data-all='boxes']")                            # boxes back on, except hidden classes
    shown = browser.evaluate(f"Array.from(document.querySelectorAll(\"{first} .box\")).map(b => "
                             f"[b.className, getComputedStyle(b).display])")
    floor_id = [k for k, v in names.items() if v == "floor"][0]
    cone_id = [k for k, v in names.items() if v == "cone"][0]
    for cls_name, display in shown:
        k = int(cls_name.split()[1][1:])
        assert (display == "none") == (k in (floor_id, cone_id))

    _click(browser, f"{first} input[data-own='boxes']")                   # frame 0's own switch
    assert browser.evaluate(f"Array.from(document.querySelectorAll(\"{first} .box\")).every(b => "
                            f"getComputedStyle(b).display === 'none')")
    second = ".frame[data-name='0001']"
    assert browser.evaluate(f"Array.from(document.querySelectorAll(\"{second} .box\")).some(b => "
                            f"getComputedStyle(b).display !== 'none')")
    _click(browser, "input[data-all='depth']")
    assert browser.evaluate(f"getComputedStyle(document.querySelector(\"{second} .depth\")).display") == "none"


# ---- thousands of frames, paged; long names ----------------------------------------------------------------
def write_coco(root, frames: int, size=(24, 16), class_names=("box", "ball"), file_name="f{:05d}.png") -> str:
    """A COCO dataset of small images, each with one rectangle per class (polygon segmentations)."""
    os.makedirs(root / "images", exist_ok=True)
    rng = np.random.default_rng(0)
    w, h = size
    images, anns = [], []
    for i in range(frames):
        img = np.full((h, w, 3), 40, np.uint8)
        name = "images/" + file_name.format(i)
        images.append({"id": i, "file_name": name, "width": w, "height": h})
        for k, cls in enumerate(class_names, start=1):
            if (i + k) % 3 == 0 and k > 1:          # not every class in every frame
                continue
            x0, y0 = int(rng.integers(0, w // 2)), int(rng.integers(0, h // 2))
            x1, y1 = x0 + w // 3, y0 + h // 3
            img[y0:y1, x0:x1] = (60 * k, 255 - 60 * k, 120)
            anns.append({"id": len(anns) + 1, "image_id": i, "category_id": k, "bbox": [x0, y0, x1 - x0, y1 - y0],
                         "area": (x1 - x0) * (y1 - y0), "iscrowd": 0,
                         "segmentation": [[x0, y0, x1, y0, x1, y1, x0, y1]]})
        Image.fromarray(img).save(root / name)
    doc = {"images": images, "annotations": anns,
           "categories": [{"id": k, "name": n} for k, n in enumerate(class_names, start=1)]}
    (root / "coco_annotations_t.json").write_text(json.dumps(doc))
    return str(root)


def test_two_thousand_frames_are_paged(browser, tmp_path):
    root = write_coco(tmp_path / "many", 2000)
    assert main(["view", root, "--html", "--out", str(tmp_path / "view"), "--page-size", "48"]) == 0
    html = str(tmp_path / "view" / "index.html")
    _open(browser, html)
    assert browser.evaluate("document.querySelector('#page-info').textContent") == "page 1 of 42 (2000 frames)"
    assert browser.evaluate("document.querySelectorAll('.frame').length") == 48
    _click(browser, "#next")
    browser.wait_for("location.hash === '#page=2'")
    assert browser.evaluate("document.querySelector('.frame').dataset.name") == "images/f00048"
    _open(browser, html, page=42)
    names = browser.evaluate("Array.from(document.querySelectorAll('.frame')).map(f => f.dataset.name)")
    assert names == [f"images/f{i:05d}" for i in range(41 * 48, 2000)]
    assert browser.evaluate("Array.from(document.querySelectorAll('.frame img.rgb')).every(i => i.naturalWidth "
                            "=== 24)")
    assert browser.evaluate("document.documentElement.scrollWidth") == 1280
    _click(browser, "#only-with")                                          # then hide "box": frames with "ball"
    browser.evaluate("Array.from(document.querySelectorAll('.chip')).find(c => c.textContent === 'box')"
                     ".querySelector('input').click()")
    with_ball = sum(1 for i in range(2000) if (i + 2) % 3 != 0)
    assert browser.evaluate("document.querySelector('#page-info').textContent") == \
        f"page 1 of {-(-with_ball // 48)} ({with_ball} frames)"


def test_long_names_do_not_widen_the_page(browser, tmp_path):
    long_class = "a-very-long-class-name-" * 8
    root = write_coco(tmp_path / "long", 3, size=(400, 300), class_names=(long_class, "x"),
                      file_name="an_unusually_long_frame_file_name_that_goes_on_and_on_{:05d}_" + "z" * 80 + ".png")
    result = write_view(root, str(tmp_path / "view"), html_gallery=True)
    for width in (1280, 800):
        browser.call("Emulation.setDeviceMetricsOverride", width=width, height=900, deviceScaleFactor=1, mobile=False)
        _open(browser, result["html"])
        assert browser.evaluate("[document.documentElement.scrollWidth, document.documentElement.clientWidth]") == \
            [width, width]
    browser.call("Emulation.setDeviceMetricsOverride", width=1280, height=900, deviceScaleFactor=1, mobile=False)
