"""Brute-force protection: failed logins lock out a username and an address separately (django-axes, 429 with a
page that says when to try again); the API takes a session or a token, never a password (no Basic), and
throttles anonymous clients per address and users per account (Django REST framework, 429)."""

from __future__ import annotations

import base64

import pytest
from django.test import Client
from rest_framework.authtoken.models import Token
from rest_framework.test import APIClient
from rest_framework.throttling import SimpleRateThrottle
from site_helpers import client_for

from facaid.generator import generate
from webapp.facades.models import Procedure

LIMIT = 10  # AXES_FAILURE_LIMIT's default


@pytest.fixture(autouse=True)
def fast_hashing(settings):
    """A cheap password hasher: these tests try many passwords (the users are made after this)."""
    settings.PASSWORD_HASHERS = ["django.contrib.auth.hashers.MD5PasswordHasher"]


def login(username: str, password: str, address: str, client: Client | None = None):
    client = client or Client()
    return client.post("/accounts/login/", {"username": username, "password": password}, REMOTE_ADDR=address)


def assert_lockout_page(r) -> None:
    assert r.status_code == 429
    text = r.content.decode()
    assert "Too many failed login attempts" in text
    assert "Try again in 15 minutes" in text
    assert r["Retry-After"] == "900"


def test_failed_logins_lock_out_a_username_from_any_address(alice, bob):
    statuses = [login("alice", f"wrong-{i}", f"10.0.{i}.1").status_code for i in range(30)]
    assert statuses == [200] * (LIMIT - 1) + [429] * (30 - LIMIT + 1), statuses
    assert_lockout_page(login("alice", "wrong", "10.9.9.9"))
    # the right password is refused too while the lockout lasts, from a new address as well
    c = Client()
    assert_lockout_page(login("alice", "alice-password-1", "10.8.8.8", c))
    assert "_auth_user_id" not in c.session
    # and so is the admin's login
    r = c.post("/admin/login/", {"username": "alice", "password": "alice-password-1"}, REMOTE_ADDR="10.8.8.9")
    assert r.status_code == 429
    # another user from another address logs in
    c = Client()
    r = login("bob", "bob-password-1", "10.7.7.7", c)
    assert r.status_code == 302 and c.session["_auth_user_id"] == str(bob.pk)


def test_failed_logins_lock_out_an_address_for_any_username(alice, bob):
    statuses = [login(f"user{i}", "wrong", "192.0.2.10").status_code for i in range(30)]
    assert statuses == [200] * (LIMIT - 1) + [429] * (30 - LIMIT + 1), statuses
    assert_lockout_page(login("someone-else", "wrong", "192.0.2.10"))
    assert_lockout_page(login("alice", "alice-password-1", "192.0.2.10"))  # a right password from there too
    c = Client()
    r = login("bob", "bob-password-1", "192.0.2.11", c)  # another address
    assert r.status_code == 302 and c.session["_auth_user_id"] == str(bob.pk)


def test_below_the_limit_a_right_password_still_logs_in(alice):
    for _ in range(LIMIT - 1):
        assert login("alice", "wrong", "198.51.100.1").status_code == 200
    c = Client()
    assert login("alice", "alice-password-1", "198.51.100.1", c).status_code == 302
    assert c.session["_auth_user_id"] == str(alice.pk)


def test_signup_and_forced_logins_still_work(alice):
    c = Client()
    r = c.post("/accounts/signup/", {"username": "dora", "email": "d@example.com", "password1": "a-long-secret-9",
                                     "password2": "a-long-secret-9"}, REMOTE_ADDR="203.0.113.5")
    assert r.status_code == 302 and "dora" in c.get("/").content.decode()
    assert "alice" in client_for(alice).get("/").content.decode()


# --- the API ------------------------------------------------------------------------------------------------------

def procedure_body() -> dict:
    return {"title": "by token", "data": generate(1).procedure.to_dict()}


def test_basic_auth_is_not_accepted(alice):
    basic = "Basic " + base64.b64encode(b"alice:alice-password-1").decode()
    c = APIClient()
    r = c.post("/api/v1/procedures/", procedure_body(), format="json", HTTP_AUTHORIZATION=basic)
    assert r.status_code in (401, 403), r.content
    assert c.get("/api/v1/photos/", HTTP_AUTHORIZATION=basic).status_code in (401, 403)
    assert not Procedure.objects.filter(owner=alice).exists()


def test_token_page_creates_regenerates_and_revokes_a_token_that_the_api_takes(alice):
    assert Client().get("/accounts/token/").status_code == 302  # log in first
    page = client_for(alice)
    assert "You have no API token" in page.get("/accounts/token/").content.decode()
    assert page.post("/accounts/token/", {"action": "create"}).status_code == 302
    key = Token.objects.get(user=alice).key
    assert key in page.get("/accounts/token/").content.decode()

    api = APIClient()
    r = api.post("/api/v1/procedures/", procedure_body(), format="json", HTTP_AUTHORIZATION=f"Token {key}")
    assert r.status_code == 201, r.content
    assert r.json()["title"] == "by token"
    assert api.get("/api/v1/procedures/", HTTP_AUTHORIZATION=f"Token {key}").json()["count"] == 1
    wrong = api.post("/api/v1/procedures/", procedure_body(), format="json", HTTP_AUTHORIZATION="Token " + "0" * 40)
    assert wrong.status_code == 401 and wrong["WWW-Authenticate"] == "Token"

    page.post("/accounts/token/", {"action": "create"})  # regenerate: the old key stops working
    new = Token.objects.get(user=alice).key
    assert new != key
    assert api.get("/api/v1/photos/", HTTP_AUTHORIZATION=f"Token {key}").status_code == 401
    assert api.get("/api/v1/photos/", HTTP_AUTHORIZATION=f"Token {new}").status_code == 200
    page.post("/accounts/token/", {"action": "revoke"})
    assert not Token.objects.filter(user=alice).exists()
    assert api.get("/api/v1/photos/", HTTP_AUTHORIZATION=f"Token {new}").status_code == 401


