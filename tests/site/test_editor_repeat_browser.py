"""Repeat to the edge in the editor, in Debian's Chromium (issue 68, item 3): on a photo made here whose bays are not
evenly spaced, the copies go where the photo shows a window, not on the bare wall the pitch would put them on, and
they stop where the photo shows none."""

from __future__ import annotations

import io
import shutil

import pytest
from editor_helpers import E, open_page, rects, screen
from photo_helpers import lattice_photo
from site_helpers import screenshot, upload

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]

XS = (40, 150, 260, 395, 505, 615)  # a pitch of 110 px, then 135, then 110: as a facade's bays often are
ROW = [(x, 40, x + 60, 120) for x in XS]
BARE = [(x, 300, x + 60, 380) for x in XS[:3]]  # a second row that stops half way: bare wall beyond


def test_repeat_to_the_edge_follows_the_photo(live_server, as_alice, browser, tmp_path):
    out = io.BytesIO()
    lattice_photo(grid=ROW + BARE, closed=set()).save(out, "PNG")
    photo = upload(as_alice, out.getvalue(), title="Uneven bays").json()
    seg = {"width": 700, "height": 520, "rects": [{"label": "facade", "x0": 0, "y0": 0, "x1": 700, "y1": 520}] + [
        {"label": "window", **dict(zip(("x0", "y0", "x1", "y1"), box, strict=True))}
        for box in (ROW[0], ROW[1], BARE[0], BARE[1])]}
    assert as_alice.post(f"/api/v1/photos/{photo['code']}/segmentations/", seg, format="json").status_code == 201
    page, context = open_page(live_server, browser, photo["code"], f"{E}?.seg?.size === 5", (1400, 1000))
    page.keyboard.press("v")

    def repeat(a, b) -> str:
        page.mouse.click(*screen(page, a[0] + 10, a[1] + 10))
        page.keyboard.down("Shift")
        page.mouse.click(*screen(page, b[0] + 10, b[1] + 10))
        page.keyboard.up("Shift")
        page.click("#repeat-edge")
        return page.text_content("#status")

    said = repeat(ROW[0], ROW[1])
    windows = sorted((r["x0"], r["y0"]) for r in rects(page) if r["label"] == "window" and r["y0"] < 200)
    assert [x for x, _ in windows] == list(XS), windows  # on the photo's windows: not 260, 370, 480, 590
    assert all(abs(y - 40) <= 2 for _, y in windows)
    assert "where the photo shows one" in said
    said = repeat(BARE[0], BARE[1])  # the second row: one more window, then bare wall
    low = sorted(r["x0"] for r in rects(page) if r["label"] == "window" and r["y0"] > 200)
    assert low == list(XS[:3]), low
    assert "up to where it shows none" in said
    screenshot(page.locator("#canvas"), "repeat-to-the-edge.png", tmp_path)
    assert page.errors == []
    context.close()
