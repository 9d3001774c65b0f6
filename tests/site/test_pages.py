"""The pages: sign up, log in, upload, photo, job, procedure; and the demo command."""

import pytest
from django.core.files.uploadedfile import SimpleUploadedFile
from django.core.management import call_command
from django.test import Client
from site_helpers import facade_png

from webapp.facades.models import Job, Photo, Procedure

pytestmark = pytest.mark.django_db


def test_signup_login_logout():
    c = Client()
    r = c.post("/accounts/signup/", {"username": "dora", "email": "d@example.com", "password1": "a-long-secret-9",
                                     "password2": "a-long-secret-9"})
    assert r.status_code == 302
    assert "dora" in c.get("/").content.decode()
    c.post("/accounts/logout/")
    assert "Log in" in c.get("/").content.decode()
    r = c.post("/accounts/login/", {"username": "dora", "password": "wrong"})
    assert r.status_code == 200 and "correct" in r.content.decode()
    assert c.post("/accounts/login/", {"username": "dora", "password": "a-long-secret-9"}).status_code == 302


def test_signup_goes_where_it_was_asked_to_and_only_on_this_site():
    """A newcomer's "Sign up and upload a photo" landed on the front page, not on the upload form."""
    fields = {"email": "e@example.com", "password1": "a-long-secret-9", "password2": "a-long-secret-9"}
    c = Client()
    page = c.get("/accounts/signup/?next=/photos/new").content.decode()
    assert '<input type="hidden" name="next" value="/photos/new">' in page
    r = c.post("/accounts/signup/", {**fields, "username": "erin", "next": "/photos/new"})
    assert (r.status_code, r["Location"]) == (302, "/photos/new")
    r = Client().post("/accounts/signup/?next=https://elsewhere.example/x", {**fields, "username": "fay"})
    assert (r.status_code, r["Location"]) == (302, "/")  # never to another site


def test_upload_page_and_photo_page_flow(alice):
    c = Client()
    c.force_login(alice)
    r = c.post("/photos/new", {"image": SimpleUploadedFile("x.txt", b"hello"), "visibility": "private"})
    assert r.status_code == 400 and "not an image" in r.content.decode()
    data, seg = facade_png()
    r = c.post("/photos/new", {"image": SimpleUploadedFile("f.png", data), "title": "Mine", "visibility": "public"})
    photo = Photo.objects.get(title="Mine")
    assert r.status_code == 302 and r["Location"] == f"/photos/{photo.code}"
    import json

    r = c.post(f"/photos/{photo.code}/segmentation", {"text": "{bad json"}, follow=True)
    assert "not valid JSON" in r.content.decode()
    # the photo picked instead of its annotations is named as such (a newcomer read a UTF-8 codec error)
    r = c.post(f"/photos/{photo.code}/segmentation", {"file": SimpleUploadedFile("f.png", data)}, follow=True)
    assert "this is a PNG image, not annotations: annotations are our segmentation JSON" in r.content.decode()
    assert 'accept=".json,.xml,application/json,text/xml"' in c.get(f"/photos/{photo.code}").content.decode()
    r = c.post("/api/v1/convert", {"text": data.decode("latin-1")}, content_type="application/json")
    assert r.status_code == 400 and r.json()["text"] == [
        "this is a binary file, not annotations: annotations are our segmentation JSON, COCO or LabelMe JSON, or "
        "CVAT XML (docs/interchange.md)"]
    r = c.post(f"/photos/{photo.code}/segmentation", {"text": json.dumps(seg)}, follow=True)
    assert "version 1 saved" in r.content.decode()
    r = c.post(f"/photos/{photo.code}/reconstruct", {"k": 2, "seed": 0})
    job = Job.objects.get()
    assert r["Location"] == f"/jobs/{job.code}"
    assert "queued" in c.get(r["Location"]).content.decode()
    assert Client().get(f"/photos/{photo.code}").status_code == 200  # public
    assert c.post(f"/photos/{photo.code}/visibility", {"visibility": "private"}).status_code == 302
    assert Client().get(f"/photos/{photo.code}").status_code == 404


def test_demo_command_is_idempotent(capsys):
    call_command("demo")
    call_command("demo")
    assert Photo.objects.count() == 1 and Job.objects.count() == 1
    photo = Photo.objects.get()
    assert photo.visibility == "public" and photo.width > 0 and photo.latest_segmentation().rect_count > 10
    assert "demo / demo-facade" in capsys.readouterr().out


