"""Fixtures of the site tests: those shared with the worker's tests (`site_fixtures`: the users, photos made from
generated facades, a media root per test, a real Redis and worker), and the browser's."""

from __future__ import annotations

import pytest
from site_fixtures import (  # noqa: F401 (pytest finds the fixtures where they are imported)
    alice,
    as_alice,
    as_bob,
    as_charlie,
    bob,
    facade_photo,
    fresh_cache,
    media_root,
    redis,
    worker,
)
from site_helpers import CHROMIUM, CHROMIUM_ARGS, wait_for_function


@pytest.fixture(autouse=True)
def csp_safe_waits(monkeypatch):
    """Page.wait_for_function that works under the site's Content-Security-Policy (`site_helpers.wait_for_function`):
    the browser tests run the pages under the policy they are served with."""
    try:
        from playwright.sync_api import Page
    except ImportError:
        return
    monkeypatch.setattr(Page, "wait_for_function", wait_for_function)


@pytest.fixture
def browser(monkeypatch):
    """Debian's Chromium through Playwright."""
    from playwright.sync_api import sync_playwright

    # Playwright's sync API keeps an event loop in this thread; the ORM calls of the test are still synchronous
    monkeypatch.setenv("DJANGO_ALLOW_ASYNC_UNSAFE", "true")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield b
        b.close()


@pytest.fixture
def editor(live_server, as_alice, browser):  # noqa: F811 (as_alice: the fixture imported above)
    """The editor open on Alice's windows photo with one segmentation, the wall and the first window
    (`editor_helpers.open_editor`); the test fails on any uncaught error of the page."""
    from editor_helpers import open_editor

    page, context = open_editor(live_server, as_alice, browser)
    yield page
    assert page.errors == []
    context.close()
