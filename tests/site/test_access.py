"""Permissions with three users: alice owns, bob is another user, charlie is anonymous."""

import html
import json

import pytest

from webapp.facades.models import Job, Photo, Procedure

pytestmark = pytest.mark.django_db


def make_procedure(photo, seg, owner, visibility="private"):
    from facaid.generator import generate

    return Procedure.objects.create(owner=owner, title="p", data=generate(3).procedure.to_dict(),
                                    photo_id=photo, segmentation_id=seg, visibility=visibility)


@pytest.fixture
def objects(facade_photo, alice):
    from webapp.facades.models import Photo, Segmentation

    photo = Photo.objects.get(code=facade_photo[0]["code"])
    seg = Segmentation.objects.get(code=facade_photo[1]["code"])
    proc = make_procedure(photo.id, seg.id, alice)
    job = Job.objects.create(owner=alice, segmentation=seg)
    return photo, seg, proc, job


def urls(photo, seg, proc, job):
    return [f"/api/v1/photos/{photo.code}/", f"/api/v1/photos/{photo.code}/image",
            f"/api/v1/photos/{photo.code}/segmentations/", f"/api/v1/segmentations/{seg.code}/",
            f"/api/v1/procedures/{proc.code}/", f"/api/v1/procedures/{proc.code}/download/procedure.json",
            f"/photos/{photo.code}", f"/procedures/{proc.code}"]


def test_private_objects_are_404_to_others_and_200_to_the_owner(objects, as_alice, as_bob, as_charlie):
    photo, seg, proc, job = objects
    for url in urls(*objects):
        assert as_alice.get(url).status_code == 200, url
        assert as_bob.get(url).status_code == 404, url
        assert as_charlie.get(url).status_code == 404, url
    for client in (as_bob, as_charlie):
        assert client.get(f"/api/v1/jobs/{job.code}/").status_code == 404
        assert client.get(f"/jobs/{job.code}").status_code in (302, 404)
        assert client.patch(f"/api/v1/procedures/{proc.code}/", {"title": "x"}, format="json").status_code in (
            403, 404)
        assert client.delete(f"/api/v1/photos/{photo.code}/").status_code in (403, 404)
    assert as_alice.get(f"/api/v1/jobs/{job.code}/").status_code == 200
    assert as_bob.get("/api/v1/photos/not-a-uuid/").status_code == 404


def test_public_objects_are_readable_but_only_the_owner_changes_them(objects, as_alice, as_bob, as_charlie):
    photo, seg, proc, job = objects
    assert as_alice.patch(f"/api/v1/photos/{photo.code}/", {"visibility": "public"}, format="json").status_code == 200
    assert as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"visibility": "public"},
                          format="json").status_code == 200
    for url in urls(*objects)[:-2]:
        assert as_bob.get(url).status_code == 200, url
        assert as_charlie.get(url).status_code == 200, url
    assert as_bob.patch(f"/api/v1/procedures/{proc.code}/", {"title": "mine"}, format="json").status_code == 403
    assert as_bob.delete(f"/api/v1/photos/{photo.code}/").status_code == 403
    assert as_charlie.patch(f"/api/v1/procedures/{proc.code}/", {"title": "x"}, format="json").status_code in (
        401, 403)
    r = as_bob.post(f"/api/v1/photos/{photo.code}/segmentations/", seg.data, format="json")
    assert r.status_code == 403
    # the gallery lists public procedures only; unlisted ones are reachable by link but not listed
    assert [p["code"] for p in as_charlie.get("/api/v1/gallery/").json()["results"]] == [str(proc.code)]
    as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"visibility": "unlisted"}, format="json")
    assert as_charlie.get("/api/v1/gallery/").json()["count"] == 0
    assert as_charlie.get(f"/api/v1/procedures/{proc.code}/").status_code == 200