def test_procedure_page_for_owner_and_visitor(alice):
    from facaid.generator import generate

    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public")
    owner = Client()
    owner.force_login(alice)
    page = owner.get(f"/procedures/{proc.code}").content.decode()
    assert "Save changes" in page and "procedure-data" in page
    visitor = Client().get(f"/procedures/{proc.code}").content.decode()
    assert "Save changes" not in visitor and "to fork this procedure" in visitor
    # no photo: every download but the overlay, the SVG among them
    assert "download/labels.svg" in visitor and "download/labels.png" in visitor and "overlay.png" not in visitor
    assert "download/procedure.cga" in visitor and "download/mesh.zip" in visitor
    assert "CityEngine CGA rules" in visitor and "for Blender and other 3D tools" in visitor  # each says what it is


def test_the_procedure_pages_3d_panel_loads_three_js_from_this_site(alice):
    import json
    import re

    from facaid.generator import generate

    data, _ = facade_png()
    photo = Photo.objects.create(owner=alice, title="Generated facade", image=SimpleUploadedFile("f.png", data))
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public", photo=photo)
    owner = Client()
    owner.force_login(alice)
    for client, photo_visible in ((owner, True), (Client(), False)):  # the photo is private: the owner's glTF only
        r = client.get(f"/procedures/{proc.code}")
        html = r.content.decode()
        nonce, imports = re.search(r'<script type="importmap" nonce="([^"]+)">(.*?)</script>', html, re.S).groups()
        assert f"script-src 'self' 'nonce-{nonce}';" in r["Content-Security-Policy"]  # the only inline script
        imports = json.loads(imports)["imports"]
        assert imports == {"three": "/static/vendor/three/build/three.module.js",
                           "three/addons/": "/static/vendor/three/examples/jsm/"}
        panel = re.search(r'<details class="panel preview3d" id="preview3d"([^>]*)>', html).group(1)
        assert f'data-glb="/api/v1/procedures/{proc.code}/download/facade.glb"' in panel
        assert ("facade-photo.glb" in panel) == photo_visible == ('id="preview3d-photo"' in html)
        assert '<script type="module" src="/static/app/procedure/preview3d.js">' in html


def test_the_api_docs_page_names_only_files_of_this_site():
    import re

    from django.contrib.staticfiles import finders

    r = Client().get("/api/v1/docs")
    assert r.status_code == 200 and r["Content-Type"].startswith("text/html")
    assert r["Cross-Origin-Opener-Policy"] == "same-origin"  # the site's, not drf-spectacular's unsafe-none
    html = r.content.decode()
    assert '<header class="top">' in html and '<script src="/api/v1/docs?script="></script>' in html
    script = Client().get("/api/v1/docs?script=")  # Swagger UI's set-up, a file of its own: the CSP runs no inline one
    assert script["Content-Type"].startswith("application/javascript") and "SwaggerUIBundle" in script.text
    urls = re.findall(r'(?:src|href)="([^"]*)"', html) + re.findall(r'url: "([^"]*)"', script.text)
    assert len(urls) > 5
    for url in urls:
        assert url.startswith("/") and not url.startswith("//") or url.startswith("data:"), url
    assert not re.search(r"https?://|//cdn|jsdelivr|unpkg|googleapis", html.replace("http://www.w3.org/2000/svg", ""))
    statics = [u for u in urls if u.startswith("/static/drf_spectacular_sidecar/")]
    assert len(statics) == 2  # Swagger UI's CSS and JS
    for url in statics:
        assert finders.find(url.removeprefix("/static/")), url
    # the footer's link goes to the page; the schema it reads stays a YAML file
    assert 'href="/api/v1/docs">API docs</a>' in Client().get("/").content.decode()
    r = Client().get("/api/v1/schema")
    assert r.status_code == 200 and r["Content-Type"].startswith("application/vnd.oai.openapi")
    assert r.content.startswith(b"openapi:")


