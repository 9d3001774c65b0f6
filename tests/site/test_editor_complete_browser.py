"""Complete in the editor, in Debian's Chromium (issue 68, item 1): where the drawn row and column give places that
the photo does not confirm (b0333's trial: a row of three windows and a column drawn, and "draw a few elements of
a row and a column"), they are shown dimmed with their scores for the person to take with a click, and the status
says what was tried."""

from __future__ import annotations

import io
import shutil

import pytest
from editor_helpers import E, open_page, rects, screen
from photo_helpers import GRID, lattice_photo
from site_helpers import screenshot, upload

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]

SHOWN = (0, 1, 2, 6, 12)  # the photo's windows: a row of three and a column of three; elsewhere bare wall


def test_places_the_photo_does_not_confirm_are_dimmed_and_one_click_takes_one(live_server, as_alice, browser,
                                                                              tmp_path):
    out = io.BytesIO()
    lattice_photo(grid=[GRID[i] for i in SHOWN], closed=set()).save(out, "PNG")
    photo = upload(as_alice, out.getvalue(), title="A row and a column").json()
    seg = {"width": 700, "height": 520, "rects": [{"label": "facade", "x0": 0, "y0": 0, "x1": 700, "y1": 520}] + [
        {"label": "window", **dict(zip(("x0", "y0", "x1", "y1"), GRID[i], strict=True))} for i in SHOWN]}
    assert as_alice.post(f"/api/v1/photos/{photo['code']}/segmentations/", seg, format="json").status_code == 201
    page, context = open_page(live_server, browser, photo["code"], f"{E}?.seg?.size === 6", (1400, 1000))
    page.click("#complete")
    page.wait_for_function(f"{E}.ui.proposals.length > 0")
    shown = page.evaluate(f"{E}.ui.proposals")
    dimmed = [p for p in shown if p.get("dimmed")]
    assert dimmed and all(p["accepted"] is False and p["score"] < 0.7 for p in dimmed)
    wall = {tuple(GRID[i]) for i in (7, 8, 13, 14)}  # crossings of the drawn row and column: bare wall here
    assert wall <= {(p["x0"], p["y0"], p["x1"], p["y1"]) for p in dimmed}
    status = page.text_content("#status")
    assert "the photo does not confirm, dimmed with their scores: click one to take it" in status
    screenshot(page.locator("#canvas"), "complete-dimmed.png", tmp_path)
    x0, y0, *_ = GRID[7]
    page.mouse.click(*screen(page, x0 + 20, y0 + 20))  # taken
    page.keyboard.press("Enter")
    windows = {(r["x0"], r["y0"]) for r in rects(page) if r["label"] == "window"}
    assert (x0, y0) in windows and len(windows) == len(SHOWN) + 1 + sum(not p.get("dimmed") for p in shown)
    assert page.errors == []
    context.close()
