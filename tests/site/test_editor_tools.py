"""The editor's panels and helpers in Debian's Chromium: the layout on a 1280x720 screen (saving and the job in
view), and the side panels' tools. (What the editor shows, the photo's brightness and contrast and the object
list's hidden and locked classes, is checked in `test_editor_view.py`.)"""

from __future__ import annotations

import json
import os
import shutil

import pytest
from editor_helpers import WINDOWS, E, drag, import_file, open_page, rects, screen, select_window, selected
from site_helpers import collect_errors, login

from webapp.facades.models import Segmentation

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


@pytest.fixture
def small_screen(live_server, facade_photo, browser):
    """The editor on a 1280x720 screen, open on a generated facade of some 300 rectangles (its label map as the
    photo)."""
    photo, seg = facade_photo
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    page = context.new_page()
    errors = collect_errors(page, [])
    login(page, live_server.url, "alice", "alice-password-1")
    page.goto(f"{live_server.url}/photos/{photo['code']}/edit")
    page.wait_for_function(f"{E}?.seg?.size === {seg['rect_count']}")
    yield page
    assert errors == []
    context.close()


def in_view(page, selector: str) -> bool:
    """Is the element wholly inside the window, the page not scrolled?"""
    b = page.locator(selector).bounding_box()
    return b is not None and b["x"] >= 0 and b["y"] >= 0 and b["x"] + b["width"] <= 1280 and b["y"] + b["height"] <= 720


def test_at_1280x720_the_canvas_saving_and_the_job_are_in_view(small_screen, tmp_path):
    page = small_screen
    hint = page.text_content("#status")
    # the job and its result as submitting shows them, with a message long enough to wrap: the rows above the
    # canvas grow, and the canvas shrinks to stay on the screen
    page.evaluate("""() => {
      document.querySelector('#job').hidden = false;
      document.querySelector('#job-status').textContent = 'running (decoding)';
      document.querySelector('#result').hidden = false;
      document.querySelector('#status').textContent = 'A long message '.repeat(12);
    }""")
    page.wait_for_function("document.querySelector('#canvas').getBoundingClientRect().bottom <= innerHeight")
    assert page.evaluate("scrollY") == 0
    for selector in ("#canvas", "#save", "#submit", "#k", "#job-progress", "#job-status", "#result-link"):
        assert in_view(page, selector), selector
    # the side panel scrolls on its own: no taller than the canvas
    panel, canvas = (page.locator(s).bounding_box() for s in (".tools", "#canvas"))
    assert panel["height"] <= canvas["height"] + 1
    assert page.eval_on_selector(".tools", "p => p.scrollHeight > p.clientHeight")
    # the picture for docs/img/editor-1280x720.png: a window selected from the object list, its numbers shown
    page.click("#objects details[data-label=window] summary .name")
    page.click("#objects details[data-label=window] ol button")
    assert page.input_value("#sel-x0") == str(selected(page)[0]["x0"]) and selected(page)[0]["label"] == "window"
    page.evaluate("hint => { document.querySelector('#job-status').textContent = 'done'; "
                  "document.querySelector('#job-progress').value = 1; "
                  "document.querySelector('#status').textContent = hint; }", hint)
    assert all(in_view(page, s) for s in ("#canvas", "#save", "#submit", "#job-progress", "#result-link"))
    path = os.environ.get("FACAID_EDITOR_SCREENSHOT") or str(tmp_path / "editor-1280x720.png")
    page.screenshot(path=path)
    assert page.evaluate(f"{E}.history.canUndo") is False


