"""What a request may cost: a tree is refused by its cost on every entry point, a request's trees by their sum and
its seconds, heavy requests past the process slots are a 503 while light pages answer; oversized bodies are refused
before they are read; a user has at most five jobs waiting or running; a database under another's write lock is a
503 to writers while reads go on."""

from __future__ import annotations

import io
import json
import socket

import pytest
from PIL import Image
from site_helpers import stored_counts, upload, wall

from facaid.generator import generate
from webapp.facades.models import Job, Photo, Procedure

pytestmark = pytest.mark.django_db


# --- what a tree costs ------------------------------------------------------------------------------------------------

def crafted() -> dict:
    """Issue 56's 2 KB tree: 256 x 256 repeats, each leaf under 29 one-child splits (2 million node instances)."""
    node = {"rule": "leaf", "label": "window"}
    for _ in range(29):
        node = {"rule": "split", "axis": "y", "sizes": [["flt", 1]], "children": [node]}
    inner = {"rule": "repeat", "axis": "y", "count": 256, "sizes": [["flt", 1]], "children": [node]}
    return {**wall(4096, 4096), "root": {"rule": "repeat", "axis": "x", "count": 256, "sizes": [["flt", 1]],
                                         "children": [inner]}}


def test_a_crafted_tree_is_refused_by_its_cost_on_every_entry_point_and_changes_nothing(as_alice, alice,
                                                                                        as_charlie):
    tree = crafted()
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public")
    before, stored = stored_counts(), proc.current_version().version
    answers = [as_charlie.post("/api/v1/render", tree, format="json"),
               as_alice.post("/api/v1/procedures/", {"data": tree}, format="json"),
               as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"data": tree}, format="json"),
               as_alice.post(f"/api/v1/procedures/{proc.code}/save-as-new", {"data": tree}, format="json"),
               as_charlie.post(f"/api/v1/procedures/{proc.code}/parameters", {"values": {}, "data": tree},
                               format="json")]
    for r in answers:
        assert r.status_code == 400 and "more than 100000 node instances" in json.dumps(r.json()), r.content[:300]
    assert stored_counts() == before and Procedure.objects.get(id=proc.id).current_version().version == stored


def test_a_request_that_makes_too_many_trees_is_a_400_naming_its_budget(as_charlie, alice, settings):
    """Each tree is bounded, and so is their sum in one request: setting many parameters of a tree at once makes a
    tree per value."""
    from facaid.grammar.layout import count_expansion

    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public")
    tree = generate(3).procedure
    settings.FACAID_REQUEST_WORK = 4 * count_expansion(tree.root, tree.width, tree.height).instances
    url = f"/api/v1/procedures/{proc.code}/parameters"
    r = as_charlie.post(url, {"values": {"width": tree.width + 20}}, format="json")
    assert r.status_code == 200, r.content[:300]
    values = {"width": tree.width + 20, "height": tree.height + 20, "floor_height": 90, "tile_width": 60}
    r = as_charlie.post(url, {"values": values}, format="json")
    assert r.status_code == 400 and "node instances in all" in r.json()["detail"], r.content[:300]
    r = as_charlie.get(f"/procedures/{proc.code}")
    assert r.status_code == 200  # the page itself stays in its budget
    settings.FACAID_REQUEST_WORK, settings.FACAID_REQUEST_SECONDS = 10**9, 1e-9
    r = as_charlie.post(url, {"values": {"width": tree.width + 20}}, format="json")
    assert r.status_code == 400 and "s of computing" in r.json()["detail"], r.content[:300]


