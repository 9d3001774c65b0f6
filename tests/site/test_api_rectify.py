"""Rectification and scale on the API and the pages: the four corners proposed from the photo, the facade's real
width or height and the downloads that take it (alice owns, bob is another user, charlie is anonymous)."""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest
from site_helpers import image_bytes, photo_like, upload

from facaid.generator import generate

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


# --- the facade's real size: the scale of its procedures' CGA rules and meshes -------------------------------------

def photo_url(photo) -> str:
    return f"/api/v1/photos/{photo['code']}/"


def test_the_real_width_or_height_is_set_validated_and_cleared(facade_photo, as_alice, as_bob):
    photo, _ = facade_photo
    r = as_alice.patch(photo_url(photo), {"real_width_m": 12.5}, format="json")
    assert r.status_code == 200, r.content
    assert r.json()["real_width_m"] == 12.5 and r.json()["metres_per_pixel"] == pytest.approx(12.5 / photo["width"])
    r = as_alice.patch(photo_url(photo), {"real_height_m": 20}, format="json")  # one at a time: the width goes
    body = r.json()
    assert body["real_width_m"] is None and body["metres_per_pixel"] == pytest.approx(20 / photo["height"])
    for field, value in (("real_width_m", 0.1), ("real_width_m", 5000), ("real_height_m", "tall"),
                         ("real_height_m", -3), ("real_width_m", "1e400"), ("real_height_m", "true")):
        body = f'{{"{field}": {value}}}' if value in ("1e400", "true") else {field: value}  # raw JSON: infinity
        r = as_alice.patch(photo_url(photo), body, content_type="application/json") if isinstance(body, str) \
            else as_alice.patch(photo_url(photo), body, format="json")
        assert r.status_code == 400 and list(r.json()) == [field], (field, value, r.content)
    r = as_alice.patch(photo_url(photo), {"real_width_m": 10, "real_height_m": 10}, format="json")
    assert r.status_code == 400 and "not both" in r.json()["real_height_m"][0]
    assert as_alice.get(photo_url(photo)).json()["real_height_m"] == 20  # nothing refused was stored
    assert as_bob.patch(photo_url(photo), {"real_width_m": 3}, format="json").status_code == 404
    r = as_alice.patch(photo_url(photo), {"real_height_m": None}, format="json")
    assert r.json()["real_height_m"] is None and r.json()["metres_per_pixel"] is None


@pytest.fixture
def procedure_of_photo(facade_photo, alice):
    from webapp.facades.models import Photo, Procedure, Segmentation

    photo, seg = facade_photo
    data = generate(3).procedure.to_dict()  # facade_png draws seed 3: the procedure has the photo's size
    proc = Procedure.objects.create(owner=alice, title="p", data=data, photo=Photo.objects.get(code=photo["code"]),
                                    segmentation=Segmentation.objects.get(code=seg["code"]))
    return photo, proc


def obj_extent(zip_bytes: bytes) -> tuple[float, str]:
    """The mesh's width (x extent of its vertices) and its header."""
    with zipfile.ZipFile(io.BytesIO(zip_bytes)) as z:
        obj = z.read("facade.obj").decode()
    xs = [float(line.split()[1]) for line in obj.splitlines() if line.startswith("v ")]
    return max(xs) - min(xs), "\n".join(line for line in obj.splitlines()[:3] if line.startswith("#"))


def test_downloads_take_the_photos_scale_and_say_so(procedure_of_photo, as_alice, as_charlie):
    photo, proc = procedure_of_photo
    base = f"/api/v1/procedures/{proc.code}/download/"
    width_px = proc.data["width"]
    default_width, header = obj_extent(as_alice.get(base + "mesh.zip").content)
    assert "a storey 3 m tall" in header
    assert as_alice.patch(photo_url(photo), {"real_width_m": 24}, format="json").status_code == 200

    width, header = obj_extent(as_alice.get(base + "mesh.zip").content)
    assert width == pytest.approx(24, abs=0.01) and width != pytest.approx(default_width, abs=0.1)
    assert f"{24 / width_px:.6g} m per pixel (the photo's real width, 24 m)" in header
    cga = as_alice.get(base + "procedure.cga").content.decode()
    assert "24 m x" in cga and "(the photo's real width, 24 m)" in cga
    # asked for another scale, the download takes it
    width, header = obj_extent(as_alice.get(base + "mesh.zip?metres_per_pixel=0.01").content)
    assert width == pytest.approx(0.01 * width_px, abs=0.01) and "(given)" in header
    # the procedure's page says which scale its downloads take: the procedure's own, which the real size gave it,
    # to all who may see the procedure (issue 67; the photo itself stays private)
    proc.refresh_from_db()
    assert proc.metres_per_pixel == pytest.approx(24 / width_px)
    proc.visibility = "public"
    proc.save()
    for client in (as_alice, as_charlie):
        page = client.get(f"/procedures/{proc.code}").content.decode().replace("&#x27;", "'")
        assert "the photo's real width, 24 m" in page and "a storey is 3 m tall" not in page


def test_the_photo_page_sets_the_real_size(facade_photo, as_alice, as_bob):
    photo, _ = facade_photo
    url = f"/photos/{photo['code']}/real-size"
    assert as_alice.post(url, {"side": "height", "metres": "18.5"}).status_code == 302
    page = as_alice.get(f"/photos/{photo['code']}").content.decode()
    assert "The facade is 18.5 m tall" in page and f"{18.5 / photo['height']:.5f} m per pixel" in page
    as_alice.post(url, {"side": "width", "metres": "0.2"})  # out of range: a message naming the field
    page = as_alice.get(f"/photos/{photo['code']}").content.decode()
    assert "real_width_m" in page and "The facade is 18.5 m tall" in page
    assert as_bob.post(url, {"side": "width", "metres": "10"}).status_code == 404
    as_alice.post(url, {"side": "width", "metres": ""})
    assert "Not given" in as_alice.get(f"/photos/{photo['code']}").content.decode()
