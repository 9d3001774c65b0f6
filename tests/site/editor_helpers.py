"""Helpers of the editor's browser tests: a photo of six equal windows, the editor opened on it, and the
conversions between image and page coordinates."""

from __future__ import annotations

import io

import numpy as np
from PIL import Image
from site_helpers import collect_errors, login, upload

E = "window.facaidEditor"
WINDOWS = [(x, y) for y in (60, 210) for x in (60, 200, 340)]  # top-left corners of six equal windows
WIN_W, WIN_H = 60, 90


def windows_photo() -> bytes:
    """A 480x360 'photo': a noisy wall with six copies of one textured window."""
    rng = np.random.default_rng(4)
    img = rng.integers(150, 200, size=(360, 480, 3), dtype=np.uint8)
    win = np.zeros((WIN_H, WIN_W, 3), dtype=np.uint8)
    yy, xx = np.mgrid[0:WIN_H, 0:WIN_W]
    win[...] = (40 + 2 * xx + yy)[..., None].clip(0, 255).astype(np.uint8)  # glass: a gradient
    win[:5], win[-5:], win[:, :5], win[:, -5:] = 20, 20, 20, 20  # frame
    win[WIN_H // 2 - 2 : WIN_H // 2 + 2], win[:, WIN_W // 2 - 2 : WIN_W // 2 + 2] = 230, 230  # cross bars
    for x, y in WINDOWS:
        img[y : y + WIN_H, x : x + WIN_W] = win
    out = io.BytesIO()
    Image.fromarray(img).save(out, "PNG")
    return out.getvalue()


def open_editor(live_server, as_alice, browser, viewport=(1400, 1000)):
    """(page, context): the editor open on Alice's windows photo with one segmentation, the wall and the first
    window; the page's uncaught errors collect in `page.errors`."""
    photo = upload(as_alice, windows_photo(), title="Six windows").json()
    x, y = WINDOWS[0]
    seg = {"width": 480, "height": 360, "rects": [
        {"label": "facade", "x0": 0, "y0": 0, "x1": 480, "y1": 360},
        {"label": "window", "x0": x, "y0": y, "x1": x + WIN_W, "y1": y + WIN_H}]}
    r = as_alice.post(f"/api/v1/photos/{photo['code']}/segmentations/", seg, format="json")
    assert r.status_code == 201, r.content
    page, context = open_page(live_server, browser, photo["code"], f"{E}?.seg?.size === 2", viewport, has_touch=True)
    page.photo = photo
    return page, context


def open_page(live_server, browser, code: str, ready: str, viewport=(1400, 1000), has_touch=False, dialog=None):
    """(page, context): Alice logged in and the editor of her photo ``code`` open, once the JavaScript ``ready``
    holds; the page's uncaught errors and CSP refusals collect in `page.errors`; ``dialog`` answers the page's
    dialogs."""
    context = browser.new_context(viewport={"width": viewport[0], "height": viewport[1]}, has_touch=has_touch)
    page = context.new_page()
    page.errors = collect_errors(page, [])
    if dialog is not None:
        page.on("dialog", dialog)
    login(page, live_server.url, "alice", "alice-password-1")
    page.goto(f"{live_server.url}/photos/{code}/edit")
    page.wait_for_function(ready)
    return page, context


def view(page) -> dict:
    return page.evaluate(f"({{s: {E}.view.scale, ox: {E}.view.ox, oy: {E}.view.oy}})")


def screen(page, x: float, y: float) -> tuple[float, float]:
    """Page coordinates of image point (x, y) in the current view."""
    v = view(page)
    box = page.locator("#canvas").bounding_box()
    return box["x"] + v["ox"] + x * v["s"], box["y"] + v["oy"] + y * v["s"]


def rects(page) -> list[dict]:
    return page.evaluate(f"[...{E}.seg.rects.values()]")


def selected(page) -> list[dict]:
    return page.evaluate(f"[...{E}.ui.selection].map(id => {E}.seg.get(id))")


def select_window(page, x: int, y: int, shift: bool = False) -> None:
    """With the select tool, click inside the window whose top-left corner is image point (x, y); with ``shift``,
    add it to the selection."""
    page.keyboard.press("v")
    if shift:
        page.keyboard.down("Shift")
    page.mouse.click(*screen(page, x + 10, y + 10))
    if shift:
        page.keyboard.up("Shift")

def drag(page, start, end, steps=6) -> None:
    """Press at image point `start`, move to `end` and release."""
    page.mouse.move(*screen(page, *start))
    page.mouse.down()
    page.mouse.move(*screen(page, *end), steps=steps)
    page.mouse.up()


def import_file(page, path, choice: str = "replace") -> None:
    """Import ``path`` through the editor's Import button; where rectangles are drawn already the editor asks what
    to do with them, and ``choice`` answers ("replace", "merge" or "cancel")."""
    page.evaluate("document.querySelector('#status').textContent = ''")  # the answer to this import, not the last
    page.set_input_files("#import", str(path))
    page.wait_for_function("document.querySelector('#import-choice').open || "
                           "/^(Imported|Not imported)/.test(document.querySelector('#status').textContent)")
    if page.evaluate("document.querySelector('#import-choice').open"):
        page.click(f"#import-choice button[value={choice}]")
        # the answer comes once the rectangles are in: a test that then counts them counts the import's, not the
        # drawing's it replaces (seen under load: the editor's two rectangles counted as the import's two)
        page.wait_for_function("/^(Imported|Not imported)/.test(document.querySelector('#status').textContent)")
