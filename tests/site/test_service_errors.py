"""The services' errors (`webapp.facades.errors`) as the API answers them and the pages show them: each kind
its status with the API's JSON (``{"<field>": …}`` for input at fault, else ``{"detail": …}``), through the real API;
on a page, the message beside the form that sent the input, else the site's error page. Alice owns, bob is another
user, charlie is anonymous."""

from __future__ import annotations

import uuid

import pytest
from rest_framework.test import APIClient
from site_helpers import image_bytes, upload

from facaid.generator import generate
from webapp.error_pages import SERVICE_STATUS, service_status
from webapp.facades.api.exception_handler import exception_handler
from webapp.facades.errors import (
    Invalid,
    NotAllowed,
    NotFound,
    NotSignedIn,
    QuotaError,
    ServiceError,
    TooManyJobs,
)
from webapp.facades.jsonbody import JSONError
from webapp.facades.models import Job, Photo, Procedure
from webapp.facades.uploads import UploadError
from webapp.middleware import ServiceErrorMiddleware

pytestmark = pytest.mark.django_db


def _kinds(cls=ServiceError) -> list[type[ServiceError]]:
    out = []
    for sub in cls.__subclasses__():
        out += [sub, *_kinds(sub)]
    return out


def test_every_kind_of_error_has_a_status_and_no_service_imports_drf():
    assert {Invalid, NotFound, NotAllowed, TooManyJobs, QuotaError, UploadError, JSONError} <= set(_kinds())
    assert {cls.kind for cls in _kinds()} <= set(SERVICE_STATUS)
    assert [service_status(cls("x")) for cls in (Invalid, NotFound, NotAllowed, TooManyJobs, QuotaError)] == [
        400, 404, 403, 429, 400]
    answer = exception_handler(Invalid("give a number", "k"), {})
    assert (answer.status_code, answer.data) == (400, {"k": "give a number"})
    answer = exception_handler(NotFound("no such job"), {})
    assert (answer.status_code, answer.data) == (404, {"detail": "no such job"})
    assert UploadError("the file is empty").field == "image" and isinstance(JSONError("bad"), ValueError)

    from pathlib import Path

    import webapp.facades.services as services

    for path in Path(services.__file__).parent.glob("*.py"):
        assert "rest_framework" not in path.read_text(), path.name


def test_invalid_input_is_a_400_naming_the_field(facade_photo, as_alice):
    photo, _ = facade_photo
    r = as_alice.get(f"/api/v1/photos/{photo['code']}/segmentation?format=svg")
    assert r.status_code == 400 and r["Content-Type"] == "application/json"
    assert r.json() == {"format": "give one of segmentation, coco, labelme, cvat, got 'svg'"}
    r = as_alice.post(f"/api/v1/photos/{photo['code']}/rectify", {"corners": [[0, 0], [1e6, 0], [9, 9], [0, 9]]},
                      format="json")
    assert r.status_code == 400 and list(r.json()) == ["corners"] and "far outside" in r.json()["corners"]
    r = upload(as_alice, b"", name="empty.png")  # an `UploadError`: the upload's field
    assert (r.status_code, r.json()) == (400, {"image": "the file is empty"})


def test_what_is_not_there_is_a_404_with_its_detail(as_alice, as_charlie):
    photo = upload(as_alice, image_bytes(size=(64, 48))).json()
    r = as_alice.get(f"/api/v1/photos/{photo['code']}/segmentation")
    assert (r.status_code, r.json()) == (404, {"detail": "this photo has no segmentation yet"})
    assert as_charlie.get(f"/api/v1/photos/{photo['code']}/").json() == {"detail": "no such photo"}  # private
    proc = as_alice.post("/api/v1/procedures/", {"data": generate(3).procedure.to_dict()}, format="json").json()
    r = as_alice.get(f"/api/v1/procedures/{proc['code']}/versions/7/")
    assert r.status_code == 404 and r.json()["detail"] == "no version 7 of this procedure: it has versions 1 to 1"


def test_what_may_not_be_changed_is_a_403(as_alice, as_bob):
    photo = upload(as_alice, image_bytes(size=(64, 48)), visibility="public").json()
    r = as_bob.patch(f"/api/v1/photos/{photo['code']}/", {"title": "mine"}, format="json")
    assert (r.status_code, r.json()) == (403, {"detail": "only the owner may change this"})
    assert Photo.objects.get(code=photo["code"]).title == ""