def test_fork_makes_a_private_copy_with_lineage(objects, as_alice, as_bob):
    photo, seg, proc, job = objects
    assert as_bob.post(f"/api/v1/procedures/{proc.code}/fork").status_code == 404  # private
    as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"visibility": "public"}, format="json")
    r = as_bob.post(f"/api/v1/procedures/{proc.code}/fork")
    assert r.status_code == 201
    fork = r.json()
    assert fork["owner"] == "bob" and fork["parent"] == str(proc.code) and fork["visibility"] == "private"
    assert fork["photo"] is None  # alice's photo is private: linked, but not shown to bob
    assert fork["data"] == proc.data
    r2 = as_bob.post(f"/api/v1/procedures/{fork['code']}/fork").json()
    page = as_bob.get(f"/procedures/{r2['code']}").content.decode()
    assert str(proc.code) in page and fork["code"] in page  # lineage shown
    assert as_bob.patch(f"/api/v1/procedures/{fork['code']}/", {"title": "bob's"}, format="json").status_code == 200


def test_lists_show_only_your_own(objects, as_alice, as_bob):
    assert as_alice.get("/api/v1/photos/").json()["count"] == 1
    assert as_bob.get("/api/v1/photos/").json()["count"] == 0
    assert as_bob.get("/api/v1/procedures/").json()["count"] == 0
    assert as_bob.get("/api/v1/jobs/").json()["count"] == 0


def fork_as_bob(as_bob, proc) -> Procedure:
    r = as_bob.post(f"/procedures/{proc.code}/fork")  # the page's button
    assert r.status_code == 302
    return Procedure.objects.get(code=r["Location"].rsplit("/", 1)[1])


def test_a_fork_keeps_the_overlay_and_rerun_while_the_photo_is_visible_to_the_forker(objects, as_alice, as_bob):
    photo, seg, proc, job = objects
    for obj in (photo, proc):
        obj.visibility = "public"
        obj.save()
    fork = fork_as_bob(as_bob, proc)
    assert (fork.photo_id, fork.segmentation_id, fork.owner.username) == (photo.id, seg.id, "bob")
    r = as_bob.get(f"/api/v1/procedures/{fork.code}/").json()
    assert (r["photo"], r["segmentation"]) == (str(photo.code), str(seg.code))
    page = as_bob.get(f"/procedures/{fork.code}").content.decode()
    assert f"/api/v1/photos/{photo.code}/image" in page and 'id="overlay"' in page  # the overlay
    assert "download/overlay.png" in page and "Re-run inference from a prefix" in page
    assert as_bob.get(f"/api/v1/procedures/{fork.code}/download/overlay.png").status_code == 200
    r = as_bob.post(f"/procedures/{fork.code}/rerun", {"nodes": 3})  # the page's re-run
    rerun = Job.objects.get(owner__username="bob")
    assert r["Location"] == f"/jobs/{rerun.code}" and rerun.segmentation_id == seg.id
    assert rerun.params["prefix_procedure"] == str(fork.code) and rerun.params["prefix_nodes"] == 3
    r = as_bob.post(f"/api/v1/procedures/{fork.code}/rerun", {"nodes": 2, "k": 2}, format="json")
    assert r.status_code == 202 and r.json()["segmentation"] == str(seg.code)
    assert as_bob.post(f"/api/v1/procedures/{fork.code}/fork").json()["photo"] == str(photo.code)  # forks of forks
    # bob's jobs on alice's photo are not listed to her; hers are
    mine = Job.objects.create(owner=proc.owner, segmentation=seg)
    page = as_alice.get(f"/photos/{photo.code}").content.decode()
    assert f"/jobs/{mine.code}" in page and f"/jobs/{rerun.code}" not in page

    # alice makes her photo private: bob's fork stops showing it, and re-running it is refused
    photo.visibility = "private"
    photo.save()
    page = as_bob.get(f"/procedures/{fork.code}").content.decode()
    assert str(photo.code) not in page and str(seg.code) not in page and "Re-run inference" not in page
    assert "once its owner shares it" in page and "overlay.png" not in page
    r = as_bob.get(f"/api/v1/procedures/{fork.code}/").json()
    assert (r["photo"], r["segmentation"]) == (None, None)
    assert as_bob.get(f"/api/v1/procedures/{fork.code}/download/overlay.png").status_code == 400
    before = Job.objects.count()
    r = as_bob.post(f"/api/v1/procedures/{fork.code}/rerun", {"nodes": 2}, format="json")
    assert r.status_code == 400 and "is not shared with you" in r.json()["procedure"]
    r = as_bob.post(f"/procedures/{fork.code}/rerun", {"nodes": 2}, follow=True)
    assert "is not shared with you" in r.content.decode() and Job.objects.count() == before


