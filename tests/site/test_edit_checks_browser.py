"""The procedure page says, beside a count, that an edit of it is not clean (issue 67, item 4), and its variations
leave that count out unless "vary those too" is ticked, saying what was left out and why; in Debian's Chromium
through Playwright. (`FACAID_SCREENSHOT_DIR=docs/img` writes docs/img/procedure-checks.png.)"""

from __future__ import annotations

import shutil

import pytest
from site_helpers import collect_errors, login, screenshot
from test_edit_checks import UNCLEAN, fake_verdicts

from facaid.generator import generate
from webapp.facades import editcheck
from webapp.facades.models import Procedure

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


def test_a_count_whose_edit_is_not_clean_is_marked_and_left_out_of_variations(live_server, alice, browser,
                                                                             monkeypatch, tmp_path):
    monkeypatch.setattr(editcheck, "check_edits", lambda tree: fake_verdicts())  # floors + 1 not clean
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="private")
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    errors = collect_errors(page, [])
    login(page, live_server.url, "alice", "alice-password-1")
    page.goto(f"{live_server.url}/procedures/{proc.code}")
    note = page.locator("#named tr[data-name=floors] td.check-note")
    note.locator("xpath=self::*[contains(@class, 'failed')]").wait_for()
    assert note.text_content() == f"floors + 1 is not clean: {UNCLEAN}"
    assert "floors \u2212 1 is clean" in note.get_attribute("title")  # both edits, on hovering
    assert page.text_content("#named tr[data-name=bays] td.check-note") == ""  # clean: nothing said
    assert page.text_content("#named tr[data-name=floor_height] td.check-note") == ""  # a length: not judged
    screenshot(page.locator("#named"), "procedure-checks.png", tmp_path)

    page.click("#vary")
    page.wait_for_function("document.querySelectorAll('#variants .card img').length === 8")
    assert page.text_content("#vary-left-out") == (f"Left out: upper floors (floors + 1 is not clean: {UNCLEAN}). "
                                                   'Tick "vary those too" to vary them anyway.')
    captions = page.eval_on_selector_all("#variants .card .meta", "els => els.map(e => e.textContent)")
    screenshot(page.locator("#vary").locator("xpath=ancestor::div[contains(@class, 'panel')]"),
               "procedure-checks-variations.png", tmp_path)
    page.check("#include-unchecked")
    page.click("#vary")
    page.wait_for_function("document.getElementById('vary-left-out').hidden")
    page.wait_for_function("(c => c.length === 8)([...document.querySelectorAll('#variants .card .meta')])")
    assert page.eval_on_selector_all("#variants .card .meta", "els => els.map(e => e.textContent)") != captions
    assert errors == []
