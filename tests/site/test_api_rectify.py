"""Rectification on the API: the four corners proposed from the photo (alice owns, bob is another user, charlie is
anonymous)."""

from __future__ import annotations

import numpy as np
import pytest
from site_helpers import image_bytes, photo_like, upload

pytestmark = pytest.mark.django_db


@pytest.fixture
def street_photo(as_alice):
    data, corners = photo_like()
    return upload(as_alice, data, title="Street").json(), corners


def propose_url(photo) -> str:
    return f"/api/v1/photos/{photo['code']}/corners/propose"


def test_the_owner_gets_corners_on_the_facade_and_rectifies_with_them(street_photo, as_alice):
    photo, true = street_photo
    r = as_alice.post(propose_url(photo))
    assert r.status_code == 200, r.content
    body = r.json()
    assert set(body) == {"corners", "confidence", "notes", "lines"} and 0 < body["confidence"] <= 1
    diag = np.hypot(*(true.max(axis=0) - true.min(axis=0)))
    assert np.linalg.norm(np.array(body["corners"]) - true, axis=1).max() < 0.01 * diag
    rectified = as_alice.post(f"/api/v1/photos/{photo['code']}/rectify", {"corners": body["corners"]},
                              format="json")
    assert rectified.status_code == 200 and rectified.json()["rectified"]


def test_a_photo_of_one_colour_gets_its_own_corners_and_a_note(as_alice):
    photo = upload(as_alice, image_bytes(size=(64, 48))).json()
    body = as_alice.post(propose_url(photo)).json()
    assert body["corners"] == [[0, 0], [64, 0], [64, 48], [0, 48]] and body["confidence"] == 0 and body["notes"]


def test_only_the_owner_may_ask(street_photo, as_alice, as_bob, as_charlie):
    photo, _ = street_photo
    assert as_bob.post(propose_url(photo)).status_code == 404  # private: not revealed
    assert as_charlie.post(propose_url(photo)).status_code == 401
    as_alice.patch(f"/api/v1/photos/{photo['code']}/", {"visibility": "public"}, format="json")
    assert as_bob.post(propose_url(photo)).status_code == 403  # public: seen, not changed
    assert as_charlie.post(propose_url(photo)).status_code == 401
    assert as_alice.get(propose_url(photo)).status_code == 405
    assert as_alice.post("/api/v1/photos/not-a-code/corners/propose").status_code == 404
