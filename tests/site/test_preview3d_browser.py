"""The procedure page's 3D panel (frontend/procedure/preview3d.js) in Debian's Chromium through Playwright, offline
(every request to another site is refused and counted): three.js and the glTF are fetched only once the panel opens,
every element of the procedure is a loaded node, a frame is drawn with the facade lit, pointing at an element names
it and its node in the tree, a click keeps it, the photo toggle loads the photo's glTF; without WebGL, or without
three.js on the server, the panel says so. WebGL runs on the CPU (SwiftShader, `--enable-unsafe-swiftshader`). With
FACAID_SCREENSHOT_DIR set, the picture of docs/img/procedure-3d.png is written there. (The page's import map, in
`test_pages.py`.)"""

from __future__ import annotations

import re
import shutil

import numpy as np
import pytest
from django.contrib.staticfiles import finders
from PIL import Image
from site_helpers import CHROMIUM, CHROMIUM_ARGS, login, offline_page, screenshot

from facaid.formats.relief import procedure_relief
from facaid.generator import generate
from facaid.grammar import Procedure as Tree
from facaid.labels import LABELS
from webapp.facades.models import Procedure, Segmentation

VENDORED = pytest.mark.skipif(finders.find("vendor/three/build/three.module.js") is None,
                              reason="three.js is not vendored: scripts/setup does it with npm (scripts/vendor-js)")
pytestmark = [pytest.mark.django_db(transaction=True), VENDORED,
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]
READY = "window.facaidPreview3d && window.facaidPreview3d.ready"
BACKGROUND = (0xEE, 0xF1, 0xF4)  # the scene's background (frontend/procedure/preview3d.js)


@pytest.fixture
def chromium(monkeypatch):
    """Launches Debian's Chromium with the site tests' flags and more; closes them all at the end."""
    from playwright.sync_api import sync_playwright

    monkeypatch.setenv("DJANGO_ALLOW_ASYNC_UNSAFE", "true")  # Playwright's sync API keeps an event loop here
    with sync_playwright() as p:
        launched = []

        def launch(*flags: str):
            launched.append(p.chromium.launch(executable_path=CHROMIUM, args=[*CHROMIUM_ARGS, *flags]))
            return launched[-1]

        yield launch
        for b in launched:
            b.close()


def _elements(data: dict) -> int:
    """The procedure's elements, as every export holds them, and its pieces of wall (one glTF node each)."""
    return len(procedure_relief(Tree.from_dict(data), 0.02).rows)


def _node(tree: Tree, path: str):
    node = tree.root
    for index in path.split("/")[1:]:
        node = node.children[int(index)]
    return node


def _requested(page) -> list[str]:
    urls = []
    page.on("request", lambda r: urls.append(r.url))
    return urls