def test_enter_in_the_threshold_field_searches_again_and_enter_elsewhere_accepts(editor):
    page = editor
    select_window(page, *WINDOWS[0])
    page.click("#similar")
    assert len(page.evaluate(f"{E}.ui.proposals")) == 5
    assert "at threshold 0.8" in page.text_content("#status")
    # the click left the focus off the button: Enter does not press "Find similar" again
    assert page.evaluate("document.activeElement.id") != "similar"
    page.mouse.click(*screen(page, WINDOWS[1][0] + 20, WINDOWS[1][1] + 20))  # reject one
    assert page.evaluate(f"{E}.ui.proposals.filter(p => p.accepted === false).length") == 1
    # a new threshold and Enter in its field: a new search (nothing added, the rejection gone), focus kept there
    page.fill("#sim-threshold", "0.9")
    page.press("#sim-threshold", "Enter")
    assert "at threshold 0.9" in page.text_content("#status")
    assert page.evaluate(f"{E}.ui.proposals.filter(p => p.accepted === false).length") == 0
    assert len(rects(page)) == 2 and page.evaluate("document.activeElement.id") == "sim-threshold"
    # out of range: refused with the range, the proposals kept
    page.fill("#sim-threshold", "5")
    page.press("#sim-threshold", "Enter")
    assert page.text_content("#status") == "The threshold must be a number from 0.3 to 1."
    assert len(page.evaluate(f"{E}.ui.proposals")) == 5
    # back on the canvas, Enter accepts the proposals: one step of five windows
    page.focus("#canvas")
    page.keyboard.press("Enter")
    assert len([r for r in rects(page) if r["label"] == "window"]) == 6


def test_repeat_with_several_selected_says_so_and_each_press_leaves_its_own_message(editor):
    page = editor
    select_window(page, *WINDOWS[0])
    page.fill("#rep-cols", "3")
    page.fill("#rep-gapx", "80")
    page.click("#repeat")
    assert page.text_content("#status") == "Added 2 window copies (3 × 1)."
    assert len(rects(page)) == 4
    # two selected: refused, the message about this press (not the last success), nothing added
    page.keyboard.press("Escape")
    select_window(page, *WINDOWS[0])
    select_window(page, WINDOWS[1][0], WINDOWS[1][1], shift=True)
    assert page.evaluate(f"{E}.ui.selection.size") == 2
    page.click("#repeat")
    assert page.text_content("#status") == ('Repeat copies one rectangle, and 2 are selected: select one of them, or '
                                            '"Repeat to the edge" to repeat the two at their pitch.')
    assert "error" in page.get_attribute("#status", "class")
    assert len(rects(page)) == 4
    page.keyboard.press("Escape")
    page.click("#repeat")
    assert page.text_content("#status") == "Repeat copies the selected rectangle: select one first."


def test_the_shortcuts_help_lists_the_key_table_opens_on_question_mark_and_closes_on_escape(editor):
    page = editor
    select_window(page, *WINDOWS[0])
    assert page.is_hidden("#help")
    page.keyboard.press("?")
    assert page.is_visible("#help")
    # the rows are keys.js's table, as the page loaded it
    table = page.evaluate("import('/static/app/editor/keys.js').then(k => k.shortcutRows())")
    shown = page.eval_on_selector_all("#help-body section:first-child tr", "rows => rows.map(r => "
                                      "({keys: r.cells[0].textContent, does: r.cells[1].textContent}))")
    assert shown == table and len(shown) >= 15
    assert {"keys": "Ctrl+Shift+Z / Ctrl+Y", "does": "redo"} in shown
    assert page.locator("#help-body").get_by_text("no snapping").is_visible()
    # while it is open the keys do not reach the editor; Escape closes it and leaves the selection alone
    page.keyboard.press("r")
    assert page.evaluate(f"{E}.ui.tool") == "select"
    page.keyboard.press("Escape")
    assert page.is_hidden("#help") and page.evaluate(f"{E}.ui.selection.size") == 1
    # the button opens it, its Close button and a click beside the dialog close it
    page.click("#help-open")
    assert page.is_visible("#help")
    page.click("#help-close")
    assert page.is_hidden("#help")
    page.click("#help-open")
    page.mouse.click(5, 700)
    assert page.is_hidden("#help")
    page.keyboard.press("Escape")  # closed, Escape clears the selection as before
    assert page.evaluate(f"{E}.ui.selection.size") == 0


