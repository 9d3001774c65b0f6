"""The canvas editor in Debian's Chromium through Playwright: draw with mouse and keys, undo and redo, repeat,
delete, save a version, export JSON, the warning before leaving with unsaved changes."""

from __future__ import annotations

import json
import shutil

import pytest
from editor_helpers import E, import_file, open_page

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
    from facaid.formats import interchange
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
    import_file(page, path)
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('Imported')")
    assert page.text_content("#status") == "Imported 2 rectangles."
    assert page.evaluate(f"{E}.seg.toJSON()") == drawn.to_dict()
    page.keyboard.press("Control+z")  # one step in the history
    assert page.evaluate(f"{E}.seg.size") == n0
    assert page.get_attribute("a[href$='segmentation?format=coco']", "download") is not None
    assert errors == []


def test_an_annotation_of_the_photo_as_taken_is_carried_through_the_rectification_and_merged_when_asked(
        live_server, as_alice, browser, tmp_path):
    """Issue 58: an annotation of the original photo (COCO here) is not refused for its size: the editor carries its
    boxes through the rectification and says so; over drawn rectangles it asks to replace, add or cancel."""
    from editor_helpers import windows_photo
    from site_helpers import upload

    from facaid.formats import interchange
    from facaid.segmentation import Rect
    from facaid.segmentation import Segmentation as Drawn

    photo = upload(as_alice, windows_photo(), title="Six windows").json()
    corners = [[40, 30], [440, 30], [440, 330], [40, 330]]  # a facade box: the rectified image is 400 x 300
    r = as_alice.post(f"/api/v1/photos/{photo['code']}/rectify", {"corners": corners}, format="json")
    assert r.status_code == 200, r.content
    taken = Drawn(480, 360, (Rect(2, 60, 60, 120, 150), Rect(2, 200, 60, 260, 150), Rect(2, 0, 0, 30, 20)))
    path = tmp_path / "as-taken.coco.json"
    path.write_bytes(interchange.write(taken, "coco", image="rue-12.jpg"))
    page, _ = open_page(live_server, browser, photo["code"], f"{E}?.seg?.width === 400")
    import_file(page, path)
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('Imported')")
    message = page.text_content("#status")
    assert message.startswith("Imported 2 rectangles.") and "carried through the rectification" in message
    assert "1 outside the facade left out" in message
    boxes = sorted((r["x0"], r["y0"], r["x1"], r["y1"]) for r in page.evaluate(f"[...{E}.seg.rects.values()]"))
    assert boxes == [(20, 30, 80, 120), (160, 30, 220, 120)]
    # again, over what is drawn now: it asks; cancel changes nothing, add keeps both
    import_file(page, path, "cancel")
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('Not imported')")
    assert page.evaluate(f"{E}.seg.size") == 2
    import_file(page, path, "merge")
    page.wait_for_function(f"{E}.seg.size === 4")
    assert "added to the 2 drawn" in page.text_content("#status")
    page.keyboard.press("Control+z")  # one step
    assert page.evaluate(f"{E}.seg.size") == 2
    # a file of neither size is refused naming both
    path.write_text(json.dumps({"width": 300, "height": 200, "rects": []}))
    import_file(page, path)
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('Not imported')")
    assert "the photo is 400x300 (as taken, before rectifying, 480x360)" in page.text_content("#status")
    # the photo picked instead of its annotations is named as such (a newcomer read "binary file")
    picture = tmp_path / "rue-12.png"
    picture.write_bytes(windows_photo())
    import_file(page, picture)
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('Not imported')")
    assert page.text_content("#status").startswith("Not imported: this is a PNG image, not annotations")
    assert page.evaluate(f"{E}.seg.size") == 2
    assert page.errors == []
