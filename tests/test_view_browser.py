"""flipkit view's page in a real browser: headless Chromium (Debian's ``chromium``, driven by
Playwright) opens the ``--html`` file offline, loads it without console errors, offers the
play button and the time slider, and draws the arm where it stands at two slider times.

Skipped only where there is no Chromium binary (``make venv`` installs Debian's).
"""

import io
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from playwright.sync_api import sync_playwright

from flipkit.cli import main

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
SIZE = (800, 600)  # pixels, the page's viewport
# WebGL without a GPU: Chromium's software rasteriser (SwiftShader) through ANGLE
ARGS = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
MESHES = 8 + 3 + 3 + 2  # arm, spatula and burger, the cell's boxes, the landing's discs

pytestmark = pytest.mark.skipif(not Path(CHROMIUM).is_file(),
                                reason=f"no Chromium binary ({CHROMIUM}): apt-get install "
                                       "chromium (make venv does)")


def shot(page) -> np.ndarray:
    """The viewport as an (h, w, 3) int array, once the viewer has drawn the change."""
    page.evaluate("viewer.set_dirty()")
    page.wait_for_timeout(250)
    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB"), int)


def changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a - b).sum(axis=2) > 30


def seek(page, t: float) -> None:
    """Move the animation's time slider (Animations > default > time) to ``t`` (s)."""
    page.evaluate(f"viewer.animator.pause(); viewer.animator.time_scrubber.setValue({t})")


ARM_ON_SCREEN = """() => {
    const arm = viewer.scene_tree.find(["meshcat", "flipkit", "arm", "visuals"]);
    return Object.values(arm.children).map(node => {
        const p = viewer.camera.position.clone();
        node.object.getWorldPosition(p);
        p.project(viewer.camera);
        return [(p.x + 1) / 2 * window.innerWidth, (1 - p.y) / 2 * window.innerHeight];
    });
}"""


def test_the_page_shows_the_moving_arm_in_chromium(flip_plan, flip_plan_file, tmp_path):
    out = tmp_path / "view.html"
    assert main(["view", str(flip_plan_file), "--html", str(out)]) == 0
    flip = flip_plan.segment("flip")
    start = sum(s.T for s in flip_plan.segments[:3])
    mid_flight = start + flip.release["time"] + flip.landing["time_of_flight"] / 2
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        try:
            page = browser.new_page(viewport=dict(zip(("width", "height"), SIZE)))
            errors = []
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.on("request", lambda r: errors.append(f"fetched {r.url}")
                    if not r.url.startswith(("file:", "data:")) else None)
            page.goto(out.as_uri())
            page.wait_for_function("window.viewer && viewer.animator.duration > 0")
            page.wait_for_function("() => { let n = 0; viewer.scene.traverse(o => "
                                   f"n += o.isMesh ? 1 : 0); return n >= {MESHES}; }}")
            controls = page.evaluate("[...document.querySelectorAll('.dg .property-name')]"
                                     ".map(e => e.textContent)")
            assert {"play", "pause", "time"} <= set(controls)
            assert page.evaluate("viewer.animator.duration") >= start + flip.T - 1e-3

            seek(page, 0.0)
            home = shot(page)
            arm_home = page.evaluate(ARM_ON_SCREEN)
            seek(page, mid_flight)
            flight = shot(page)
            arm_flight = page.evaluate(ARM_ON_SCREEN)
            page.evaluate("viewer.scene_tree.find(['meshcat', 'flipkit', 'arm']).object"
                          ".visible = false")
            no_arm = shot(page)
        finally:
            browser.close()
    assert errors == []
    h, w = home.shape[:2]
    assert (w, h) == SIZE
    moved = changed(home, flight)
    assert moved.mean() > 0.005, "the two slider times look the same"
    arm = changed(flight, no_arm)  # the arm's own pixels at mid-flight
    assert arm.mean() > 0.02, "no arm on the page"
    # the arm's pixels are where its links project, and the links moved between the times
    hits = [arm[max(int(y) - 6, 0):int(y) + 6, max(int(x) - 6, 0):int(x) + 6].any()
            for x, y in arm_flight if 0 <= x < w and 0 <= y < h]
    assert sum(hits) >= 5, f"the arm is not drawn where its links are: {arm_flight}"
    assert np.abs(np.subtract(arm_home, arm_flight)).max() > 10  # pixels
    ys, xs = np.nonzero(arm)
    assert 0.1 * w < xs.mean() < 0.9 * w and 0.05 * h < ys.mean() < 0.9 * h
