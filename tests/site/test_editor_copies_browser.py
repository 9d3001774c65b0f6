"""Find copies in the editor, in Debian's Chromium (issue 57): a window and its sill selected on a photo made here
(`photo_helpers.lattice_photo`: a lighting gradient, noise, two closed blinds), their copies proposed with their
scores, a row rejected and a column accepted with one click each."""

from __future__ import annotations

import io
import shutil

import pytest
from editor_helpers import E, open_page, rects, screen
from photo_helpers import CLOSED, GRID, lattice_photo, sill_of
from site_helpers import screenshot, upload

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


@pytest.fixture
def lattice_editor(live_server, as_alice, browser):
    out = io.BytesIO()
    lattice_photo().save(out, "PNG")
    photo = upload(as_alice, out.getvalue(), title="A lattice of windows").json()
    seg = {"width": 700, "height": 520, "rects": [
        {"label": "facade", "x0": 0, "y0": 0, "x1": 700, "y1": 520},
        {"label": "window", **dict(zip(("x0", "y0", "x1", "y1"), GRID[7], strict=True))},
        {"label": "sill", **dict(zip(("x0", "y0", "x1", "y1"), sill_of(GRID[7]), strict=True))}]}
    r = as_alice.post(f"/api/v1/photos/{photo['code']}/segmentations/", seg, format="json")
    assert r.status_code == 201, r.content
    page, context = open_page(live_server, browser, photo["code"], f"{E}?.seg?.size === 3", (1400, 1000))
    yield page
    assert page.errors == []
    context.close()


def proposals(page) -> list[dict]:
    return page.evaluate(f"{E}.ui.proposals")


def test_find_copies_proposes_the_unit_and_one_click_takes_a_row_or_a_column(lattice_editor, tmp_path):
    page = lattice_editor
    page.click("#accept")  # no proposals yet: nothing was rejected (issue 68)
    assert page.text_content("#status").startswith("Nothing to accept: there are no proposals")
    page.click("#copies")  # nothing selected: it says what to select
    assert "a unit is elements (a window and what belongs to it" in page.text_content("#status")
    page.keyboard.press("v")
    x0, y0, x1, y1 = GRID[7]
    page.mouse.click(*screen(page, x0 + 10, y0 + 10))
    page.keyboard.down("Shift")
    page.mouse.click(*screen(page, x0 + 30, y1 + 8))  # the sill under it
    page.keyboard.up("Shift")
    assert page.evaluate(f"{E}.ui.selection.size") == 2
    page.click("#copies")
    copies = len(GRID) - 1 - len(CLOSED)
    page.wait_for_function(f"{E}.ui.proposals.length === {2 * copies}")
    shown = proposals(page)
    assert {p["copy"] for p in shown} == set(range(copies)) and all(0.6 <= p["score"] <= 1 for p in shown)
    assert f"{copies} copies of the unit" in page.text_content("#status")
    screenshot(page.locator("#canvas"), "find-copies.png", tmp_path)
    # one click on a window rejects its copy: the window and its sill
    wx0, wy0, *_ = GRID[14]
    page.mouse.click(*screen(page, wx0 + 20, wy0 + 20))
    off = [p for p in proposals(page) if p.get("accepted") is False]
    assert len(off) == 2 and len({p["copy"] for p in off}) == 1 and {p["label"] for p in off} == {"window", "sill"}
    page.mouse.click(*screen(page, wx0 + 20, wy0 + 20))  # and a second click takes it back
    assert not any(p.get("accepted") is False for p in proposals(page))
    # the first row's chip, left of its first window: the whole row rejected
    fx0, fy0, _, fy1 = GRID[0]
    sx, sy = screen(page, fx0, (fy0 + fy1) / 2)
    page.mouse.click(sx - 4 - 9, sy)
    row = [p for p in proposals(page) if p["y0"] < 130]
    assert len(row) == 12 and all(p.get("accepted") is False for p in row)
    assert "Rejected a row of 12 proposals" in page.text_content("#status")
    assert page.evaluate(f"{E}.ui.selection.size") == 2  # the press on the chip selected nothing under it
    # Shift and the last column's chip, above its first window: the column's copies added, alone
    lx0, ly0, lx1, _ = GRID[5]
    before = len(rects(page))
    sx, sy = screen(page, (lx0 + lx1) / 2, ly0)
    page.keyboard.down("Shift")
    page.mouse.click(sx, sy - 4 - 9)
    page.keyboard.up("Shift")
    column = [r for r in rects(page) if r["x0"] >= lx0 - 10 and r["label"] in ("window", "sill")]
    assert len(rects(page)) == before + 6 and len(column) == 6  # rows 1-3: the first row's copy was rejected
    # Enter adds the rest; the rejected row is remembered and not proposed again
    page.keyboard.press("Enter")
    assert len(rects(page)) == 3 + 2 * copies - 12 + 0 and proposals(page) == []


def test_a_box_started_on_the_drawn_wall_takes_the_unit_not_the_wall(lattice_editor, tmp_path):
    """Issue 68, item 2: once a facade rectangle was drawn, a box that started inside it grabbed the facade (a move
    of the wall), and Find copies then said the unit was the wall. A box started on the wall takes what it touches
    but the wall; a click on the wall still selects it, and Find copies leaves the wall out of a unit."""
    page = lattice_editor
    page.keyboard.press("v")
    x0, y0, x1, y1 = GRID[7]
    sx0, sy0, sx1, sy1 = sill_of(GRID[7])
    start, end = screen(page, x0 - 12, y0 - 12), screen(page, x0 + 10, sy0 + 2)  # from the wall over both
    page.mouse.move(*start)
    page.mouse.down()
    page.mouse.move(*end, steps=5)
    page.mouse.up()
    chosen = page.evaluate(f"[...{E}.ui.selection].map((id) => {E}.seg.get(id).label).sort()")
    assert chosen == ["sill", "window"]
    assert [(r["x0"], r["y0"]) for r in rects(page) if r["label"] == "facade"] == [(0, 0)]  # the wall did not move
    screenshot(page.locator("#canvas"), "marquee-on-the-wall.png", tmp_path)
    page.click("#copies")
    page.wait_for_function(f"{E}.ui.proposals.length > 0")
    assert "copies of the unit" in page.text_content("#status")
    page.keyboard.press("Escape")
    page.mouse.click(*screen(page, 20, 20))  # a click on the wall selects it
    assert page.evaluate(f"[...{E}.ui.selection].map((id) => {E}.seg.get(id).label)") == ["facade"]
    page.click("#copies")  # the wall alone is no unit: it says what a unit is, and how to leave the wall out
    status = page.text_content("#status")
    assert "not the wall" in status and "locking the facade class" in status
