"""The fixtures the site's tests share with the worker's (tests/worker/conftest.py imports them too): three users
(alice owns, bob is another user, charlie is anonymous), photos made from generated facades, a media root and a fresh
cache per test, a real Redis server and a real worker process."""

from __future__ import annotations

import pytest
from site_helpers import Redis, Worker, client_for, facade_png, upload


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
