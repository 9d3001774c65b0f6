"""The 3D downloads of a procedure (glTF, glTF with the photo, IFC, CityJSON): served with their content types,
read back by their formats' readers (the CityJSON valid by `facaid validate-cityjson`), at the scale asked for,
and a bad parameter or a procedure too large a 400 (alice owns, charlie is anonymous)."""

import io
import json

import ifcopenshell
import pytest
import trimesh
from format_helpers import window_grid

from facaid.formats.cityjson_check import check_cityjson
from facaid.formats.relief import procedure_relief
from facaid.generator import generate
from facaid.labels import LABEL_ID

pytestmark = pytest.mark.django_db

THREE_D = {"facade.glb": "model/gltf-binary", "facade.gltf": "model/gltf+json",
           "facade-photo.glb": "model/gltf-binary", "facade.ifc": "application/x-step",
           "facade.city.json": "application/city+json"}


@pytest.fixture
def procedure(facade_photo, alice):
    from webapp.facades.models import Photo, Procedure

    photo, _ = facade_photo
    return Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public",
                                    photo=Photo.objects.get(code=photo["code"]))


def labelled_nodes(content: bytes, kind: str) -> int:
    scene = trimesh.load(io.BytesIO(content), file_type=kind, force="scene")
    labelled = {node: parent for (parent, node), d in scene.graph.transforms.edge_data.items()
                if "label" in d.get("metadata", {})}
    return sum(parent not in labelled for parent in labelled.values())  # not the frames of a node's primitives


def test_each_3d_download_reads_back_at_the_scale_asked(procedure, as_alice, tmp_path):
    rects = procedure_relief(generate(3).procedure, 0.02).rows  # the elements every export holds, and the wall
    windows = sum(r[0] == LABEL_ID["window"] for r in rects.tolist())
    base = f"/api/v1/procedures/{procedure.code}/download/"
    got = {}
    for name, content_type in THREE_D.items():
        r = as_alice.get(base + name + "?metres_per_pixel=0.02")
        assert r.status_code == 200 and r["Content-Type"] == content_type, name
        assert r["Content-Disposition"].endswith(f'-{name}"')
        got[name] = r.content
    assert labelled_nodes(got["facade.glb"], "glb") == labelled_nodes(got["facade.gltf"], "gltf") == len(rects)
    textured = trimesh.load(io.BytesIO(got["facade-photo.glb"]), file_type="glb", force="scene")
    assert sum(getattr(g.visual, "uv", None) is not None for g in textured.geometry.values()) == len(rects)
    assert json.loads(got["facade.gltf"])["asset"]["extras"]["facaid"]["metres_per_pixel"] == 0.02
    path = tmp_path / "f.ifc"
    path.write_bytes(got["facade.ifc"])
    model = ifcopenshell.open(str(path))
    assert sum(w.PredefinedType == "WINDOW" for w in model.by_type("IfcWindow")) == windows
    assert "0.02 m per pixel (given)" in model.by_type("IfcProject")[0].Description
    report = check_cityjson(got["facade.city.json"])
    assert (report.valid, report.version, report.warnings) == (True, "2.0", [])
    city = json.loads(got["facade.city.json"])
    building = city["CityObjects"]["facade"]
    assert building["attributes"]["facaid_metres_per_pixel"] == 0.02
    assert sum(s["type"] == "Window" and s["label"] == "window"
               for s in building["geometry"][0]["semantics"]["surfaces"]) == windows


def test_bad_parameters_and_too_large_procedures_are_a_400(procedure, as_alice, alice):
    from webapp.facades.models import Procedure

    base = f"/api/v1/procedures/{procedure.code}/download/"
    for name in THREE_D:
        for bad in ("0", "-1", "nan", "abc", "1e9"):
            r = as_alice.get(base + f"{name}?metres_per_pixel={bad}")
            assert r.status_code == 400 and "metres_per_pixel" in r.json(), (name, bad)
    huge = Procedure.objects.create(owner=alice, data=window_grid(200, 60).to_dict())
    for name in ("facade.glb", "facade.gltf", "facade.city.json"):
        r = as_alice.get(f"/api/v1/procedures/{huge.code}/download/{name}")
        assert r.status_code == 400 and "24000 rectangles" in r.json()["name"], name
    r = as_alice.get(f"/api/v1/procedures/{huge.code}/download/facade.ifc")  # 20,000 of them: past the budget
    assert r.status_code == 400 and "node instances in all" in r.json()["detail"]


def test_the_page_offers_them_with_their_scale_and_the_photo_only_to_who_sees_it(procedure, as_alice, as_charlie):
    from facaid.formats.cga import default_scale

    page = as_charlie.get(f"/procedures/{procedure.code}").content.decode()
    for name in ("facade.glb", "facade.gltf", "facade.ifc", "facade.city.json"):
        assert f'download/{name}" data-scaled>' in page, name
    assert "download/facade-photo.glb" not in page  # alice's photo is private
    assert as_charlie.get(f"/api/v1/procedures/{procedure.code}/download/facade-photo.glb").status_code == 400
    scale = default_scale(generate(3).procedure)
    assert f"a storey is 3 m tall: {scale:.5f} m per pixel" in page
    assert "in metres at that scale, which the file states" in page
    assert "download/facade-photo.glb" in as_alice.get(f"/procedures/{procedure.code}").content.decode()


