"""The 3D downloads of a procedure (glTF, glTF with the photo, IFC, CityJSON): served with their content types,
read back by their formats' readers, at the scale asked for, and a bad parameter or a procedure too large a 400
(alice owns, charlie is anonymous)."""

import io
import json

import ifcopenshell
import pytest
import trimesh
from format_helpers import window_grid

from facaid.generator import generate
from facaid.grammar.execute import to_segmentation
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
    rects = to_segmentation(generate(3).procedure).rects
    windows = sum(r.label == LABEL_ID["window"] for r in rects)
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
    for name in ("facade.glb", "facade.gltf", "facade.ifc", "facade.city.json"):
        r = as_alice.get(f"/api/v1/procedures/{huge.code}/download/{name}")
        assert r.status_code == 400 and "24000 rectangles" in r.json()["name"], name


def test_the_page_offers_them_with_their_scale_and_the_photo_only_to_who_sees_it(procedure, as_alice, as_charlie):
    from facaid.cga import default_scale

    page = as_charlie.get(f"/procedures/{procedure.code}").content.decode()
    for name in ("facade.glb", "facade.gltf", "facade.ifc", "facade.city.json"):
        assert f'download/{name}" data-scaled>' in page, name
    assert "download/facade-photo.glb" not in page  # alice's photo is private
    assert as_charlie.get(f"/api/v1/procedures/{procedure.code}/download/facade-photo.glb").status_code == 400
    scale = default_scale(generate(3).procedure)
    assert f"a storey is 3 m tall: {scale:.5f} m per pixel" in page
    assert "in metres at that scale, which the file states" in page
    assert "download/facade-photo.glb" in as_alice.get(f"/procedures/{procedure.code}").content.decode()
