"""How the pictures of docs/cli.md's viewer section were made (run from the repository root).

    python docs/images/viewer_pictures.py

``view_gallery.png``: ``graphsdg view --html`` of the demo (6 frames, 256x256) in headless Chromium at 1280 px
(tests/headless_chromium.py), the top of the page. ``view_rerun.png``: ``graphsdg view --rerun`` of a BasicWriter
dataset with camera parameters, shown by Rerun's viewer running headless (needs a Vulkan driver; Mesa's
lavapipe: apt-get install mesa-vulkan-drivers) and saved with its screenshot call. Both are written as
palette PNGs to stay small.
"""
from __future__ import annotations

import os
import sys
import tempfile
import time

from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def small_png(img: Image.Image, path: str, colours: int = 128) -> None:
    img.convert("RGB").quantize(colours, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(
        path, optimize=True)
    print(f"wrote {path} ({os.path.getsize(path) // 1024} KiB)")


def gallery_picture(work: str) -> None:
    sys.path.insert(0, os.path.join(ROOT, "tests"))
    from headless_chromium import HeadlessChromium

    from graphsdg.dataset.view import write_view
    from graphsdg.jobs.cli import run_demo
    os.chdir(work)
    run_demo("demo", frames=6, resolution=(256, 256), seed=3)
    result = write_view("demo", os.path.join(work, "demo.view"), html_gallery=True)
    with HeadlessChromium(1280, 1100) as browser:
        browser.goto("file://" + result["html"])
        browser.wait_for("Array.from(document.images).every(i => i.complete && i.naturalWidth > 0)")
        browser.evaluate("document.querySelector('.frame[data-name=\"0001\"] input[data-own=\"masks\"]').click()")
        shot = browser.screenshot()
    small_png(Image.fromarray(shot), os.path.join(HERE, "view_gallery.png"))


def rerun_picture(work: str) -> None:
    import graphsdg as rep
    from graphsdg.dataset.rerun_recording import record
    from rerun.experimental import ViewerClient
    sys.path.insert(0, os.path.join(ROOT, "tests"))
    from test_rerun_recording import write_scene_dataset
    rep.stage.new_stage()
    write_scene_dataset(os.path.join(work, "scene"), frames=3, resolution=(256, 192))
    rrd = os.path.join(work, "scene.rrd")
    record(os.path.join(work, "scene"), rrd)
    os.environ["PATH"] = os.path.dirname(sys.executable) + os.pathsep + os.environ["PATH"]
    viewer = ViewerClient.spawn(headless=True, port=9881, hide_welcome_screen=True)
    try:
        time.sleep(3)
        viewer.open(rrd)
        time.sleep(5)
        viewer.set_time("frame", sequence=1, play_state="paused")
        time.sleep(5)
        path = os.path.join(work, "rerun.png")
        viewer.save_screenshot(path)
    finally:
        viewer.quit()
    shot = Image.open(path)
    shot = shot.resize((1280, round(shot.height * 1280 / shot.width)), Image.Resampling.LANCZOS)
    small_png(shot, os.path.join(HERE, "view_rerun.png"), colours=160)


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as work:
        for make in (gallery_picture, rerun_picture):
            if len(sys.argv) < 2 or make.__name__.split("_")[0] in sys.argv[1:]:
                make(work)