def test_a_fork_of_a_procedure_whose_photo_is_private_shows_it_once_shared(objects, as_alice, as_bob, as_charlie):
    photo, seg, proc, job = objects  # alice's photo stays private; her procedure made from it is public
    proc.visibility = "public"
    proc.save()
    fork = fork_as_bob(as_bob, proc)
    assert (fork.photo_id, fork.segmentation_id) == (photo.id, seg.id)  # linked, and shown only while shared

    def shown(client, code) -> bool:
        r = client.get(f"/api/v1/procedures/{code}/").json()
        page = client.get(f"/procedures/{code}").content.decode()
        overlay = client.get(f"/api/v1/procedures/{code}/download/overlay.png").status_code
        names = str(photo.code) in page or str(seg.code) in page
        assert names == ('id="overlay"' in page) == (overlay == 200) == (r["photo"] is not None)
        assert (overlay == 200) != (overlay == 400)
        return r["photo"] == str(photo.code) and r["segmentation"] == str(seg.code)

    assert not shown(as_bob, fork.code)
    page = as_bob.get(f"/procedures/{fork.code}").content.decode()
    assert 'id="photo-hidden"' in page and "once its owner shares it" in page and "Re-run inference" not in page
    r = as_bob.post(f"/api/v1/procedures/{fork.code}/rerun", {"nodes": 2}, format="json")
    assert r.status_code == 400 and "is not shared with you" in r.json()["procedure"]
    mine = as_bob.get(f"/api/v1/procedures/{fork.code}/").json()
    assert (mine["photo_shared"], mine["viewers_see"]) == (False, "Only you see this procedure.")
    # an edited tree is not measured against the segmentation bob may not see: no figure tells him about it
    edited = json.loads(json.dumps(mine["data"]))
    edited["meta"] = {"probe": 1}
    edited["root"]["sizes"][0][1] += 3
    r = as_bob.patch(f"/api/v1/procedures/{fork.code}/", {"data": edited}, format="json").json()
    assert r["accuracy"] is None and "iou" not in r["metrics"]
    assert r["metrics"]["unmeasured"] == "the photo it was made from is not shared with you"
    as_bob.patch(f"/api/v1/procedures/{fork.code}/", {"visibility": "public"}, format="json")
    assert not shown(as_charlie, fork.code)
    assert "No photo to overlay" in as_charlie.get(f"/procedures/{fork.code}").content.decode()
    assert as_charlie.get(f"/api/v1/procedures/{fork.code}/").json()["photo_shared"] is None  # not the owner's

    # alice shares her photo: bob's fork, made before, shows it to bob and to everyone, and re-runs
    photo.visibility = "public"
    photo.save()
    assert shown(as_bob, fork.code) and shown(as_charlie, fork.code)
    assert "Re-run inference" in as_bob.get(f"/procedures/{fork.code}").content.decode()
    assert as_bob.post(f"/api/v1/procedures/{fork.code}/rerun", {"nodes": 2}, format="json").status_code == 202
    edited["root"]["sizes"][0][1] -= 3
    r = as_bob.patch(f"/api/v1/procedures/{fork.code}/", {"data": edited}, format="json").json()
    assert r["accuracy"] is not None and "unmeasured" not in r["metrics"]  # shared now: measured
    # and hides it again: never shown while private
    photo.visibility = "private"
    photo.save()
    assert not shown(as_bob, fork.code) and not shown(as_charlie, fork.code)
    r = as_alice.post(f"/api/v1/procedures/{proc.code}/fork")  # alice's own fork shows her photo, private as it is
    assert r.status_code == 201 and r.json()["photo"] == str(photo.code)


