"""Issue 67, item 7: a procedure keeps its own scale (metres per pixel). Made from a photo with a real size it takes
that photo's; a fork keeps it, so that it downloads at its owner's size even where the forker may not see the photo;
an edit of a window's size never changes it; its owner may set or clear it; a new real size of the photo rescales
its owner's procedures and no one else's; and migration 0009 gives existing procedures theirs where that shows
nobody anything they were not shown before."""

from __future__ import annotations

import io
import os
import re
import shutil
import zipfile

import pytest
from site_helpers import collect_errors, facade_png, login

from facaid.generator import generate
from webapp.facades.models import Photo, Procedure, Segmentation

pytestmark = pytest.mark.django_db

REAL_WIDTH = 22.0


def mesh_width(client, code, query: str = "") -> tuple[float, str]:
    """The relief mesh's width in metres (the x extent of its vertices) and its scale line."""
    r = client.get(f"/api/v1/procedures/{code}/download/mesh.zip{query}")
    assert r.status_code == 200, r.content
    with zipfile.ZipFile(io.BytesIO(r.content)) as z:
        obj = z.read("facade.obj").decode()
    xs = [float(line.split()[1]) for line in obj.splitlines() if line.startswith("v ")]
    return max(xs) - min(xs), next(line for line in obj.splitlines() if line.startswith("# scale:"))


@pytest.fixture
def scaled(facade_photo, alice, as_alice):
    """Alice's public procedure of her private photo, to which she then gives a real width: her procedure takes it."""
    photo, seg = facade_photo
    data = generate(3).procedure.to_dict()  # facade_png draws seed 3: the procedure has the photo's size
    proc = Procedure.objects.create(owner=alice, title="Rue 5", data=data, visibility="public",
                                    photo=Photo.objects.get(code=photo["code"]),
                                    segmentation=Segmentation.objects.get(code=seg["code"]))
    r = as_alice.patch(f"/api/v1/photos/{photo['code']}/", {"real_width_m": REAL_WIDTH}, format="json")
    assert r.status_code == 200
    proc.refresh_from_db()
    assert proc.metres_per_pixel == pytest.approx(REAL_WIDTH / data["width"])
    assert proc.scale_from == f"the photo's real width, {REAL_WIDTH:g} m"
    return photo, proc


def test_a_fork_downloads_at_its_owners_size_and_an_edit_keeps_the_scale(scaled, as_alice, as_bob):
    photo, proc = scaled
    width, line = mesh_width(as_alice, proc.code)
    assert width == pytest.approx(REAL_WIDTH, abs=0.01) and "the photo's real width, 22 m" in line
    r = as_bob.post(f"/api/v1/procedures/{proc.code}/fork")  # bob may not see alice's photo
    assert r.status_code == 201 and r.json()["photo"] is None
    fork = r.json()
    assert fork["metres_per_pixel"] == proc.metres_per_pixel
    assert mesh_width(as_bob, fork["code"]) == (width, line)  # the same metres, said the same way
    page = as_bob.get(f"/procedures/{fork['code']}").content.decode().replace("&#x27;", "'")
    assert "(left empty, the photo's real width, 22 m: " in page  # the page says so too
    for name in ("procedure.cga", "facade.city.json"):
        mine = as_alice.get(f"/api/v1/procedures/{proc.code}/download/{name}").content.decode()
        theirs = as_bob.get(f"/api/v1/procedures/{fork['code']}/download/{name}").content.decode()
        assert f"{REAL_WIDTH:.2f} m x" in theirs or "22 m x" in theirs, name
        assert mine.replace("Rue 5", "Fork of Rue 5") == theirs or name == "facade.city.json", name
    # an edit of the window height (a new version) keeps the scale: the facade is as wide in metres as before
    before = Procedure.objects.get(code=fork["code"]).metres_per_pixel
    r = as_bob.post(f"/api/v1/procedures/{fork['code']}/parameters", {"values": {"window_height": 70}, "save": True},
                    format="json")
    assert r.status_code == 200, r.content
    edited = Procedure.objects.get(code=fork["code"])
    assert edited.current_version().version == 2 and edited.metres_per_pixel == before
    width_after, line_after = mesh_width(as_bob, fork["code"])  # taller windows, a taller facade, as wide
    assert line_after.rsplit(":", 1)[0] == line.rsplit(":", 1)[0] and width_after == pytest.approx(width)
    assert as_bob.get(f"/api/v1/procedures/{fork['code']}/").json()["metres_per_pixel"] == before
    # so does a copy saved from it, and alice's own edit of her procedure
    copy = as_bob.post(f"/api/v1/procedures/{fork['code']}/save-as-new", {}, format="json").json()
    assert copy["metres_per_pixel"] == before
    as_alice.post(f"/api/v1/procedures/{proc.code}/parameters", {"values": {"window_height": 40}, "save": True},
                  format="json")
    proc.refresh_from_db()
    assert proc.metres_per_pixel == before