def test_heavy_requests_past_the_process_slots_are_a_503_and_light_pages_answer(live_server, alice, settings):
    """With one heavy slot, a render in flight makes the next heavy request a 503 with Retry-After at once, and the
    gallery answers meanwhile (a burst of heavy requests leaves threads to the light pages)."""
    import threading
    import time
    import urllib.error
    import urllib.request

    settings.FACAID_HEAVY_SLOTS = 1
    settings.FACAID_API_HEAVY_RATE = None
    Procedure.objects.create(owner=alice, title="shown", data=wall(100, 100), visibility="public")
    tile = {"rule": "split", "axis": "x", "sizes": [["flt", 1], ["flt", 2], ["flt", 1]],
            "children": [{"rule": "leaf", "label": "facade"}, {"rule": "leaf", "label": "window"},
                         {"rule": "leaf", "label": "facade"}]}
    row = {"rule": "repeat", "axis": "x", "count": 150, "sizes": [["flt", 1]], "children": [tile]}
    big = {**wall(4000, 4000), "root": {"rule": "repeat", "axis": "y", "count": 150, "sizes": [["flt", 1]],
                                        "children": [row]}}

    def post(tree) -> tuple[int, str | None]:
        request = urllib.request.Request(f"{live_server.url}/api/v1/render", json.dumps(tree).encode(),
                                         {"Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(request, timeout=60) as r:
                return r.status, None
        except urllib.error.HTTPError as exc:
            assert exc.code != 503 or exc.headers.get("X-Facaid-Busy") == "slots"  # safe to send again
            return exc.code, exc.headers.get("Retry-After")

    heavy: list = []

    def patient():  # as the page does: wait as told when busy, until it is rendered
        while len(heavy) < 50 and (not heavy or heavy[-1][0] != 200):
            heavy.append(post(big))
            time.sleep(0.05)

    thread = threading.Thread(target=patient)
    thread.start()
    others, gallery = [], []
    while thread.is_alive() and len(others) < 500:
        others.append(post(wall(50, 50)))
        with urllib.request.urlopen(f"{live_server.url}/api/v1/gallery/", timeout=60) as r:
            gallery.append(r.status)
    thread.join()
    assert heavy[-1] == (200, None) and set(heavy[:-1]) <= {(503, "2")}
    assert (503, "2") in heavy + others and set(gallery) == {200}
    assert post(wall(50, 50)) == (200, None)  # every slot is given back


def test_a_user_has_at_most_five_jobs_waiting_or_running(facade_photo, as_alice, as_bob, settings):
    photo, seg = facade_photo
    codes = [as_alice.post("/api/v1/jobs/", {"segmentation": seg["code"], "k": 1}, format="json").status_code
             for _ in range(settings.FACAID_MAX_ACTIVE_JOBS)]
    assert codes == [202] * settings.FACAID_MAX_ACTIVE_JOBS
    r = as_alice.post("/api/v1/jobs/", {"segmentation": seg["code"], "k": 1}, format="json")
    assert r.status_code == 429 and "5 reconstructions waiting or running" in r.json()["detail"]
    r = as_alice.post(f"/photos/{photo['code']}/reconstruct", {"k": 1, "seed": 0}, follow=True)
    assert "5 reconstructions waiting or running" in r.content.decode()
    assert Job.objects.count() == 5
    Job.objects.filter(id=Job.objects.first().id).update(status="done")
    assert as_alice.post("/api/v1/jobs/", {"segmentation": seg["code"], "k": 1}, format="json").status_code == 202


# --- uploads --------------------------------------------------------------------------------------------------------

def test_a_photo_from_a_phone_in_mpo_is_taken_as_its_first_frame(as_alice):
    first, second = Image.new("RGB", (64, 48), (200, 10, 10)), Image.new("RGB", (64, 48), (10, 200, 10))
    out = io.BytesIO()
    first.save(out, "MPO", save_all=True, append_images=[second])
    assert Image.open(io.BytesIO(out.getvalue())).format == "MPO"
    r = upload(as_alice, out.getvalue(), name="IMG_0001.jpg")
    assert r.status_code == 201, r.content
    stored = Image.open(io.BytesIO(as_alice.get(r.json()["image"]).getvalue()))
    assert stored.format == "JPEG" and stored.size == (64, 48)
    red, green, _ = stored.getpixel((30, 20))
    assert red > 150 and green < 60


def test_an_oversized_body_is_refused_before_it_is_read(live_server, alice):
    """A 200 MB upload: the answer (413) comes after the headers and 1 MB, and the server reads no further."""
    host, port = live_server.url.removeprefix("http://").split(":")
    with socket.create_connection((host, int(port)), timeout=30) as s:
        s.sendall(b"POST /api/v1/photos/ HTTP/1.1\r\nHost: localhost\r\nContent-Type: multipart/form-data; "
                  b"boundary=x\r\nContent-Length: 209715200\r\n\r\n" + b"x" * (1 << 20))
        s.settimeout(10)
        answer = b""
        while b"accepted" not in answer:
            chunk = s.recv(65536)
            if not chunk:
                break
            answer += chunk
        answer = answer.decode("latin-1")
    assert answer.startswith("HTTP/1.1 413"), answer[:200]
    assert "at most 21 MB are accepted" in answer
    assert Photo.objects.count() == 0


def test_a_declared_length_over_the_limit_is_413_on_every_path(as_alice):
    for url in ("/api/v1/photos/", "/photos/new", "/api/v1/render"):
        r = as_alice.generic("POST", url, b"{}", content_type="multipart/form-data; boundary=x",
                             CONTENT_LENGTH=str(300 << 20))
        assert r.status_code == 413 and b"at most 21 MB are accepted for uploads" in r.content, url
    body = '{"a": "' + "x" * (5 << 20) + '"}'  # over the 4 MB of a JSON body, far under an upload's
    for client, url in ((as_alice, "/api/v1/procedures/"), (as_alice, "/api/v1/render")):
        r = client.post(url, body, content_type="application/json")
        assert r.status_code == 413 and "at most 4 MB are accepted for JSON" in r.json()["detail"], url
    r = as_alice.generic("POST", "/api/v1/render", b"{}", content_type="application/json", CONTENT_LENGTH="lots")
    assert r.status_code == 400


# --- the database under a write lock ------------------------------------------------------------------------------

SQLITE = "sqlite3" in __import__("django.conf").conf.settings.DATABASES["default"]["ENGINE"]


@pytest.mark.skipif(not SQLITE, reason="SQLite's locking")
@pytest.mark.django_db(transaction=True)
def test_reads_go_on_while_another_process_holds_the_write_lock(alice, as_alice, as_charlie):
    import sqlite3

    from django.db import connection

    Procedure.objects.create(owner=alice, title="Rivoli", data=wall(100, 100), visibility="public")
    options = connection.settings_dict["OPTIONS"]
    holder = sqlite3.connect(connection.settings_dict["NAME"], timeout=1, isolation_level=None)
    connection.close()
    options["timeout"] = 1  # a writer waits this long for the lock, then is told to come back
    holder.execute("BEGIN EXCLUSIVE")  # another process writing: without write-ahead logging, readers wait too
    holder.execute("UPDATE facades_procedure SET title = 'being written'")
    try:
        r = as_charlie.get("/api/v1/gallery/")
        assert r.status_code == 200 and r.json()["results"][0]["title"] == "Rivoli"  # the last committed state
        assert as_charlie.get("/").status_code == 200
        r = as_alice.post("/api/v1/procedures/", {"data": wall(10, 10)}, format="json")
        assert r.status_code == 503 and r["Retry-After"] == "5" and "busy" in r.json()["detail"]
    finally:
        holder.execute("ROLLBACK")
        holder.close()
        connection.close()
        options["timeout"] = 20
    assert as_alice.post("/api/v1/procedures/", {"data": wall(10, 10)}, format="json").status_code == 201