def guide_seen(page, x: float) -> bool:
    """Is a snap guide (magenta) drawn down the canvas at image x, in its top rows?"""
    return page.evaluate(f"""(() => {{
      const v = {E}.view, c = document.querySelector('#canvas'), sx = Math.floor(v.ox + {x} * v.scale);
      const d = c.getContext('2d').getImageData(sx - 1, 3, 3, 1).data;
      return [0, 4, 8].some((i) => d[i] > 200 && d[i + 1] < 140 && d[i + 2] > 170);
    }})()""")


def test_snapping_is_a_few_screen_pixels_at_two_zooms_with_a_guide_while_it_snaps(editor):
    page = editor
    wx, wy = WINDOWS[0]
    right = wx + 60  # the window's right edge
    page.keyboard.press("4")  # door

    def draw_to(screen_px):
        """Draw a door whose moving corner ends `screen_px` screen pixels right of the window's right edge:
        (its left edge, whether a guide showed before the release)."""
        s = page.evaluate(f"{E}.view.scale")
        page.mouse.move(*screen(page, right + 30, wy + 150))
        page.mouse.down()
        page.mouse.move(*screen(page, right + screen_px / s, wy + 110), steps=5)
        seen = guide_seen(page, right)
        page.mouse.up()
        x0 = selected(page)[0]["x0"]
        page.keyboard.press("Control+z")
        return x0, seen

    for zoom in ("fit", "zoomed"):
        if zoom == "zoomed":  # about 3.3 times closer, about the window's right edge
            for _ in range(2):
                page.mouse.move(*screen(page, right + 10, wy + 120))
                page.mouse.wheel(0, -400)
                page.wait_for_timeout(50)
        s = page.evaluate(f"{E}.view.scale")
        assert (s > 4) == (zoom == "zoomed"), s
        # 3 screen pixels: snapped onto the edge, the guide shown while dragging
        assert draw_to(3) == (right, True), zoom
        # 12 screen pixels (at the higher zoom under 2 image pixels): left where the pointer was, no guide
        x0, seen = draw_to(12)
        assert x0 == pytest.approx(right + 12 / s, abs=1.01) and x0 != right and not seen, zoom


def test_exact_numbers_of_one_selection_are_one_undo_step_and_bad_ones_are_refused(editor):
    page = editor
    wx, wy = WINDOWS[0]
    assert page.is_disabled("#sel-x0") and page.is_disabled("#sel-apply")  # nothing selected
    select_window(page, wx, wy)
    assert [page.input_value(f"#sel-{k}") for k in ("x0", "y0", "x1", "y1")] == ["60", "60", "120", "150"]
    assert page.text_content("#sel-size") == "window 60 × 90"
    # typed and applied with Enter: one step, the fields and the size follow
    page.fill("#sel-x1", "130")
    page.fill("#sel-y0", "55")
    page.press("#sel-y0", "Enter")
    assert selected(page)[0] | {"id": 0} == {"id": 0, "label": "window", "x0": 60, "y0": 55, "x1": 130, "y1": 150}
    assert page.text_content("#sel-size") == "window 70 × 95" and page.text_content("#status").startswith("Set to")
    page.click("#undo")
    assert selected(page)[0]["x1"] == 120 and page.input_value("#sel-x1") == "120"
    assert not page.evaluate(f"{E}.history.canUndo")
    # refused, with the field named, and nothing changed or recorded
    for field, value, message in [("x1", "481", "x1 must be at most the image's width, 480, not 481."),
                                  ("x1", "50", "x1 must be greater than x0 (60), not 50."),
                                  ("y0", "-3", "y0 must be at least 0, not -3."),
                                  ("x0", "2.5", 'x0 must be a whole number of pixels, not "2.5".')]:
        page.fill(f"#sel-{field}", value)
        page.click("#sel-apply")
        assert page.text_content("#status") == f"Not applied: {message}"
        assert "error" in page.get_attribute("#status", "class")
        assert selected(page)[0]["x1"] == 120 and not page.evaluate(f"{E}.history.canUndo")
        page.fill(f"#sel-{field}", {"x1": "120", "y0": "60", "x0": "60"}[field])
    # two selected: no numbers to edit
    select_window(page, *WINDOWS[0])
    page.keyboard.press("Control+a")
    assert page.is_disabled("#sel-x0") and page.input_value("#sel-x0") == ""



