"""The editor's panels and helpers in Debian's Chromium: the layout on a 1280x720 screen (saving and the job in
view), and the side panels' tools."""

from __future__ import annotations

import os
import shutil

import pytest
from editor_helpers import E, open_editor

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


@pytest.fixture
def editor(live_server, as_alice, browser):
    page, context = open_editor(live_server, as_alice, browser)
    yield page
    assert page.errors == []
    context.close()


@pytest.fixture
def small_screen(live_server, as_alice, browser):
    page, context = open_editor(live_server, as_alice, browser, viewport=(1280, 720))
    yield page
    assert page.errors == []
    context.close()


def in_view(page, selector: str) -> bool:
    """Is the element wholly inside the window, the page not scrolled?"""
    b = page.locator(selector).bounding_box()
    return b is not None and b["x"] >= 0 and b["y"] >= 0 and b["x"] + b["width"] <= 1280 and b["y"] + b["height"] <= 720


def test_at_1280x720_the_canvas_saving_and_the_job_are_in_view(small_screen, tmp_path):
    page = small_screen
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
    assert page.evaluate("document.querySelector('.tools').scrollHeight > document.querySelector('.tools').clientHeight")
    page.evaluate("document.querySelector('#status').textContent = 'Ready.'")
    path = os.environ.get("FACAID_EDITOR_SCREENSHOT") or str(tmp_path / "editor-1280x720.png")
    page.screenshot(path=path)
    assert page.evaluate(f"{E}.history.canUndo") is False
