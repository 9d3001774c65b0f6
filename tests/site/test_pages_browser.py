"""The site's own pages in Debian's Chromium through Playwright, offline (every request to another site is refused
and counted): the API docs list the operations from the schema with Swagger UI served from our static files; the
404 page; disabled controls look disabled. With FACAID_SCREENSHOT_DIR set, the pictures of docs/img are written
there (api-docs.png, not-found.png)."""

from __future__ import annotations

import shutil
import uuid

import pytest
from editor_helpers import open_editor
from site_helpers import login, offline_page, screenshot

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


def test_the_api_docs_list_the_operations_offline(live_server, alice, browser, tmp_path):
    page = offline_page(browser, live_server.url, viewport=(1280, 1100))
    login(page, live_server.url, "alice", "alice-password-1")
    page.goto(f"{live_server.url}/")
    page.click("footer >> text=API docs")
    page.wait_for_url(f"{live_server.url}/api/v1/docs")
    page.wait_for_selector(".opblock")
    paths = page.eval_on_selector_all(".opblock-summary-path", "els => els.map(e => e.dataset.path || e.textContent)")
    methods = page.eval_on_selector_all(".opblock-summary-method", "els => els.map(e => e.textContent)")
    for expected in ("/api/v1/photos/", "/api/v1/procedures/{code}/fork", "/api/v1/jobs/{code}/"):
        assert expected in paths, paths
    assert len(paths) >= 20 and {"GET", "POST", "PATCH", "DELETE"} <= set(methods)
    assert page.elsewhere == [] and page.errors == []
    assert page.locator("header.top .who").inner_text() == "alice"  # the site's header over Swagger UI
    # an operation opens with its parameters and answers
    one = page.locator(".opblock-get:has(.opblock-summary-path[data-path='/api/v1/procedures/{code}/'])")
    one.locator(".opblock-summary-control").click()
    one.locator(".parameters-container").wait_for()
    assert "code" in one.locator(".parameters-container").inner_text()
    one.locator(".opblock-summary-control").click()  # closed again for the picture
    one.locator(".parameters-container").wait_for(state="detached")
    page.evaluate("scrollTo(0, 0)")
    screenshot(page, "api-docs.png", tmp_path)
    # the YAML the page is read from stays a link away
    href = page.get_attribute("#schema-yaml", "href")
    assert href == "/api/v1/schema"
    assert page.request.get(f"{live_server.url}{href}").text().startswith("openapi:")


def test_the_404_page_offline(live_server, alice, browser, tmp_path):
    page = offline_page(browser, live_server.url)
    login(page, live_server.url, "alice", "alice-password-1")
    r = page.goto(f"{live_server.url}/photos/{uuid.uuid4()}")
    assert r.status == 404
    assert page.locator("h1").inner_text() == "Not found"
    assert page.locator("header.top .who").inner_text() == "alice"
    assert page.elsewhere == [] and page.errors == []
    screenshot(page, "not-found.png", tmp_path)
    page.click("text=Go to the gallery")
    page.wait_for_url(f"{live_server.url}/")


def test_disabled_controls_look_disabled(live_server, as_alice, browser):
    """In the editor, every kind of control, disabled, is greyed or faded and shows the not-allowed cursor, whatever
    colours its own rule gives it (the palette's white buttons, a pressed layer toggle, a link styled as a button)."""
    page, context = open_editor(live_server, as_alice, browser)
    page.wait_for_selector("#objects button.layer")
    page.evaluate("""() => {
      document.querySelector('#result').hidden = false;
      document.querySelector('#result-link').setAttribute('aria-disabled', 'true');
      document.querySelector('#objects button.layer').setAttribute('aria-pressed', 'true');
      for (const s of ['#palette button', '#objects button.layer', '#split-dir', '#snap', '#fill', '#import']) {
        document.querySelector(s).disabled = true;
      }
    }""")
    look = """el => { const s = getComputedStyle(el);
      return {background: s.backgroundColor, color: s.color, cursor: s.cursor, opacity: s.opacity,
              events: s.pointerEvents}; }"""
    assert page.eval_on_selector("#undo", "b => b.disabled")  # nothing to undo yet: the toolbar's own state
    assert page.eval_on_selector("#sel-x0", "i => i.disabled")  # nothing selected
    greyed = ("#undo", "#palette button", "#objects button.layer", "#result-link", "label.button:has(#import)")
    faded = ("#sel-x0", "#split-dir", "#snap", "#fill")
    for selector in greyed:
        style = page.eval_on_selector(selector, look)
        assert (style["background"], style["color"], style["cursor"]) == (
            "rgb(201, 204, 209)", "rgb(95, 102, 112)", "not-allowed"), (selector, style)
    for selector in faded:
        style = page.eval_on_selector(selector, look)
        assert float(style["opacity"]) < 1 and style["cursor"] == "not-allowed", (selector, style)
    assert page.eval_on_selector("#result-link", look)["events"] == "none"  # a disabled link is not followed
    for selector, background in (("#save", "rgb(31, 111, 235)"), ("#duplicate", "rgb(31, 111, 235)"),
                                 ("#palette button:enabled", "rgb(255, 255, 255)")):  # enabled ones keep theirs
        style = page.eval_on_selector(selector, look)
        assert style["background"] == background and style["cursor"] == "pointer", (selector, style)
    assert page.errors == []
    context.close()


def test_a_newcomer_sees_photo_procedure_variations_and_tries_the_demo_offline(live_server, browser, tmp_path):
    """Issue 58: the front page shows what the product does, from the demo, and the first step."""
    from django.core.management import call_command

    from facaid.generator import generate
    from webapp.facades.models import Photo, Procedure

    call_command("demo")
    photo = Photo.objects.get()
    proc = Procedure.objects.create(owner=photo.owner, data=generate(3).procedure.to_dict(), visibility="public",
                                    photo=photo, accuracy=0.9971)  # what the worker makes of the demo
    page = offline_page(browser, live_server.url, viewport=(1280, 800))
    page.goto(f"{live_server.url}/")
    page.wait_for_function("[...document.querySelectorAll('#example img')].every(i => i.complete && i.naturalWidth)")
    assert page.locator("#example img").count() == 5  # the photo, the procedure, three variations
    assert page.is_visible("text=Sign up and upload a photo") and page.is_visible("#try-demo")
    box = page.locator("#try-demo").bounding_box()
    assert box["y"] + box["height"] <= 800  # the first step is above the fold
    screenshot(page.locator("#intro"), "front-page.png", tmp_path)
    page.click("#try-demo")  # no account: the demo's page, with its parameters to change
    page.wait_for_url(f"{live_server.url}/procedures/{proc.code}")
    page.wait_for_selector("#named input")
    assert page.elsewhere == [] and page.errors == []