def test_a_new_real_size_rescales_the_owners_procedures_and_not_others_forks(scaled, as_alice, as_bob):
    photo, proc = scaled
    fork = as_bob.post(f"/api/v1/procedures/{proc.code}/fork").json()
    own = as_alice.post(f"/api/v1/procedures/{proc.code}/fork").json()  # alice's own fork follows her photo
    assert as_alice.patch(f"/api/v1/photos/{photo['code']}/", {"real_height_m": 30}, format="json").status_code == 200
    proc.refresh_from_db()
    assert proc.metres_per_pixel == pytest.approx(30 / proc.data["height"]) and "real height, 30 m" in proc.scale_from
    assert Procedure.objects.get(code=own["code"]).metres_per_pixel == proc.metres_per_pixel
    assert Procedure.objects.get(code=fork["code"]).metres_per_pixel == pytest.approx(REAL_WIDTH / proc.data["width"])
    assert as_alice.patch(f"/api/v1/photos/{photo['code']}/", {"real_height_m": None}, format="json").status_code == 200
    proc.refresh_from_db()
    assert (proc.metres_per_pixel, proc.scale_from) == (None, "")
    assert "a storey 3 m tall" in mesh_width(as_alice, proc.code)[1]


def test_its_owner_sets_or_clears_the_scale_and_bad_input_is_a_400(scaled, as_alice, as_bob):
    _, proc = scaled
    url = f"/api/v1/procedures/{proc.code}/"
    r = as_alice.patch(url, {"metres_per_pixel": 0.05}, format="json")
    assert r.status_code == 200
    assert (r.json()["metres_per_pixel"], r.json()["scale_from"]) == (0.05, "given by its owner")
    assert "0.05 m per pixel (given by its owner)" in mesh_width(as_alice, proc.code)[1]
    for bad in (0, -1, 1e6, "0.05", "abc", True, [0.05], {"m": 1}, "1e400"):
        r = as_alice.patch(url, {"metres_per_pixel": bad}, format="json")
        assert r.status_code == 400 and "metres_per_pixel" in r.json(), (bad, r.content)
    assert as_bob.patch(url, {"metres_per_pixel": 0.1}, format="json").status_code in (403, 404)
    r = as_alice.patch(url, {"metres_per_pixel": None}, format="json")
    assert r.status_code == 200 and (r.json()["metres_per_pixel"], r.json()["scale_from"]) == (None, "")
    # without a scale of its own, the photo's real size is still its owner's (who may see the photo), not bob's
    assert "the photo's real width, 22 m" in mesh_width(as_alice, proc.code)[1]
    assert "a storey 3 m tall" in mesh_width(as_bob, proc.code)[1]
    made = as_alice.post("/api/v1/procedures/", {"data": proc.data, "metres_per_pixel": 0.03}, format="json")
    assert made.status_code == 201 and made.json()["metres_per_pixel"] == 0.03
    r = as_alice.post("/api/v1/procedures/", {"data": proc.data, "metres_per_pixel": -2}, format="json")
    assert r.status_code == 400 and "metres_per_pixel" in r.json()


