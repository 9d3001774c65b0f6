"""The procedure page's sharing and overlay in Debian's Chromium through Playwright: sharing asks whether to share
the photo too and says what viewers will see, and the overlay on the photo follows; it hides while the procedure is
not the photo's size."""

from __future__ import annotations

import shutil

import pytest
from site_helpers import faithful_procedure, open_as_alice

from facaid.grammar import Procedure as Tree

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


def test_sharing_asks_whether_to_share_the_photo_and_the_overlay_follows(live_server, alice, facade_photo, browser,
                                                                        tmp_path):
    from site_helpers import screenshot

    _, seg = facade_photo
    proc = faithful_procedure(alice, seg)  # alice's photo and procedure, both private
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1280, "height": 800}, advanced=False)
    assert page.text_content("#viewers-see") == "Only you see this procedure."
    assert not page.is_visible("#share-photo")  # nothing to ask while it stays private
    page.select_option("#visibility-form select", "public")
    assert page.is_visible("#share-photo") and "the photo is private; either way the procedure itself redraws" in (
        page.text_content("#share-photo"))
    assert page.text_content("#viewers-will-see") == (
        "Once saved: Anyone sees the procedure, its pictures and 3D models, but not the photo or the overlay: the "
        "photo is private. The procedure itself redraws the annotation (an exact version reproduces it as drawn) "
        "at its size in metres; the photo's title and the accuracy against it are not shown.")
    page.check("#share-photo input")
    assert page.text_content("#viewers-will-see") == (
        "Once saved: Anyone sees the procedure with its photo and the overlay.")
    page.uncheck("#share-photo input")
    form = page.locator("#visibility-form").locator("xpath=ancestor::div[contains(@class, 'panel')]")
    form.scroll_into_view_if_needed()
    screenshot(form, "share-photo.png", tmp_path)
    page.click("#visibility-form button")  # public, the photo left private: the page says what viewers see
    page.wait_for_selector(".msg")
    assert "the photo is private. The procedure itself redraws the annotation" in page.text_content("#viewers-see")
    anonymous = browser.new_page()
    anonymous.goto(f"{live_server.url}/procedures/{proc.code}")
    assert anonymous.locator("#overlay").count() == 0 and "No photo to overlay" in anonymous.content()
    page.select_option("#visibility-form select", "public")
    page.check("#share-photo input")
    page.click("#visibility-form button")
    page.wait_for_selector("text=Anyone sees the procedure with its photo and the overlay.")
    anonymous.reload()
    anonymous.wait_for_function("document.getElementById('overlay') && document.getElementById('overlay').complete "
                                "&& document.getElementById('overlay').naturalWidth > 0")
    assert not errors


def test_the_overlay_hides_while_the_procedure_is_not_the_photos_size(live_server, alice, facade_photo, browser):
    """A newcomer saw a floor more drawn stretched over the photo, as if the reconstruction had broken."""
    from facaid.editing.parameters import named_parameters

    _, seg = facade_photo
    proc = faithful_procedure(alice, seg)  # the photo's size
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1280, "height": 900}, advanced=False)
    page.wait_for_selector("#named input[name=floors]")
    assert page.is_visible("#overlay") and page.is_hidden("#overlay-note")
    floors = next(p.value for p in named_parameters(Tree.from_dict(proc.data)) if p.name == "floors")
    field = page.locator("#named input[name=floors]")
    field.fill(str(floors + 1))
    field.dispatch_event("change")
    page.wait_for_function("!document.getElementById('overlay-note').hidden")
    assert page.is_hidden("#overlay") and "its photo" in page.text_content("#overlay-note")
    field.fill(str(floors))  # back to the photo's size: the overlay again
    field.dispatch_event("change")
    page.wait_for_function("document.getElementById('overlay-note').hidden")
    assert page.is_visible("#overlay") and not errors
