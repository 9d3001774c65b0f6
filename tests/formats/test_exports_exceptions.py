"""The 3D, BIM and GIS exports of a procedure whose repeats have exceptions (a closed blind, a sill left out, a
taller floor, a wider bay): every element drawn once, where the procedure draws it, named by its node (an
exception's node by its own path, root/1/!0)."""

import ifcopenshell
import numpy as np
from grammar_helpers import example
from test_cityjson import surfaces
from test_gltf import elements, load

from facaid.formats.cityjson import procedure_cityjson
from facaid.formats.gltf import procedure_gltf
from facaid.formats.ifc import procedure_ifc
from facaid.formats.relief import procedure_relief

SCALE = 0.02


def test_every_export_draws_the_exceptions(tmp_path):
    proc = example()
    relief = procedure_relief(proc, SCALE)
    labels = relief.labels()
    assert (labels.count("window"), labels.count("blind"), labels.count("sill")) == (19, 1, 19)
    nodes = dict(proc.nodes())

    found = elements(load(procedure_gltf(proc, SCALE)))
    assert len(found) == len(labels)
    paths = {e["extras"]["path"] for e in found.values()}
    assert "root/1/!0" in paths  # the blind is the exception's node
    assert all(nodes[e["extras"]["path"]].label == e["extras"]["label"] for e in found.values())

    path = tmp_path / "facade.ifc"
    path.write_text(procedure_ifc(proc, SCALE))
    model = ifcopenshell.open(str(path))
    assert len([w for w in model.by_type("IfcWindow") if w.PredefinedType == "WINDOW"]) == 19

    doc = procedure_cityjson(proc, SCALE)
    windows = [ring for semantic, ring in surfaces(doc) if semantic["type"] == "Window"
               and semantic["label"] == "window"]
    assert len(windows) == 19
    heights = sorted({round(float(np.ptp(ring[:, 2])), 3) for ring in windows})
    assert heights == [round(40 * SCALE, 3)]  # a window 40 px tall, whatever floor it is on
