"""Fixtures of the site tests: three users (alice owns, bob is another user, charlie is anonymous), photos
made from generated facades, a media root per test."""

from __future__ import annotations

import pytest
from site_helpers import CHROMIUM, CHROMIUM_ARGS, Redis, Worker, client_for, facade_png, upload, wait_for_function


@pytest.fixture(autouse=True)
def media_root(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    return settings.MEDIA_ROOT


@pytest.fixture(autouse=True)
def fresh_cache():
    """The API's throttle counts and the pages kept in memory start from nothing in each test."""
    from django.core.cache import caches

    for alias in ("default", "pages"):
        caches[alias].clear()
    yield
    for alias in ("default", "pages"):
        caches[alias].clear()


@pytest.fixture
def alice(django_user_model):
    return django_user_model.objects.create_user("alice", "alice@example.com", "alice-password-1")


@pytest.fixture
def bob(django_user_model):
    return django_user_model.objects.create_user("bob", "bob@example.com", "bob-password-1")


@pytest.fixture
def as_alice(alice):
    return client_for(alice)


@pytest.fixture
def as_bob(bob):
    return client_for(bob)


@pytest.fixture
def as_charlie(db):
    return client_for(None)


@pytest.fixture
def facade_photo(as_alice):
    """Alice's private photo of a generated facade with one segmentation version."""
    data, seg = facade_png()
    photo = upload(as_alice, data, title="Generated facade").json()
    r = as_alice.post(f"/api/v1/photos/{photo['code']}/segmentations/", seg, format="json")
    assert r.status_code == 201, r.content
    return photo, r.json()


@pytest.fixture
def redis(tmp_path):
    server = Redis(tmp_path)
    server.start()
    from webapp.facades.queue import sender as app

    def use(url):  # point the sending side at this server, with fresh connection pools
        app.conf.broker_url = url
        if app._pool is not None:
            app._pool.force_close_all()
        app._pool = None
        app.amqp._producer_pool = None

    use(server.url)
    yield server
    server.stop()
    use(server.url)


@pytest.fixture
def worker(redis, tmp_path):
    w = Worker(redis, tmp_path / "worker.log")
    yield w
    w.kill()


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
def editor(live_server, as_alice, browser):
    """The editor open on Alice's windows photo with one segmentation, the wall and the first window
    (`editor_helpers.open_editor`); the test fails on any uncaught error of the page."""
    from editor_helpers import open_editor

    page, context = open_editor(live_server, as_alice, browser)
    yield page
    assert page.errors == []
    context.close()
