"""The CityJSON export: the 1.0 form valid against the official CityJSON schema (the 1.0.1 schema files cjio
0.6.10 ships, checked by jsonschema-rs), the 2.0 form the same model and read by cityjson-lib, one Window semantic
surface per window and one Door per door where the procedure draws them, every ring facing out."""

import json
from importlib.resources import files

import cityjson_lib
import jsonschema_rs
import numpy as np
import pytest
from format_helpers import window_grid

from facaid.cityjson import cityjson_text, procedure_cityjson
from facaid.generator import generate
from facaid.relief import DEPTHS, MeshTooLarge, procedure_relief

SCALE = 0.02
SCHEMAS = files("cjio") / "schemas" / "1.0.1"


@pytest.fixture(scope="module")
def validator():
    # jsonschema-rs, not jsonschema: the schema's oneOf over every kind of city object takes the pure-Python
    # validator 13 s a facade here, this 3 ms; a schema without an $id refers to its neighbours as json-schema:///NAME
    schemas = {p.name: json.loads(p.read_text()) for p in SCHEMAS.iterdir() if p.name.endswith(".schema.json")}
    registry = jsonschema_rs.Registry([(f"json-schema:///{name}", schema) for name, schema in schemas.items()])
    return jsonschema_rs.validator_for(schemas["cityjson.schema.json"], registry=registry)


@pytest.fixture(scope="module")
def proc():
    return generate(3).procedure


def surfaces(doc: dict) -> list[tuple[dict, np.ndarray]]:
    """Each surface of the building's geometry: its semantic object and its ring in metres."""
    building = doc["CityObjects"]["facade"]
    geometry, = building["geometry"]
    scale, translate = (np.array(doc["transform"][k]) for k in ("scale", "translate"))
    vertices = np.array(doc["vertices"]) * scale + translate
    semantics = geometry["semantics"]
    return [(semantics["surfaces"][value], vertices[surface[0]])
            for surface, value in zip(geometry["boundaries"], semantics["values"], strict=True)]


def test_the_1_0_form_is_valid_against_the_official_schema(proc, validator):
    doc = json.loads(cityjson_text(procedure_cityjson(proc, SCALE, version="1.0")))
    assert list(validator.iter_errors(doc)) == []
    broken = json.loads(json.dumps(doc))  # the schema bites: an unknown semantic type, a building without a type
    broken["CityObjects"]["facade"]["geometry"][0]["semantics"]["surfaces"][0]["type"] = "Windoh"
    assert not validator.is_valid(broken)
    del doc["CityObjects"]["facade"]["type"]
    assert not validator.is_valid(doc)


def test_the_2_0_form_is_the_same_model_and_cityjson_lib_reads_it(proc):
    new, old = (procedure_cityjson(proc, SCALE, version=v) for v in ("2.0", "1.0"))
    assert new["version"] == "2.0" and new["CityObjects"]["facade"]["geometry"][0]["lod"] == "3"
    assert "0.02 m per pixel (given): 8.88 m x 15.94 m" in new.pop("metadata")["title"]
    new["version"], new["CityObjects"]["facade"]["geometry"][0]["lod"] = "1.0", 3
    assert new == old  # so the schema's verdict on 1.0 holds for 2.0's geometry and semantics
    model = cityjson_lib.CityModel.parse_document_bytes(cityjson_text(procedure_cityjson(proc, SCALE)).encode())
    summary = model.summary()
    relief = procedure_relief(proc, SCALE)
    assert (summary.cityobject_count, summary.geometry_count) == (1, 1)
    assert summary.vertex_count == len(new["vertices"])
    openings = sum(label in ("window", "door", "shop") for label in relief.labels())
    assert summary.semantic_count == openings + len(set(relief.labels()))  # one per opening, a wall per label


def test_one_window_surface_per_window_and_one_door_per_door_where_they_are(proc):
    doc = procedure_cityjson(proc, SCALE, scale_from="the photo's real width, 8.88 m")
    assert doc["CityObjects"]["facade"]["attributes"]["facaid_metres_per_pixel"] == SCALE
    assert "(the photo's real width, 8.88 m)" in doc["CityObjects"]["facade"]["attributes"]["facaid_scale"]
    relief = procedure_relief(proc, SCALE)
    labels = relief.labels()
    expected = {tuple(np.round(box, 4)) + (label,) for label, box in zip(labels, relief.boxes(), strict=True)
                if label in ("window", "door", "shop")}
    found, nodes = set(), dict(proc.nodes())
    for semantic, ring in surfaces(doc):
        if semantic["type"] in ("Window", "Door"):
            label = semantic["label"]
            assert semantic["type"] == ("Door" if label == "door" else "Window")
            assert nodes[semantic["path"]].label == label
            assert np.allclose(ring[:, 1], -DEPTHS[label])  # set back into the building
            box = (ring[:, 0].min(), ring[:, 0].max(), ring[:, 2].min(), ring[:, 2].max())
            found.add(tuple(np.round(box, 4)) + (label,))
    assert found == expected
    kinds = [s["type"] for s in doc["CityObjects"]["facade"]["geometry"][0]["semantics"]["surfaces"]]
    windows = [s for s in doc["CityObjects"]["facade"]["geometry"][0]["semantics"]["surfaces"]
               if s["type"] == "Window" and s["label"] == "window"]
    assert (len(windows), kinds.count("Door")) == (labels.count("window"), labels.count("door")) == (30, 1)


def test_every_ring_faces_out_of_the_building(proc):
    fronts = 0
    for _, ring in surfaces(procedure_cityjson(proc, SCALE)):
        normal = np.cross(ring[1] - ring[0], ring[2] - ring[0])
        assert np.linalg.norm(normal) > 0
        normal /= np.linalg.norm(normal)
        if abs(normal[1]) > 0.5:  # a front faces the street (-y); a side is square to it
            assert np.allclose(normal, [0, -1, 0])
            fronts += 1
        else:
            assert normal[1] == pytest.approx(0)
    assert fronts == len(procedure_relief(proc, SCALE).rows)


def test_bad_input_is_refused(proc):
    with pytest.raises(ValueError, match="version must be one of 2.0, 1.0"):
        procedure_cityjson(proc, SCALE, version="1.1")
    with pytest.raises(ValueError, match="scale must be a number of metres per pixel"):
        procedure_cityjson(proc, -1)
    huge = window_grid(200, 60)
    with pytest.raises(MeshTooLarge, match="draws 24000 rectangles"):
        procedure_cityjson(huge, 0.01)