def test_token_page_needs_csrf(alice):
    c = Client(enforce_csrf_checks=True)
    c.force_login(alice)
    assert c.post("/accounts/token/", {"action": "create"}).status_code == 403
    assert not Token.objects.filter(user=alice).exists()


@pytest.fixture
def low_rates(monkeypatch):
    """The real throttles at low rates (DRF reads the rates into the class when it is imported)."""
    monkeypatch.setattr(SimpleRateThrottle, "THROTTLE_RATES", {"anon": "5/min", "user": "8/min", "heavy": "3/min",
                                                               "signup": "2/hour"})


def test_anonymous_api_clients_are_throttled_per_address(low_rates, db):
    c = APIClient()
    statuses = [c.get("/api/v1/gallery/", REMOTE_ADDR="10.1.1.1").status_code for _ in range(5)]
    assert statuses == [200] * 5
    r = c.get("/api/v1/gallery/", REMOTE_ADDR="10.1.1.1")
    assert r.status_code == 429
    assert r.json()["detail"].startswith("Request was throttled.")
    assert int(r["Retry-After"]) > 0
    # a forged X-Forwarded-For is not another address (FACAID_PROXY_COUNT=0)
    r = c.get("/api/v1/gallery/", REMOTE_ADDR="10.1.1.1", HTTP_X_FORWARDED_FOR="10.2.2.2")
    assert r.status_code == 429
    assert c.get("/api/v1/gallery/", REMOTE_ADDR="10.1.1.2").status_code == 200  # another address


def test_users_are_throttled_per_account(low_rates, alice, bob):
    as_alice, as_bob = client_for(alice), client_for(bob)
    assert [as_alice.get("/api/v1/photos/").status_code for _ in range(8)] == [200] * 8
    r = as_alice.get("/api/v1/photos/", REMOTE_ADDR="10.3.3.3")  # from another address: the same account
    assert r.status_code == 429 and "throttled" in r.json()["detail"]
    assert as_bob.get("/api/v1/photos/").status_code == 200


def test_costly_requests_have_a_rate_of_their_own(low_rates, alice):
    """Rendering is throttled at the 'heavy' rate (3/min here) before the general one (8/min) is reached."""
    as_alice = client_for(alice)
    tree = generate(1).procedure.to_dict()
    statuses = [as_alice.post("/api/v1/render", tree, format="json").status_code for _ in range(4)]
    assert statuses == [200, 200, 200, 429]
    assert as_alice.get("/api/v1/photos/").status_code == 200  # cheap requests go on
    anonymous = APIClient()
    statuses = [anonymous.post("/api/v1/render", tree, format="json", REMOTE_ADDR="10.4.4.4").status_code
                for _ in range(4)]
    assert statuses == [200, 200, 200, 429]


def test_new_accounts_are_limited_per_address(low_rates, db, django_user_model):
    from django.test import Client

    def signup(name, address):
        return Client().post("/accounts/signup/", {"username": name, "password1": "a-long-passphrase-9",
                                                   "password2": "a-long-passphrase-9"}, REMOTE_ADDR=address)

    assert [signup(f"user{i}", "10.5.5.5").status_code for i in range(2)] == [302, 302]
    r = signup("user2", "10.5.5.5")
    assert r.status_code == 429 and "Too many new accounts" in r.content.decode() and int(r["Retry-After"]) > 0
    assert not django_user_model.objects.filter(username="user2").exists()
    assert signup("user3", "10.5.5.6").status_code == 302  # another address


def test_the_token_page_is_never_cached_and_takes_a_double_click(alice):
    page = client_for(alice)
    r = page.get("/accounts/token/")
    assert "no-store" in r["Cache-Control"]
    for _ in range(2):
        assert page.post("/accounts/token/", {"action": "create"}).status_code == 302
    from rest_framework.authtoken.models import Token

    assert Token.objects.filter(user=alice).count() == 1


def test_writes_that_draw_pictures_count_as_heavy_and_reads_of_kept_files_do_not(low_rates, alice):
    """Saving a procedure draws its pictures: 3 saves a minute here; reading it, or its kept labels.png, is free."""
    as_alice = client_for(alice)
    tree = generate(1).procedure.to_dict()
    statuses = [as_alice.post("/api/v1/procedures/", {"data": tree}, format="json").status_code for _ in range(4)]
    assert statuses == [201, 201, 201, 429]
    code = as_alice.get("/api/v1/procedures/").json()["results"][0]["code"]
    reads = [as_alice.get(f"/api/v1/procedures/{code}/download/labels.png").status_code for _ in range(3)]
    assert reads == [200] * 3  # (the general rate, 8/min here, still counts them)
    r = as_alice.post(f"/procedures/{code}/fork", follow=True)
    assert "Too many forks and edits in a row" in r.content.decode()
