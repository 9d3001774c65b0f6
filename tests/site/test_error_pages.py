"""The error pages: 404, 403, 500 (and the 503 and CSRF pages) with the site's header and footer, JSON under
/api/; the 500 page drawn with the database unreachable. Alice owns, bob is another user, charlie is anonymous."""

from __future__ import annotations

import re
import uuid

import pytest
from django.db import OperationalError, connection
from django.test import Client
from django.urls import path

import webapp.urls
from webapp.facades.models import Photo

pytestmark = pytest.mark.django_db


def boom(request):
    raise RuntimeError("a bug")


# this module is also the URL conf of the tests marked `urls(__name__)`: the site's, with views that fail
urlpatterns = [path("test-only/boom", boom), path("api/v1/test-only/boom", boom), *webapp.urls.urlpatterns]
handler400, handler403 = webapp.urls.handler400, webapp.urls.handler403
handler404, handler500 = webapp.urls.handler404, webapp.urls.handler500


def site_page(r) -> str:
    """The page's HTML, checked to be the site's: its header, its footer and HTML, not JSON."""
    html = r.content.decode()
    assert r["Content-Type"].startswith("text/html"), r["Content-Type"]
    assert '<header class="top">' in html and 'class="brand"' in html and "/api/v1/docs" in html
    return html


def without_token(html: str) -> str:
    return re.sub(r'(name="csrf-?(token|middlewaretoken)" (content|value))="[^"]*"', r"\1", html)


@pytest.fixture
def photo(facade_photo):
    return Photo.objects.get(code=facade_photo[0]["code"])  # alice's, private


def test_a_missing_photo_page_is_the_styled_404(as_alice, as_charlie):
    for url in (f"/photos/{uuid.uuid4()}", "/photos/not-a-code", "/no/such/page"):
        r = as_alice.get(url)
        assert r.status_code == 404, url
        html = site_page(r)
        assert "Not found" in html and "not shared with you" in html and "alice" in html  # logged in, as ever
    html = site_page(as_charlie.get(f"/photos/{uuid.uuid4()}"))
    assert "No such photo." in html and 'href="/accounts/login/"' in html
    assert "tried" not in site_page(as_charlie.get("/no/such/page"))  # the resolver's patterns are not shown


def test_a_post_only_address_opened_as_a_link_is_the_styled_405(photo, as_alice):
    """The smoke test of the seventh session: a GET of a form's address (`require_POST`) was an empty 405 that the
    browser showed as its own error."""
    r = as_alice.get(f"/photos/{photo.code}/visibility")
    assert r.status_code == 405 and r["Allow"] == "POST"
    html = site_page(r)
    assert "Not this way" in html and "use the button" in html and "alice" in html


def test_another_users_private_photo_is_the_same_404_and_a_visible_one_is_403_to_change(photo, as_alice, as_bob):
    missing = as_bob.get(f"/photos/{uuid.uuid4()}")
    for url in (f"/photos/{photo.code}", f"/photos/{photo.code}/edit"):
        r = as_bob.get(url)
        assert r.status_code == 404, url
        assert without_token(site_page(r)) == without_token(missing.content.decode())  # its existence not told
    photo.visibility = "public"
    photo.save()
    assert as_bob.get(f"/photos/{photo.code}").status_code == 200
    r = as_bob.get(f"/photos/{photo.code}/edit")
    assert r.status_code == 403
    html = site_page(r)
    assert "Not allowed" in html and "only its owner may change it" in html
    assert "Only the owner may change this." in html  # the error's own message
    assert as_alice.get(f"/photos/{photo.code}/edit").status_code == 200


def test_the_api_keeps_answering_json_errors(photo, as_bob, as_charlie):
    cases = [(as_charlie, "/api/v1/no-such-route"), (as_charlie, f"/api/v1/photos/{uuid.uuid4()}/"),
             (as_bob, f"/api/v1/photos/{photo.code}/"), (as_bob, "/api/v1/photos/x/image")]
    for client, url in cases:
        r = client.get(url)
        assert r.status_code == 404 and r["Content-Type"] == "application/json", url
        assert r.json()["detail"], url
    photo.visibility = "public"
    photo.save()
    r = as_bob.patch(f"/api/v1/photos/{photo.code}/", {"title": "mine"}, format="json")
    assert r.status_code == 403 and r["Content-Type"] == "application/json"


@pytest.mark.urls(__name__)
def test_a_bug_is_the_styled_500_even_with_the_database_unreachable(settings, alice):
    assert not settings.DEBUG
    client = Client(raise_request_exception=False)
    client.force_login(alice)
    queries = []

    def unreachable(execute, sql, params, many, context):
        queries.append(sql)
        raise OperationalError("could not connect to server")

    with connection.execute_wrapper(unreachable):
        r = client.get("/test-only/boom")
        api = client.get("/api/v1/test-only/boom")
    assert r.status_code == 500 and queries == []  # the page read neither the session nor the user
    html = site_page(r)
    assert "Server error" in html and "try again in a moment" in html and "a bug" not in html
    assert 'href="/accounts/login/"' in html  # drawn without the session: the logged-out header
    assert api.status_code == 500 and api.json() == {"detail": "Server error."}


def test_an_unreachable_database_is_the_styled_503(as_charlie):
    def unreachable(execute, sql, params, many, context):
        raise OperationalError("could not connect to server")

    with connection.execute_wrapper(unreachable):
        r = as_charlie.get("/")
        api = as_charlie.get("/api/v1/gallery/")
    assert r.status_code == 503 and r["Retry-After"] == "5"
    assert "The database is busy or unavailable" in site_page(r)
    assert api.status_code == 503 and "busy" in api.json()["detail"]


def test_a_form_without_its_csrf_token_is_the_styled_403(photo, alice):
    client = Client(enforce_csrf_checks=True)
    client.force_login(alice)
    r = client.post(f"/photos/{photo.code}/visibility", {"visibility": "public"})
    assert r.status_code == 403
    assert "reload the page and send it again" in site_page(r)
    photo.refresh_from_db()
    assert photo.visibility == "private"