def test_the_3d_panel_loads_the_procedure_lit_and_names_its_elements(live_server, alice, facade_photo, chromium,
                                                                     tmp_path):
    _, seg = facade_photo  # the photo is generate(3)'s label map: the procedure's own picture
    data = generate(3).procedure.to_dict()
    segmentation = Segmentation.objects.get(photo__code=seg["photo"], version=seg["version"])
    proc = Procedure.objects.create(owner=alice, data=data, segmentation=segmentation, photo=segmentation.photo)
    page = offline_page(chromium("--enable-unsafe-swiftshader"), live_server.url, viewport=(1280, 1000))
    requested = _requested(page)
    login(page, live_server.url, "alice", "alice-password-1")
    page.goto(f"{live_server.url}/procedures/{proc.code}")
    page.wait_for_selector("#tree input", state="attached")  # in the closed "Advanced" panel
    # nothing of the preview is fetched until the panel opens
    assert not any("/vendor/three/" in u or u.endswith(".glb") for u in requested)
    assert page.evaluate("window.facaidPreview3d.frames") == 0
    page.click("#preview3d summary")
    page.wait_for_function(READY, timeout=90_000)
    state = page.evaluate("window.facaidPreview3d")
    assert state["error"] is None and state["variant"] == "plain" and state["frames"] >= 1
    assert state["elements"] == _elements(data) > 100
    assert any(u.endswith("/download/facade.glb") for u in requested)
    assert any(u.endswith("/static/vendor/three/build/three.module.js") for u in requested)
    assert page.elsewhere == [] and page.errors == []

    # the facade fills the view's height, lit: many shades (light and shadow on the relief), neither black nor white
    page.evaluate("scrollTo(0, document.getElementById('preview3d').offsetTop - 8)")
    path = screenshot(page.locator("#preview3d"), "procedure-3d.png", tmp_path)
    view = page.locator(".preview3d-view").bounding_box()
    panel = page.locator("#preview3d").bounding_box()
    box = (int(view["x"] - panel["x"]) + 2, int(view["y"] - panel["y"]) + 2,
           int(view["x"] - panel["x"] + view["width"]) - 2, int(view["y"] - panel["y"] + view["height"]) - 2)
    pixels = np.asarray(Image.open(path).convert("RGB").crop(box)).astype(int)
    drawn = np.abs(pixels - BACKGROUND).max(axis=2) > 2
    rows = np.flatnonzero(drawn.any(axis=1))
    assert (rows[-1] - rows[0]) / len(drawn) > 0.8 and 0.2 < drawn.mean() < 0.9, (rows[[0, -1]], drawn.mean())
    facade = pixels[drawn]
    assert len(np.unique(facade // 4, axis=0)) > 200  # shaded, not flat colours
    assert 60 < facade.mean() < 230  # lit: neither black nor washed out

    # pointing at the middle names an element and its node; a click keeps it
    view = page.locator("#preview3d-canvas").bounding_box()
    page.mouse.move(view["x"] + view["width"] / 2, view["y"] + view["height"] / 2)
    page.wait_for_selector("#preview3d-tip:not([hidden])")
    tip = page.text_content("#preview3d-tip")
    label, node_path = re.match(r"^(\w+) · (root(?:/\d+)*) · x \d+–\d+, y \d+–\d+ px$", tip).groups()
    assert label in LABELS and label != "background"
    node = _node(Tree.from_dict(data), node_path)
    assert node.is_leaf and node.label == label
    page.mouse.down()
    page.mouse.up()
    assert page.evaluate("window.facaidPreview3d.selected.path") == node_path
    assert page.text_content("#preview3d-info") == f"Selected: {tip}"
    # the page selects the same node: in the tree, and outlined in the picture
    assert page.get_attribute("#tree li.selected", "data-path") == node_path
    assert int(page.get_attribute("#selection", "data-outlined")) >= 1
    # the tree opened above it, and the page stayed: the view is still under the pointer
    assert abs(page.locator("#preview3d-canvas").bounding_box()["y"] - view["y"]) <= 1

    # a drag orbits (a frame drawn), fit to view draws again
    frames = page.evaluate("window.facaidPreview3d.frames")
    page.mouse.move(view["x"] + view["width"] / 2, view["y"] + view["height"] / 2)
    page.mouse.down()
    page.mouse.move(view["x"] + view["width"] / 2 + 120, view["y"] + view["height"] / 2 + 30, steps=5)
    page.mouse.up()
    page.wait_for_function(f"window.facaidPreview3d.frames > {frames}")
    frames = page.evaluate("window.facaidPreview3d.frames")
    page.click("#preview3d-fit")
    page.wait_for_function(f"window.facaidPreview3d.frames > {frames}")

    # the photo on the fronts: the other glTF, the same elements
    page.check("#preview3d-photo")
    page.wait_for_function(f"{READY} && window.facaidPreview3d.variant === 'photo'", timeout=90_000)
    assert page.evaluate("window.facaidPreview3d.elements") == _elements(data)
    assert any(u.endswith("/download/facade-photo.glb") for u in requested)
    # closed and opened again: what is saved now, fetched again
    fetched = len([u for u in requested if u.endswith(".glb")])
    with page.expect_request("**/download/facade-photo.glb"):
        page.click("#preview3d summary")
        page.click("#preview3d summary")
    page.wait_for_function(f"{READY} && window.facaidPreview3d.variant === 'photo'", timeout=90_000)
    assert [u.rsplit("/", 1)[1] for u in requested if u.endswith(".glb")][fetched:] == ["facade-photo.glb"]
    assert page.elsewhere == [] and page.errors == []


def test_without_webgl_the_3d_panel_says_so(live_server, alice, chromium):
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public")
    page = offline_page(chromium("--disable-webgl", "--disable-3d-apis"), live_server.url)
    requested = _requested(page)
    page.goto(f"{live_server.url}/procedures/{proc.code}")  # anonymous: no photo to toggle
    assert page.locator("#preview3d-photo").count() == 0
    page.click("#preview3d summary")
    page.wait_for_function("window.facaidPreview3d.error !== null")
    assert page.evaluate("window.facaidPreview3d.error") == "no WebGL"
    assert "no WebGL 2" in page.text_content("#preview3d-status")
    assert page.locator(".preview3d-view").is_hidden() and page.locator("#preview3d-fit").is_disabled()
    assert not any("/vendor/three/" in u or u.endswith(".glb") for u in requested)
    assert page.elsewhere == [] and page.errors == []


def test_without_three_js_on_the_server_the_3d_panel_says_so(live_server, alice, chromium):
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public")
    page = offline_page(chromium("--enable-unsafe-swiftshader"), live_server.url)
    page.route("**/static/vendor/three/**", lambda r: r.fulfill(status=404))  # as if the set-up had no npm
    page.goto(f"{live_server.url}/procedures/{proc.code}")
    page.click("#preview3d summary")
    page.wait_for_function("window.facaidPreview3d.error !== null")
    assert page.evaluate("window.facaidPreview3d.error") == "three.js missing"
    assert "not installed on this server" in page.text_content("#preview3d-status")
    assert page.elsewhere == [] and page.errors == []