def test_sharing_a_procedure_asks_about_its_photo_and_says_what_viewers_see(objects, as_alice, as_bob, as_charlie):
    photo, seg, proc, job = objects  # both alice's and private
    url = f"/api/v1/procedures/{proc.code}/"
    r = as_alice.patch(url, {"visibility": "public"}, format="json").json()
    # the question and the answer say plainly that the procedure itself redraws the annotation (issue 66)
    assert (r["photo_shared"], r["viewers_see"]) == (False, (
        "Anyone sees the procedure, its pictures and 3D models, but not the photo or the overlay: the photo is "
        "private. The procedure itself redraws the annotation (an exact version reproduces it as drawn) at its "
        "size in metres; the photo's title and the accuracy against it are not shown."))
    assert as_charlie.get(url).json()["photo"] is None
    page = html.unescape(as_alice.get(f"/procedures/{proc.code}").content.decode())
    assert 'id="share-photo"' in page and r["viewers_see"] in page
    assert "(the photo is private; either way the procedure itself redraws the annotation)" in page
    previews = json.loads(page.split('id="sharing-previews"', 1)[1].split(">", 1)[1].split("</script>", 1)[0])
    assert previews["public"] == previews["unlisted"].replace("Anyone with its link", "Anyone") == r["viewers_see"]
    r = as_alice.post(f"/procedures/{proc.code}/visibility", {"visibility": "unlisted"}, follow=True)
    assert "The procedure is now unlisted. Anyone with its link sees the procedure, its pictures and 3D models, but " \
           "not the photo or the overlay: the photo is private. The procedure itself redraws the annotation" in (
               html.unescape(r.content.decode()))
    # unlisted with its photo: the photo becomes unlisted too
    r = as_alice.patch(url, {"visibility": "unlisted", "share_photo": True}, format="json").json()
    photo.refresh_from_db()
    assert (photo.visibility, r["photo_shared"]) == ("unlisted", True)
    assert r["viewers_see"] == "Anyone with its link sees the procedure with its photo and the overlay."
    r = as_alice.patch(url, {"visibility": "public"}, format="json").json()  # the photo stays unlisted: it shows
    assert r["photo_shared"] is True and r["viewers_see"] == (
        "Anyone sees the procedure with its photo and the overlay (the photo is unlisted: its page is not in the "
        "gallery).")
    assert as_charlie.get(url).json()["photo"] == str(photo.code)
    # the page's form: public, and the photo with it
    r = as_alice.post(f"/procedures/{proc.code}/visibility", {"visibility": "public", "share_photo": "on"},
                      follow=True)
    photo.refresh_from_db()
    assert photo.visibility == "public"
    assert "The procedure is now public. Anyone sees the procedure with its photo and the overlay." in (
        r.content.decode())
    assert as_charlie.get(url).json()["photo"] == str(photo.code)
    assert as_charlie.get(url + "download/overlay.png").status_code == 200
    assert 'id="share-photo"' not in as_alice.get(f"/procedures/{proc.code}").content.decode()  # nothing to ask
    # making the procedure private again leaves the photo as it is (it may be shared for itself)
    as_alice.patch(url, {"visibility": "private"}, format="json")
    photo.refresh_from_db()
    assert photo.visibility == "public"