def test_a_change_asked_without_an_account_is_a_401_or_the_sign_in_page(as_alice, rf):
    """The smoke test of the seventh session: an anonymous PATCH of someone's photo or procedure was a 403 "only the
    owner may change this", where fork, jobs and the rest said 401. Now DRF's 401 with its challenge; on a page,
    the sign-in page."""
    photo = upload(as_alice, image_bytes(size=(64, 48)), visibility="public").json()
    proc = as_alice.post("/api/v1/procedures/", {"data": generate(3).procedure.to_dict(), "visibility": "public"},
                         format="json").json()
    anon = APIClient()
    for r in (anon.patch(f"/api/v1/photos/{photo['code']}/", {"title": "mine"}, format="json"),
              anon.patch(f"/api/v1/procedures/{proc['code']}/", {"title": "mine"}, format="json"),
              anon.delete(f"/api/v1/procedures/{proc['code']}/")):
        assert r.status_code == 401 and r.json() == {"detail": "Authentication credentials were not provided."}
        assert r.headers["WWW-Authenticate"] == "Token"
    assert Photo.objects.get(code=photo["code"]).title == "" and Procedure.objects.filter(code=proc["code"]).exists()
    page = ServiceErrorMiddleware(lambda request: None).process_exception(rf.post("/procedures/x/fork"),
                                                                          NotSignedIn("sign in to change this"))
    assert page.status_code == 302 and page.url.startswith("/accounts/login/?next=")


def test_a_bad_procedure_is_one_flat_message_under_data(as_alice):
    """Not ``{"data": {"data": ...}}``: the library's message under the field, as every service error gives it."""
    proc = as_alice.post("/api/v1/procedures/", {"data": generate(3).procedure.to_dict()}, format="json").json()
    for bad in ({"bogus": 1}, "x"):
        r = as_alice.patch(f"/api/v1/procedures/{proc['code']}/", {"data": bad}, format="json")
        assert r.status_code == 400 and isinstance(r.json()["data"], str) and "procedure" in r.json()["data"]
    r = as_alice.post("/api/v1/procedures/", {"data": {"bogus": 1}}, format="json")
    assert r.status_code == 400 and isinstance(r.json()["data"], str)


def test_too_many_jobs_is_a_429(facade_photo, as_alice, settings):
    settings.FACAID_MAX_ACTIVE_JOBS = 0
    r = as_alice.post("/api/v1/jobs/", {"segmentation": facade_photo[1]["code"]}, format="json")
    assert r.status_code == 429 and r.json() == {"detail": "You have 0 reconstructions waiting or running (at most 0); "
                                                           "submit more when one has finished."}
    assert not Job.objects.exists()


def test_a_full_quota_is_a_400_saying_so(as_alice, settings):
    settings.FACAID_STORAGE_QUOTA_MB = 1e-6  # a byte
    r = upload(as_alice, image_bytes(size=(400, 300)))
    assert r.status_code == 400 and list(r.json()) == ["detail"] and "your account stores" in r.json()["detail"]
    assert not Photo.objects.exists()


def test_a_page_shows_the_error_page_for_what_is_missing_or_not_the_viewers(as_alice, as_bob):
    r = as_alice.get(f"/procedures/{uuid.uuid4()}")
    html = r.content.decode()
    assert r.status_code == 404 and r["Content-Type"].startswith("text/html")
    assert "No such procedure." in html and "There is nothing here, or it is not shared with you." in html
    proc = as_alice.post("/api/v1/procedures/", {"data": generate(3).procedure.to_dict(), "visibility": "public"},
                         format="json").json()
    r = as_bob.post(f"/procedures/{proc['code']}/delete")
    assert r.status_code == 403 and "Only the owner may change this." in r.content.decode()
    assert as_bob.get(f"/procedures/{proc['code']}").status_code == 200  # still there


def test_a_page_says_invalid_input_and_too_many_jobs_beside_the_form(facade_photo, as_alice, settings):
    proc = as_alice.post("/api/v1/procedures/", {"data": generate(3).procedure.to_dict()}, format="json").json()
    r = as_alice.post(f"/procedures/{proc['code']}/visibility", {"visibility": "public", "share_photo": "on"},
                      follow=True)
    assert r.status_code == 200 and "share_photo: this procedure has no photo to share" in r.content.decode()
    settings.FACAID_MAX_ACTIVE_JOBS = 0
    photo, _ = facade_photo
    r = as_alice.post(f"/photos/{photo['code']}/reconstruct", {"k": 2, "seed": 0, "structure": "editable"},
                      follow=True)
    assert r.status_code == 200 and "You have 0 reconstructions waiting or running" in r.content.decode()
