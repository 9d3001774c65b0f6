"""The whole path in Debian's Chromium, with a real Redis and a real worker: log in, upload a facade photo,
rectify it, draw rectangles with mouse and keys, use the repeat tool, undo and redo, submit, wait for the
result, download the PNG, the JSON, the CGA rules and the mesh and check them."""

from __future__ import annotations

import io
import json
import shutil
import zipfile

import pytest
from PIL import Image, ImageOps
from site_helpers import collect_errors, login

from facaid.formats.render import render_segmentation
from facaid.generator import generate

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None or shutil.which("redis-server") is None,
                                 reason="needs Debian's chromium and redis-server")]
E = "window.facaidEditor"
PAD = 40  # the facade sits inside a border that rectification crops away


@pytest.fixture
def page(browser):
    page = browser.new_page(viewport={"width": 1400, "height": 1000}, accept_downloads=True)
    page.errors = collect_errors(page, [])
    page.on("dialog", lambda d: d.accept())
    return page


def photo_file(tmp_path):
    sample = generate(3)
    image = ImageOps.expand(render_segmentation(sample.segmentation), PAD, fill=(90, 90, 90))
    path = tmp_path / "facade.jpg"
    image.save(path, quality=95)
    return path, sample.segmentation.width, sample.segmentation.height


def drag(page, start, end):
    page.mouse.move(*start)
    page.mouse.down()
    page.mouse.move(*end, steps=6)
    page.mouse.up()


def test_editor_from_upload_to_downloads(live_server, alice, worker, page, tmp_path):
    worker.start()
    base = live_server.url
    login(page, base, "alice", "alice-password-1")
    # upload
    path, fw, fh = photo_file(tmp_path)
    page.goto(f"{base}/photos/new")
    page.set_input_files("#id_image", str(path))
    page.fill("#id_title", "Street facade")
    page.click("button[type=submit]")
    page.wait_for_url(f"{base}/photos/*")
    page.click("text=Open the editor")
    page.wait_for_function(f"{E}?.seg !== null && {E}?.seg !== undefined")
    # rectify: drag the corners from the photo's corners onto the facade's
    page.click("#rectify")
    page.wait_for_function(f"{E}.rectifying")
    box = page.locator("#canvas").bounding_box()
    r = page.evaluate(f"({{s: {E}.rectifying.scale, ox: {E}.rectifying.ox, oy: {E}.rectifying.oy}})")

    def rect_at(x, y):
        return box["x"] + r["ox"] + x * r["s"], box["y"] + r["oy"] + y * r["s"]

    w, h = fw + 2 * PAD, fh + 2 * PAD
    for (x, y), (tx, ty) in zip([(0, 0), (w, 0), (w, h), (0, h)],
                                [(PAD, PAD), (PAD + fw, PAD), (PAD + fw, PAD + fh), (PAD, PAD + fh)], strict=True):
        drag(page, rect_at(x, y), rect_at(tx, ty))
    corners = page.evaluate(f"{E}.rectifying.corners")
    for got, want in zip(corners, [(PAD, PAD), (PAD + fw, PAD), (PAD + fw, PAD + fh), (PAD, PAD + fh)], strict=True):
        assert abs(got[0] - want[0]) <= 3 and abs(got[1] - want[1]) <= 3, corners
    page.click("#rectify-apply")
    page.wait_for_function(f"{E}?.seg && {E}.seg.width > 0 && !{E}.rectifying")
    sw, sh = page.evaluate(f"[{E}.seg.width, {E}.seg.height]")
    assert abs(sw - fw) <= 4 and abs(sh - fh) <= 4
    view = page.evaluate(f"({{s: {E}.view.scale, ox: {E}.view.ox, oy: {E}.view.oy}})")

    def at(x, y):
        return box["x"] + view["ox"] + x * view["s"], box["y"] + view["oy"] + y * view["s"]

    # draw: the wall with the mouse (key 2), a window (key 3), repeated along its row
    page.keyboard.press("2")
    drag(page, at(1, 1), at(sw - 1, sh - 1))
    page.keyboard.press("3")
    drag(page, at(0.1 * sw, 0.3 * sh), at(0.2 * sw, 0.4 * sh))
    assert page.evaluate(f"{E}.seg.size") == 2
    page.fill("#rep-cols", "4")
    page.fill("#rep-gapx", str(round(0.1 * sw)))
    page.click("#repeat")
    assert page.evaluate(f"{E}.seg.size") == 5
    page.keyboard.press("Control+z")
    assert page.evaluate(f"{E}.seg.size") == 2
    page.keyboard.press("Control+y")
    assert page.evaluate(f"{E}.seg.size") == 5
    labels = page.evaluate(f"{E}.seg.toJSON().rects.map(r => r.label)")
    assert labels == ["facade"] + ["window"] * 4
    # submit and wait for the worker's result
    page.click("#submit")
    page.wait_for_selector("#result:not([hidden])", timeout=240_000)
    assert page.text_content("#job-status") == "done"
    # the status says what the job made, not the last save's news (the smoke test of the seventh session)
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('Reconstructed: ')")
    assert "No facade is drawn" not in page.text_content("#status")  # it is: no hint to draw it
    page.click("#result-link")
    page.wait_for_url(f"{base}/procedures/*")
    # the procedure and its overlay on the photo at the same scale, side by side: the overlay is below the
    # parameters, beside the picture, which stays in view (issue 68)
    page.wait_for_function("['render', 'overlay'].every(id => document.getElementById(id).complete)")
    page.evaluate("window.scrollBy(0, document.getElementById('overlay-box').closest('.panel').getBoundingClientRect()"
                  ".top - parseFloat(getComputedStyle(document.getElementById('picture-panel')).top))")  # stuck there
    render, overlay = (page.locator(f"#{i}").bounding_box() for i in ("render", "overlay"))
    assert abs(render["width"] - overlay["width"]) <= 1 and abs(render["height"] - overlay["height"]) <= 1
    assert abs(render["y"] - overlay["y"]) <= 1  # side by side
    page.set_viewport_size({"width": 600, "height": 900})  # a phone: stacked, each as wide as the page allows
    render, overlay = (page.locator(f"#{i}").bounding_box() for i in ("render", "overlay"))
    assert overlay["y"] >= render["y"] + render["height"] and render["width"] > 450
    page.set_viewport_size({"width": 1400, "height": 1000})
    # downloads
    with page.expect_download() as d:
        page.click("text=labels.png")
    png = Image.open(io.BytesIO(d.value.path().read_bytes()))
    assert png.size == (sw, sh)
    with page.expect_download() as d:
        page.click("text=procedure.json")
    proc = json.loads(d.value.path().read_text())
    assert proc["grammar"] == "facaid-split-1" and (round(proc["width"]), round(proc["height"])) == (sw, sh)
    assert (214, 200, 178) in {c for _, c in png.getcolors(1 << 16)}  # the wall came back
    with page.expect_download() as d:
        page.click("a[href$='/procedure.cga']")
    rules = d.value.path().read_text()
    assert "@StartRule\nFacade -->" in rules and "Wall -->" in rules
    with page.expect_download() as d:
        page.click("a[href$='/mesh.zip']")
    with zipfile.ZipFile(d.value.path()) as z:
        assert sorted(z.namelist()) == ["facade.mtl", "facade.obj"] and "usemtl facade" in z.read("facade.obj").decode()
    page.screenshot(path=str(tmp_path / "procedure.png"))
    assert page.errors == []