def test_facaid_export_writes_every_site_download(procedure, as_alice, tmp_path, capsys):
    """The command line offers the site's set: each download has an extension of `facaid export`, and the files in
    pixels hold the same picture or rectangles as the downloads (the OBJ and its MTL come zipped from the site)."""
    import numpy as np
    from PIL import Image

    from facaid.cli import main
    from facaid.formats.exports import export_for
    from facaid.formats.interchange import read
    from webapp.facades.downloads import DOWNLOADS

    cli = {"procedure.json": ".json", "segmentation.json": ".segmentation.json", "segmentation.coco.json": ".coco.json",
           "segmentation.labelme.json": ".labelme.json", "segmentation.cvat.xml": ".cvat.xml", "labels.png": ".png",
           "labels.svg": ".svg", "procedure.cga": ".cga", "mesh.zip": ".obj", "facade.glb": ".glb",
           "facade.gltf": ".gltf", "facade-photo.glb": ".glb", "facade.ifc": ".ifc", "facade.city.json": ".city.json",
           "overlay.png": ".overlay.png"}  # the OBJ and its MTL are zipped there; the textured .glb takes --photo
    assert set(cli) == set(DOWNLOADS)  # a new download needs its extension here and in facaid.formats.exports
    assert all(export_for(f"facade.{name}")[0] == ext for name, ext in cli.items() if name != "mesh.zip")
    source = tmp_path / "p.json"
    source.write_text(json.dumps(procedure.data))
    photo = tmp_path / "photo.png"
    base = f"/api/v1/procedures/{procedure.code}/download/"
    with procedure.photo.working_image().open("rb") as f:
        Image.open(f).convert("RGB").save(photo)
    size = (round(procedure.data["width"]), round(procedure.data["height"]))
    for name in ("segmentation.json", "segmentation.coco.json", "segmentation.labelme.json", "segmentation.cvat.xml",
                 "labels.png", "labels.svg", "overlay.png", "procedure.json"):
        out = tmp_path / f"facade.{name}"
        assert main(["export", str(source), "--out", str(out), *(["--photo", str(photo)] if name == "overlay.png"
                                                                  else [])]) == 0, name
        site = as_alice.get(base + name)
        assert site.status_code == 200, name
        if name.endswith(".png"):
            a = np.asarray(Image.open(out).convert("RGB"), dtype=int)
            b = np.asarray(Image.open(io.BytesIO(site.content)).convert("RGB"), dtype=int)
            assert a.shape == b.shape and np.abs(a - b).max() <= 2, name  # the same picture (resampling aside)
        elif name == "labels.svg":
            assert out.read_bytes() == site.content
        elif name == "procedure.json":
            assert json.loads(out.read_text()) == json.loads(site.content)
        else:
            assert read(out.read_bytes(), size=size) == read(site.content, size=size), name
    # the annotation formats hold one box per element, the wall under them; the same label map as the exact pieces
    from facaid.labels import LABEL_ID
    from facaid.segmentation import rasterize

    boxes = read(as_alice.get(base + "segmentation.coco.json").content, size=size)
    exact = read(as_alice.get(base + "segmentation.json").content, size=size)
    assert len(boxes.rects) < len(exact.rects) and (rasterize(boxes) == rasterize(exact)).all()
    assert sum(r.label == LABEL_ID["facade"] for r in boxes.rects) < sum(r.label == LABEL_ID["facade"]
                                                                       for r in exact.rects)
    capsys.readouterr()


def test_the_procedure_json_names_its_scale_where_one_is_known(procedure, as_alice):
    """In pixels, and where the photo's real size (or metres_per_pixel) gives a scale, its meta names it."""
    url = f"/api/v1/procedures/{procedure.code}/download/procedure.json"
    procedure.data = {**procedure.data, "meta": {"scale": {"metres_per_pixel": 9.0, "from": "given"}}}
    procedure.save()  # a tree saved from an earlier download keeps no scale of its own
    assert "scale" not in json.loads(as_alice.get(url).content).get("meta", {})  # no real size: a storey is a guess
    given = json.loads(as_alice.get(url + "?metres_per_pixel=0.02").content)["meta"]["scale"]
    assert given == {"metres_per_pixel": 0.02, "from": "given"}
    photo = procedure.photo
    photo.real_width_m = 12.5
    photo.save()
    known = json.loads(as_alice.get(url).content)["meta"]["scale"]
    assert known["metres_per_pixel"] == pytest.approx(12.5 / photo.width) and "real width, 12.5 m" in known["from"]
    r = as_alice.get(url + "?metres_per_pixel=abc")
    assert r.status_code == 400 and "metres_per_pixel" in r.json()
