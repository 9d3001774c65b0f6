"""The canvas editor in Debian's Chromium through Playwright: draw with mouse and keys, undo and redo, repeat,
delete, save a version, export JSON, the warning before leaving with unsaved changes."""

from __future__ import annotations

import json
import shutil

import pytest
from editor_helpers import E, open_page

from webapp.facades.models import Segmentation

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


def test_editor_draw_undo_repeat_save_export(live_server, facade_photo, browser, tmp_path):
    photo, seg = facade_photo
    page, _ = open_page(live_server, browser, photo["code"], f"{E}?.seg?.size > 0")
    errors = page.errors
    n0 = page.evaluate(f"{E}.seg.size")
    assert n0 == seg["rect_count"]
    view = page.evaluate(f"({{s: {E}.view.scale, ox: {E}.view.ox, oy: {E}.view.oy}})")
    box = page.locator("#canvas").bounding_box()

    def at(x, y):
        return box["x"] + view["ox"] + x * view["s"], box["y"] + view["oy"] + y * view["s"]

    # draw a door with the mouse after picking the class by its hotkey
    page.keyboard.press("4")
    page.mouse.move(*at(20, 40))
    page.mouse.down()
    page.mouse.move(*at(60, 100), steps=6)
    page.mouse.up()
    assert page.evaluate(f"{E}.seg.size") == n0 + 1
    door = page.evaluate(f"[...{E}.ui.selection].map(id => {E}.seg.get(id))")[0]
    assert door["label"] == "door" and abs(door["x1"] - door["x0"] - 40) <= 7 and abs(door["y1"] - door["y0"] - 60) <= 7
    # undo and redo with keys, then with the buttons
    page.keyboard.press("Control+z")
    assert page.evaluate(f"{E}.seg.size") == n0
    page.keyboard.press("Control+Shift+z")
    assert page.evaluate(f"{E}.seg.size") == n0 + 1
    page.click("#undo")
    page.click("#redo")
    assert page.evaluate(f"{E}.seg.size") == n0 + 1
    # select it again, nudge it with the arrow keys, relabel it with a key
    page.keyboard.press("v")
    page.evaluate(f"{E}.ui.selection = new Set([{door['id']}])")
    page.keyboard.press("Shift+ArrowRight")
    assert page.evaluate(f"{E}.seg.get({door['id']}).x0") == door["x0"] + 10
    page.keyboard.press("3")
    assert page.evaluate(f"{E}.seg.get({door['id']}).label") == "window"
    # the repeat tool: three columns
    page.fill("#rep-cols", "3")
    page.fill("#rep-rows", "1")
    page.fill("#rep-gapx", "5")
    page.click("#repeat")
    assert page.evaluate(f"{E}.seg.size") == n0 + 3
    page.keyboard.press("Delete")
    assert page.evaluate(f"{E}.seg.size") == n0 + 2
    assert page.text_content("#dirty") == "unsaved changes"
    # save: a new version on the server
    page.click("#save")
    page.wait_for_function("document.querySelector('#dirty').textContent === 'saved'")
    latest = Segmentation.objects.filter(photo__code=photo["code"]).order_by("-version").first()
    assert latest.version == 2 and latest.rect_count == n0 + 2
    # export: the JSON the editor holds
    with page.expect_download() as download:
        page.click("#export")
    path = tmp_path / "export.json"
    download.value.save_as(path)
    exported = json.loads(path.read_text())
    assert (exported["width"], exported["height"]) == (photo["width"], photo["height"])
    assert len(exported["rects"]) == n0 + 2
    # leaving with unsaved changes asks first
    page.keyboard.press("Control+z")
    dialogs = []
    page.on("dialog", lambda d: (dialogs.append(d.type), d.dismiss()))
    page.evaluate("location.reload()")
    page.wait_for_timeout(300)
    assert "beforeunload" in dialogs
    assert errors == []


def test_editor_imports_a_coco_file_of_several_images(live_server, facade_photo, browser, tmp_path):
    from facaid import interchange
    from facaid.segmentation import Segmentation as SegmentationData

    photo, _ = facade_photo
    w, h = photo["width"], photo["height"]
    drawn = SegmentationData.from_dict({"width": w, "height": h, "rects": [
        {"label": "facade", "x0": 0, "y0": 0, "x1": w, "y1": h},
        {"label": "window", "x0": 10, "y0": 12, "x1": 30, "y1": 40}]})
    doc = json.loads(interchange.write(drawn, "coco", image="rue-12.jpg"))
    doc["images"].append({"id": 2, "width": w + 5, "height": h, "file_name": "rue-14.jpg"})  # the photo's is picked
    doc["annotations"].append({"id": 9, "image_id": 2, "category_id": 4, "bbox": [1, 1, 5, 5], "area": 25})
    path = tmp_path / "facades.coco.json"
    path.write_text(json.dumps(doc))
    page, _ = open_page(live_server, browser, photo["code"], f"{E}?.seg?.size > 0")
    errors = page.errors
    n0 = page.evaluate(f"{E}.seg.size")
    page.set_input_files("#import", str(path))
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('Imported')")
    assert page.text_content("#status") == "Imported 2 rectangles."
    assert page.evaluate(f"{E}.seg.toJSON()") == drawn.to_dict()
    page.keyboard.press("Control+z")  # one step in the history
    assert page.evaluate(f"{E}.seg.size") == n0
    assert page.get_attribute("a[href$='segmentation?format=coco']", "download") is not None
    assert errors == []