def test_only_the_photos_owner_shares_it_and_a_refusal_changes_nothing(objects, as_alice, as_bob):
    photo, seg, proc, job = objects
    proc.visibility = "public"
    proc.save()
    fork = fork_as_bob(as_bob, proc)
    url = f"/api/v1/procedures/{fork.code}/"
    r = as_bob.patch(url, {"visibility": "public", "title": "bob's", "share_photo": True}, format="json")
    assert r.status_code == 400 and r.json() == {"share_photo": "the photo is alice's: only they can share it"}
    fork.refresh_from_db()
    photo.refresh_from_db()
    assert (fork.visibility, fork.title, photo.visibility) == ("private", "Fork of p", "private")
    r = as_bob.patch(url, {"visibility": "public"}, format="json").json()
    assert "the photo is private (it is alice's: only they can share it). The procedure itself redraws the " \
           "annotation" in r["viewers_see"]
    assert 'id="share-photo"' not in as_bob.get(f"/procedures/{fork.code}").content.decode()
    r = as_bob.post(f"/procedures/{fork.code}/visibility", {"visibility": "public", "share_photo": "on"},
                    follow=True)
    assert "share_photo: the photo is alice&#x27;s: only they can share it" in r.content.decode()
    bare = make_procedure(None, None, proc.owner)
    r = as_alice.patch(f"/api/v1/procedures/{bare.code}/", {"share_photo": True}, format="json")
    assert r.status_code == 400 and r.json() == {"share_photo": "this procedure has no photo to share"}
    r = as_alice.patch(f"/api/v1/procedures/{bare.code}/", {"visibility": "public"}, format="json").json()
    assert r["viewers_see"] == "Anyone sees the procedure, its pictures and 3D models; it has no photo."


def test_a_forks_rerun_stores_nothing_once_its_photo_is_made_private(objects, as_alice, as_bob, monkeypatch):
    """Issue 66, 7: bob re-runs his fork while alice's photo is shared, and alice makes it private while the job runs
    (at its first progress beat, through the API). The worker's task, run in this process as the worker runs it,
    reads the photo again as it stores: it fails the job and stores nothing, and the job's JSON no longer names the
    segmentation."""
    from webapp.facades.services import jobs
    from worker import tasks

    monkeypatch.setenv("FACAID_HEARTBEAT_SECONDS", "3600")  # the progress beats are enough here
    photo, seg, proc, job = objects
    for obj in (photo, proc):
        obj.visibility = "public"
        obj.save()
    fork = fork_as_bob(as_bob, proc)
    photo_url = f"/api/v1/photos/{photo.code}/"

    def rerun() -> Job:
        r = as_bob.post(f"/api/v1/procedures/{fork.code}/rerun", {"nodes": 2, "k": 1}, format="json")
        assert r.status_code == 202 and r.json()["segmentation"] == str(seg.code)
        return Job.objects.get(code=r.json()["code"])

    # shared throughout: the re-run is the fork's next version (the control)
    done = rerun()
    tasks.run_job.apply(args=[done.id])
    done.refresh_from_db()
    assert (done.status, done.result_id, done.result_version) == ("done", fork.id, 2), done.message

    racing, beat = rerun(), jobs.beat

    def made_private_while_running(job_id, progress=None, stage=None):
        if progress is not None and Photo.objects.get(id=photo.id).visibility == "public":
            assert as_alice.patch(photo_url, {"visibility": "private"}, format="json").status_code == 200
        beat(job_id, progress, stage)

    monkeypatch.setattr(jobs, "beat", made_private_while_running)
    tasks.run_job.apply(args=[racing.id])
    racing.refresh_from_db()
    assert racing.status == "failed" and racing.message == tasks.MADE_PRIVATE
    assert racing.result_id is None and fork.versions.count() == 2 and Procedure.objects.count() == 2
    body = as_bob.get(f"/api/v1/jobs/{racing.code}/").json()
    assert body["status"] == "failed" and body["segmentation"] is None and str(seg.code) not in json.dumps(body)
    assert all(j["segmentation"] is None for j in as_bob.get("/api/v1/jobs/").json()["results"])
    assert str(seg.code) not in as_bob.get(f"/jobs/{racing.code}").content.decode()

    # shared again for a re-run that waits in the queue, made private before a worker takes it: not even computed
    monkeypatch.setattr(jobs, "beat", beat)
    as_alice.patch(photo_url, {"visibility": "public"}, format="json")
    queued = rerun()
    as_alice.patch(photo_url, {"visibility": "private"}, format="json")
    tasks.run_job.apply(args=[queued.id])
    queued.refresh_from_db()
    assert (queued.status, queued.message, queued.progress) == ("failed", tasks.MADE_PRIVATE, 0.0)
    assert fork.versions.count() == 2