def test_jobs_are_named_by_their_photo(alice, bob):
    import re

    data, seg = facade_png()
    owner = Client()
    owner.force_login(alice)
    named = Photo.objects.create(owner=alice, title="Rue de Rivoli", image=SimpleUploadedFile("a.png", data))
    untitled = Photo.objects.create(owner=alice, image=SimpleUploadedFile("b.png", data))
    jobs = {}
    for photo in (named, untitled):
        version = photo.segmentations.create(version=1, data=seg, rect_count=len(seg["rects"]))
        jobs[photo.pk] = Job.objects.create(owner=alice, segmentation=version)
    untitled_name = f"untitled photo {str(untitled.code)[:8]}"

    def link_text(html: str, job: Job) -> str:
        return re.search(rf'<a href="/jobs/{job.code}">([^<]*)</a>', html).group(1)

    home = owner.get("/").content.decode()
    assert link_text(home, jobs[named.pk]) == "Rue de Rivoli" and link_text(home, jobs[untitled.pk]) == untitled_name
    for job in jobs.values():
        assert str(job.code)[:8] not in home.replace(f"/jobs/{job.code}", "")  # named, not coded
    page = owner.get(f"/photos/{named.code}").content.decode()
    assert link_text(page, jobs[named.pk]) == "Rue de Rivoli" and "segmentation v1" in page
    page = owner.get(f"/jobs/{jobs[named.pk].code}").content.decode()
    assert "<h1>Reconstruction of Rue de Rivoli</h1>" in page and f'href="/photos/{named.code}"' in page
    page = owner.get(f"/jobs/{jobs[untitled.pk].code}").content.decode()
    assert f"<h1>Reconstruction of {untitled_name}</h1>" in page
    # a job of bob's on a photo he may no longer see (a fork's re-run, the photo made private since) names nothing
    other = Job.objects.create(owner=bob, segmentation=named.latest_segmentation())
    visitor = Client()
    visitor.force_login(bob)
    for page in (visitor.get("/").content.decode(), visitor.get(f"/jobs/{other.code}").content.decode()):
        assert "a photo not shared with you" in page
        assert "Rivoli" not in page and str(named.code) not in page


def test_cards_say_pixel_accuracy_and_the_photo_page_links_to_the_rectification(alice, bob):
    """Issue 58: "0.997 acc." said nothing to a newcomer; the photo page pointed at a control it does not have."""
    from facaid.generator import generate

    data, _ = facade_png()
    photo = Photo.objects.create(owner=alice, title="Mine", visibility="public",
                                 image=SimpleUploadedFile("f.png", data))
    Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public", accuracy=0.99712)
    home = Client().get("/").content.decode()
    assert "pixel accuracy 99.7 %" in home and " acc." not in home
    assert 'title="The share of the photo\'s pixels' in home
    owner = Client()
    owner.force_login(alice)
    page = owner.get(f"/photos/{photo.code}").content.decode()
    assert f'href="/photos/{photo.code}/edit#rectify">Rectify it in the editor</a>' in page
    visitor = Client()
    visitor.force_login(bob)
    assert "Rectify it in the editor" not in visitor.get(f"/photos/{photo.code}").content.decode()


def _distinct_colours(image_bytes: bytes) -> int:
    import io

    import numpy as np
    from PIL import Image

    pixels = np.asarray(Image.open(io.BytesIO(image_bytes)).convert("RGB")).reshape(-1, 3)
    return len(np.unique(pixels, axis=0))


def test_the_front_page_shows_a_newcomer_what_it_does_from_the_demo(alice, bob):
    """Issue 58: the front page was a bare gallery. A newcomer sees the demo's photo -> procedure -> variations,
    and a first step: sign up and upload, or try the demo without an account."""
    from django.core.cache import caches

    from facaid.editing.parameters import named_parameters
    from facaid.generator import generate
    from facaid.grammar import Procedure as Tree
    from webapp.facades.example import VARIANTS

    home = Client().get("/").content.decode()
    assert 'id="intro"' in home and 'href="/accounts/signup/?next=/photos/new">Sign up and upload a photo' in home
    assert 'id="example"' not in home and 'id="try-demo"' not in home  # no demo procedure yet
    call_command("demo")
    photo = Photo.objects.get()
    assert _distinct_colours(photo.image.read()) > 1000  # a photo-like picture, not the 12 colours of a label map
    proc = Procedure.objects.create(owner=photo.owner, data=generate(3).procedure.to_dict(), visibility="public",
                                    photo=photo, accuracy=0.9987)  # what the worker makes of it
    home = Client().get("/").content.decode()
    assert f'<img src="/api/v1/photos/{photo.code}/image"' in home
    assert f'src="/api/v1/procedures/{proc.code}/thumbnail.png"' in home and "pixel accuracy 99.9 %" in home
    assert home.count('src="data:image/png;base64,') == VARIANTS
    assert f'id="try-demo" href="/procedures/{proc.code}">Try the demo</a>' in home
    floors = next(p for p in named_parameters(Tree.from_dict(proc.data)) if p.name == "floors")
    assert f"{floors.value:g} upper floors" in home
    assert Client().get(f"/procedures/{proc.code}").status_code == 200  # the demo is open to anyone
    assert len(caches["pages"].get(f"front-example:{proc.code}:{proc.digest}")["variations"]) == VARIANTS
    c = Client()
    c.force_login(bob)  # logged in, no photo yet: the example, and an upload button
    page = c.get("/").content.decode()
    assert 'id="example"' in page and 'href="/photos/new">Upload a photo' in page
    Photo.objects.create(owner=bob, title="Mine", image=SimpleUploadedFile("f.png", facade_png()[0]))
    assert 'id="intro"' not in c.get("/").content.decode()  # not a newcomer any more