@pytest.mark.django_db(transaction=True)
def test_migration_0009_gives_procedures_their_photos_scale_where_it_discloses_nothing(alice, bob):
    from django.core.files.base import ContentFile
    from django.core.files.storage import default_storage
    from django.db import connection
    from django.db.migrations.executor import MigrationExecutor

    before = [("facades", "0008_stored_sizes")]
    executor = MigrationExecutor(connection)
    executor.migrate(before)
    old = executor.loader.project_state(before).apps
    png, _ = facade_png(3)
    tree = generate(3).procedure.to_dict()
    width, height = round(tree["width"]), round(tree["height"])
    OldPhoto, OldProcedure = old.get_model("facades", "Photo"), old.get_model("facades", "Procedure")

    def photo(visibility: str, real_width_m: float | None):
        name = default_storage.save("photos/p.png", ContentFile(png))
        return OldPhoto.objects.create(owner_id=alice.id, image=name, width=width, height=height,
                                       visibility=visibility, real_width_m=real_width_m)

    private, public, unsized = photo("private", 20.0), photo("public", 30.0), photo("private", None)

    def proc(owner, photo, visibility):
        return OldProcedure.objects.create(owner_id=owner.id, data=tree, digest="x", photo_id=photo.id,
                                           visibility=visibility).id

    cases = {proc(alice, private, "private"): 20.0, proc(alice, private, "public"): None,  # told it is not shown
             proc(alice, public, "public"): 30.0, proc(bob, public, "private"): 30.0,
             proc(bob, private, "private"): None,  # a fork of a photo bob may not see
             proc(alice, unsized, "private"): None}
    no_photo = OldProcedure.objects.create(owner_id=alice.id, data=tree, digest="x").id
    executor = MigrationExecutor(connection)
    executor.loader.build_graph()
    executor.migrate(executor.loader.graph.leaf_nodes())  # the schema at the leaf again, for the tests after
    for pk, metres in cases.items():
        got = Procedure.objects.get(id=pk)
        if metres is None:
            assert (got.metres_per_pixel, got.scale_from) == (None, ""), pk
        else:
            assert got.metres_per_pixel == pytest.approx(metres / width), pk
            assert got.scale_from == f"the photo's real width, {metres:g} m"
    assert Procedure.objects.get(id=no_photo).metres_per_pixel is None


@pytest.mark.django_db(transaction=True)
@pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")
def test_in_the_browser_a_fork_downloads_at_its_owners_size(scaled, live_server, browser, bob, tmp_path):
    """Bob, who may not see Alice's photo, forks her procedure from its page and downloads the fork's 3D relief: it
    is 22 m wide, as hers is, and the fork's page says where that size comes from (screenshot looked at)."""
    photo, proc = scaled
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    errors = collect_errors(page, [])
    login(page, live_server.url, "bob", "bob-password-1")
    page.goto(f"{live_server.url}/procedures/{proc.code}")
    page.click("form.inline button:has-text('Fork')")
    page.wait_for_url(re.compile(rf"/procedures/(?!{proc.code})[\w-]+"))
    assert page.url.rstrip("/").split("/")[-1] != str(proc.code)
    with page.expect_download() as download:
        page.click("a.button[href$='/download/mesh.zip']")
    with zipfile.ZipFile(download.value.path()) as z:
        obj = z.read("facade.obj").decode()
    xs = [float(line.split()[1]) for line in obj.splitlines() if line.startswith("v ")]
    assert max(xs) - min(xs) == pytest.approx(REAL_WIDTH, abs=0.01)
    assert "the photo's real width, 22 m" in page.content().replace("&#x27;", "'")
    page.screenshot(path=str(tmp_path / "fork.png"), full_page=True)
    if os.environ.get("FACAID_SCREENSHOTS"):
        shutil.copy(tmp_path / "fork.png", os.environ["FACAID_SCREENSHOTS"])
    assert errors == []
