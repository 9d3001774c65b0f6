"""The CityJSON export: both forms pass `facaid validate-cityjson` (the official schemas, CityJSON 2.0.2 and 1.0.3,
checked by jsonschema-rs, and cjval's checks), which bites on broken files; cjio reads the export and cityjson-lib
parses the 2.0 form; one Window semantic surface per window and one Door per door where the procedure draws them,
every ring facing out."""

import json
import subprocess
import sys
from pathlib import Path

import cityjson_lib
import numpy as np
import pytest
from format_helpers import window_grid

from facaid.cli import main
from facaid.formats.cityjson import cityjson_text, procedure_cityjson
from facaid.formats.cityjson_check import check_cityjson
from facaid.formats.relief import DEPTHS, MeshTooLarge, procedure_relief
from facaid.generator import generate

SCALE = 0.02


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


@pytest.mark.parametrize("version", ["2.0", "1.0"])
def test_both_forms_are_valid_against_the_official_schema_and_cjvals_checks(proc, version):
    doc = procedure_cityjson(proc, SCALE, version=version)
    report = check_cityjson(cityjson_text(doc))
    assert (report.valid, report.version, report.errors, report.warnings) == (True, version, [], [])
    assert report.counts == {"city objects": 1, "vertices": len(doc["vertices"]),
                             "surfaces": len(doc["CityObjects"]["facade"]["geometry"][0]["boundaries"])}


def _broken(doc: dict, how) -> str:
    copy = json.loads(json.dumps(doc))
    how(copy)
    return json.dumps(copy)


def test_the_validator_bites(proc):
    doc = procedure_cityjson(proc, SCALE)
    geometry = lambda d: d["CityObjects"]["facade"]["geometry"][0]  # noqa: E731

    def errors(how) -> list[str]:
        return check_cityjson(_broken(doc, how)).errors

    assert errors(lambda d: geometry(d)["semantics"]["surfaces"][0].update(type="Windoh")) == [
        "schema cityjson-2.0.2: CityObjects/facade/geometry/0/semantics/surfaces/0/type: 'Windoh' is not a type "
        "CityJSON 2.0 allows here"]
    assert errors(lambda d: d["CityObjects"]["facade"].update(type="Buildin")) == [
        "schema cityjson-2.0.2: CityObjects/facade/type: 'Buildin' is not a type CityJSON 2.0 allows here"]
    assert errors(lambda d: d["CityObjects"]["facade"].pop("type")) == [
        'schema cityjson-2.0.2: CityObjects/facade: "type" is a required property']
    assert errors(lambda d: geometry(d).update(lod=3)) == [  # 2.0 writes the LoD as a string
        'schema cityjson-2.0.2: CityObjects/facade/geometry/0/lod: 3 is not one of "0", "1" or 18 other candidates']
    out = errors(lambda d: geometry(d)["boundaries"][0][0].__setitem__(2, len(d["vertices"]) + 5))
    assert out == [f"wrong vertex index: 'facade' geometry 0: 1 indices out of 0..{len(doc['vertices']) - 1}, "
                   f"the first {len(doc['vertices']) + 5}"]
    out = errors(lambda d: geometry(d)["semantics"]["values"].pop())
    n = len(geometry(doc)["boundaries"])
    assert out == [f"semantics arrays: 'facade' geometry 0: its values are shaped {n - 1}, its surfaces {n}"]
    out = errors(lambda d: geometry(d)["semantics"]["values"].__setitem__(0, 10_000))
    assert out[0].startswith("semantics arrays: 'facade' geometry 0: values name surface 10000, of ")
    out = errors(lambda d: d["CityObjects"].update(part={"type": "BuildingPart", "parents": ["facade"]}))
    assert out == ["parents and children: 'part' names parent 'facade', which does not name it as a child"]
    report = check_cityjson(_broken(doc, lambda d: d["vertices"].extend([d["vertices"][0], [1, 2, 3]])))
    assert report.valid and report.warnings == ["duplicate vertices: 1", "unused vertices: 2"]
    assert check_cityjson("{").errors[0].startswith("json syntax: ")
    assert check_cityjson("[1]").errors == ["not a CityJSON file: it is a JSON list, not 'CityJSON'"]
    assert "version 1.1: this validator knows 2.0 and 1.0" in errors(lambda d: d.update(version="1.1"))[0]
    many = errors(lambda d: [s.update(type="Windoh") for s in geometry(d)["semantics"]["surfaces"]])
    assert len(many) == 21 and many[-1].endswith("more")  # 20 named, then a count


def test_a_person_validates_and_reads_an_export(tmp_path, capsys):
    procedure = tmp_path / "p.json"
    procedure.write_text(json.dumps(generate(3).procedure.to_dict()))
    out = tmp_path / "facade.city.json"
    assert main(["export", str(procedure), "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["validate-cityjson", str(out)]) == 0
    line = capsys.readouterr().out
    assert line.startswith(f"{out}: valid CityJSON 2.0 (schema cityjson-2.0.2, vertices, semantics, parents and "
                           "children): 1 city object, ") and "warning" not in line
    broken = tmp_path / "broken.city.json"
    broken.write_text(out.read_text().replace('"Door"', '"Dor"'))
    assert main(["validate-cityjson", str(out), str(broken)]) == 2
    said = capsys.readouterr()
    assert f"{broken}: not valid\n  error: schema cityjson-2.0.2: " in said.out and "Dor" in said.out
    assert "error: 1 of 2 files are not valid CityJSON" in said.err
    cjio = Path(sys.executable).parent / "cjio"  # the CityJSON project's own tool reads it
    info = subprocess.run([str(cjio), str(out), "info"], capture_output=True, text=True, timeout=120)
    assert info.returncode == 0, info.stderr
    assert "CityJSON version = 2.0" in info.stdout and "Building (1)" in info.stdout


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
    assert fronts == len(procedure_relief(proc, SCALE).parts)  # a front per part of each element


def test_bad_input_is_refused(proc):
    with pytest.raises(ValueError, match="version must be one of 2.0, 1.0"):
        procedure_cityjson(proc, SCALE, version="1.1")
    with pytest.raises(ValueError, match="scale must be a number of metres per pixel"):
        procedure_cityjson(proc, -1)
    huge = window_grid(200, 60)
    with pytest.raises(MeshTooLarge, match="draws 24000 rectangles"):
        procedure_cityjson(huge, 0.01)