def test_repeat_to_the_edge_from_two_examples_and_split_into_columns_each_one_undo_step(editor, tmp_path):
    page = editor
    # a wall from x 20 to 460 and two windows of a row, 140 px apart (the photo's own pitch)
    path = tmp_path / "two.json"
    path.write_text(json.dumps({"width": 480, "height": 360, "rects": [
        {"label": "facade", "x0": 20, "y0": 0, "x1": 460, "y1": 360},
        {"label": "window", "x0": 200, "y0": 60, "x1": 260, "y1": 150},
        {"label": "window", "x0": 340, "y0": 60, "x1": 400, "y1": 150}]}))
    import_file(page, path)
    page.wait_for_function(f"{E}.seg.size === 3")
    steps = page.evaluate(f"{E}.history.done.length")
    select_window(page, 200, 60)
    select_window(page, 340, 60, shift=True)
    page.click("#repeat-edge")
    assert page.text_content("#status") == ("Added 1 window copy at a pitch of about 140, 0 px where the photo shows "
                                            "one, up to the facade's edge.")  # the photo's own pitch
    windows = sorted((r["x0"], r["y0"], r["x1"], r["y1"]) for r in rects(page) if r["label"] == "window")
    assert windows == [(60, 60, 120, 150), (200, 60, 260, 150), (340, 60, 400, 150)]
    assert page.evaluate(f"{E}.history.done.length") == steps + 1
    # one selected: no pitch to measure, refused with the count
    page.keyboard.press("Escape")
    select_window(page, 60, 60)
    page.click("#repeat-edge")
    assert "and 1 is selected" in page.text_content("#status")
    page.click("#undo")
    assert len([r for r in rects(page) if r["label"] == "window"]) == 2
    # split the first window into three columns with 3 px gaps: one step, the pieces selected
    page.keyboard.press("Escape")
    select_window(page, 200, 60)
    page.fill("#split-n", "3")
    page.select_option("#split-dir", "columns")
    page.fill("#split-gap", "3")
    page.click("#split")
    assert page.text_content("#status") == "Split the window into 3 columns with gaps of 3 px."
    pieces = sorted((r["x0"], r["x1"], r["y0"], r["y1"]) for r in selected(page))
    assert pieces == [(200, 218, 60, 150), (221, 239, 60, 150), (242, 260, 60, 150)]
    page.click("#undo")
    assert sorted(r["x0"] for r in rects(page) if r["label"] == "window") == [200, 340]
    # too many pieces for the width: refused, nothing changed
    select_window(page, 200, 60)
    page.fill("#split-n", "40")
    page.click("#split")
    assert page.text_content("#status") == "40 columns with gaps of 3 px do not fit in 60 px."
    assert len(rects(page)) == 3


def test_the_draft_is_kept_on_the_server_offered_in_another_browser_and_dropped_by_a_save(editor, live_server,
                                                                                          as_alice, browser):
    page, code = editor, editor.photo["code"]
    x, y = WINDOWS[1]
    drag(page, (x, y), (x + 60, y + 90))  # the second window, drawn
    assert len(rects(page)) == 3
    page.wait_for_function("document.querySelector('#draft-note').textContent.includes('kept on the server')",
                           timeout=15_000)
    draft = as_alice.get(f"/api/v1/photos/{code}/draft").json()["draft"]
    assert draft["rect_count"] == 3
    # another browser, with nothing kept of its own, is offered the server's draft and restores it
    asked = []
    other, context = open_page(live_server, browser, code, f"{E}?.seg?.size === 3",
                               dialog=lambda d: (asked.append(d.message), d.accept()))
    assert len(asked) == 1 and "kept on the server" in asked[0]
    other.click("#save")
    other.wait_for_function("document.querySelector('#dirty').textContent === 'saved'")
    assert as_alice.get(f"/api/v1/photos/{code}/draft").json() == {"draft": None}
    assert Segmentation.objects.filter(photo__code=code).count() == 2
    assert other.errors == []
    context.close()
