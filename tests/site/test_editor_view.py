"""What the editor shows, in Debian's Chromium: brightness and contrast change the photo shown, not the rectangles
nor the photo; the object list selects, and hides or locks a class, without changing what is saved."""

from __future__ import annotations

import shutil

import pytest
from editor_helpers import WINDOWS, E, drag, rects, screen, select_window, selected

from webapp.facades.models import Segmentation

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


def canvas_pixel(page, x: float, y: float) -> list[int]:
    """The canvas's RGB at image point (x, y), the pixel an outline along that edge is drawn on."""
    return page.evaluate(f"""(() => {{
      const v = {E}.view, c = document.querySelector('#canvas');
      return [...c.getContext('2d').getImageData(Math.round(v.ox + {x} * v.scale), Math.round(v.oy + {y} * v.scale),
        1, 1).data].slice(0, 3);
    }})()""")


def set_range(page, selector: str, value: float) -> None:
    page.eval_on_selector(selector, f"e => {{ e.value = {value}; e.dispatchEvent(new Event('input')); }}")


def test_brightness_and_contrast_change_the_photo_shown_not_the_rectangles_nor_the_photo(editor):
    page = editor
    requests = []
    page.on("request", lambda r: requests.append(r.url))
    set_range(page, "#fill", 0)  # the photo alone inside the rectangles, their outlines on top
    wall = (30, 30)  # inside the facade, away from the windows
    outline = (WINDOWS[0][0] + 30, WINDOWS[0][1])  # the window's top edge, drawn over the photo
    before, edge = canvas_pixel(page, *wall), canvas_pixel(page, *outline)
    assert page.is_disabled("#adjust-reset")
    set_range(page, "#brightness", 2)
    brighter = canvas_pixel(page, *wall)
    assert all(b >= min(255, 1.8 * a) for a, b in zip(before, brighter, strict=True)), (before, brighter)
    assert canvas_pixel(page, *outline) == edge  # the rectangles are drawn as before
    set_range(page, "#brightness", 1)
    set_range(page, "#contrast", 0.2)
    flat = canvas_pixel(page, *wall)
    assert max(abs(c - 128) for c in flat) < max(abs(c - 128) for c in before)  # pulled toward mid gray
    assert page.text_content("#adjust-value") == "100 %, 20 %" and not page.is_disabled("#adjust-reset")
    # nothing was sent, nothing to undo, nothing to save; Reset shows the photo as it is
    assert requests == [] and not page.evaluate(f"{E}.history.canUndo") and page.text_content("#dirty") == "saved"
    page.click("#adjust-reset")
    assert canvas_pixel(page, *wall) == before and page.is_disabled("#adjust-reset")
    assert page.input_value("#brightness") == "1" and page.input_value("#contrast") == "1"
    # find similar reads the photo, not the view: the same five windows with the photo shown darker
    set_range(page, "#brightness", 0.3)
    select_window(page, *WINDOWS[0])
    page.click("#similar")
    assert len(page.evaluate(f"{E}.ui.proposals")) == 5



def test_object_list_selects_and_hides_or_locks_a_class_without_changing_what_is_saved(editor):
    page = editor
    wx, wy = WINDOWS[0]
    summary = "#objects details[data-label={}] summary"
    assert page.text_content(summary.format("window") + " .name") == "window 1"
    assert page.text_content(summary.format("facade") + " .name") == "facade 1"
    set_range(page, "#fill", 0)
    outline = canvas_pixel(page, wx + 30, wy)  # the window's top edge, not selected
    # an entry selects its rectangle
    page.click(summary.format("window") + " .name")
    page.click("#objects details[data-label=window] ol button")
    assert [r["label"] for r in selected(page)] == ["window"]
    # locked: drawn, but its entry disabled (and greyed), dropped from the selection, a press goes to the wall
    page.click(summary.format("window") + " button.locked")
    assert page.evaluate(f"{E}.ui.selection.size") == 0 and "locked: window" in page.text_content("#count")
    entry = "#objects details[data-label=window] ol button"
    assert page.is_disabled(entry)
    assert page.eval_on_selector(entry, "b => getComputedStyle(b).cursor") == "not-allowed"
    assert canvas_pixel(page, wx + 30, wy) == outline
    page.keyboard.press("v")
    page.mouse.click(*screen(page, wx + 10, wy + 10))
    assert [r["label"] for r in selected(page)] == ["facade"]
    page.keyboard.press("Control+a")
    assert [r["label"] for r in selected(page)] == ["facade"]
    page.keyboard.press("Escape")
    # the wall locked too: a drag over the window draws a box, moving nothing
    page.click(summary.format("facade") + " button.locked")
    before = rects(page)
    drag(page, (wx + 10, wy + 10), (wx + 40, wy + 40))
    assert rects(page) == before and not page.evaluate(f"{E}.history.canUndo")
    # hidden: not drawn (the outline is gone), not hit; Delete after Ctrl+A removes nothing of it
    page.click(summary.format("window") + " button.locked")
    page.click(summary.format("window") + " button.hidden")
    assert "hidden: window; locked: facade" in page.text_content("#count")
    assert canvas_pixel(page, wx + 30, wy) != outline
    page.mouse.click(*screen(page, wx + 10, wy + 10))
    assert page.evaluate(f"{E}.ui.selection.size") == 0
    page.keyboard.press("Control+a")
    page.keyboard.press("Delete")
    assert len(rects(page)) == 2
    # none of it was an edit: nothing to undo, "saved", and a save stores both rectangles
    assert not page.evaluate(f"{E}.history.canUndo") and page.text_content("#dirty") == "saved"
    page.click("#save")
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('Saved')")
    latest = Segmentation.objects.filter(photo__code=page.photo["code"]).order_by("-version").first()
    assert latest.version == 2 and sorted(r["label"] for r in latest.data["rects"]) == ["facade", "window"]
    # shown again: drawn and picked as before
    page.click(summary.format("window") + " button.hidden")
    assert canvas_pixel(page, wx + 30, wy) == outline
    page.mouse.click(*screen(page, wx + 10, wy + 10))
    assert [r["label"] for r in selected(page)] == ["window"]
