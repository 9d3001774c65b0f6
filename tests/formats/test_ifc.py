"""The IFC export, opened by IfcOpenShell from the written file: valid IFC4 in metres, one IfcWindow per window and
one IfcDoor per door, each filling an IfcOpeningElement that voids the IfcWall, placed and sized as the
procedure draws it; the wall's solid, with its openings cut by IfcOpenShell's geometry kernel, has the volume
left."""

import ifcopenshell
import ifcopenshell.geom
import ifcopenshell.util.element
import ifcopenshell.util.placement
import ifcopenshell.util.shape
import ifcopenshell.util.unit
import ifcopenshell.validate
import numpy as np
import pytest
from format_helpers import window_grid

from facaid.formats.ifc import MAX_OPENINGS, WALL_M, procedure_ifc
from facaid.formats.relief import DEPTHS, MeshTooLarge, procedure_relief
from facaid.generator import generate

SCALE = 0.02


@pytest.fixture(scope="module")
def proc():
    return generate(3).procedure


@pytest.fixture(scope="module")
def model(proc, tmp_path_factory):
    path = tmp_path_factory.mktemp("ifc") / "facade.ifc"
    path.write_text(procedure_ifc(proc, SCALE, scale_from="the photo's real width, 8.88 m", name="Rue X"))
    return ifcopenshell.open(str(path))


def test_valid_ifc4_in_metres_that_states_its_scale(model):
    assert model.schema == "IFC4"
    log = ifcopenshell.validate.json_logger()
    ifcopenshell.validate.validate(model, log, express_rules=True)
    assert log.statements == []
    assert ifcopenshell.util.unit.calculate_unit_scale(model) == 1.0  # project length unit: the metre
    project, = model.by_type("IfcProject")
    assert project.Name == "Rue X"
    assert "0.02 m per pixel (the photo's real width, 8.88 m): 8.88 m x 15.94 m" in project.Description
    wall, = model.by_type("IfcWall")
    assert ifcopenshell.util.element.get_psets(wall)["FacAID_Export"]["MetresPerPixel"] == "0.02"
    assert ifcopenshell.util.element.get_container(wall).is_a("IfcBuildingStorey")


def test_one_window_per_window_and_one_door_per_door_each_in_an_opening_of_the_wall(proc, model):
    relief = procedure_relief(proc, SCALE)
    labels = relief.labels()
    boxes = dict(zip(range(len(labels)), relief.boxes().tolist(), strict=True))
    windows = [w for w in model.by_type("IfcWindow") if w.PredefinedType == "WINDOW"]
    shops = [w for w in model.by_type("IfcWindow") if w.PredefinedType == "USERDEFINED"]
    doors = model.by_type("IfcDoor")
    assert (len(windows), len(doors), len(shops)) == (labels.count("window"), labels.count("door"),
                                                      labels.count("shop")) == (30, 1, 1)
    assert all(s.ObjectType == "shop front" for s in shops)
    wall, = model.by_type("IfcWall")
    nodes = dict(proc.nodes())
    for filling in [*windows, *doors, *shops]:
        opening = filling.FillsVoids[0].RelatingOpeningElement
        assert opening.is_a("IfcOpeningElement") and opening.VoidsElements[0].RelatingBuildingElement == wall
        about = ifcopenshell.util.element.get_psets(filling)["FacAID_Element"]
        label, index = filling.Name.split()
        assert about["Label"] == label and nodes[about["TreePath"]].label == label
        left, right, bottom, top = boxes[int(index)]
        assert filling.OverallWidth == pytest.approx(right - left) and filling.OverallHeight == pytest.approx(
            top - bottom)
        where = ifcopenshell.util.placement.get_local_placement(filling.ObjectPlacement)[:3, 3]
        assert np.allclose(where, [left, -DEPTHS[label], bottom])  # set back into the wall by its depth
        cut = ifcopenshell.util.placement.get_local_placement(opening.ObjectPlacement)[:3, 3]
        assert np.allclose(cut[[0, 2]], [left, bottom]) and cut[1] < 0


def test_the_openings_cut_the_wall(proc, model):
    relief = procedure_relief(proc, SCALE)
    boxes = relief.boxes()
    openings = boxes[[label in ("window", "door", "shop") for label in relief.labels()]]
    wall, = model.by_type("IfcWall")
    shape = ifcopenshell.geom.create_shape(ifcopenshell.geom.settings(), wall)
    width = boxes[:, 1].max() - boxes[:, 0].min()
    height = boxes[:, 3].max() - boxes[:, 2].min()
    holes = ((openings[:, 1] - openings[:, 0]) * (openings[:, 3] - openings[:, 2])).sum()
    assert ifcopenshell.util.shape.get_volume(shape.geometry) == pytest.approx((width * height - holes) * WALL_M,
                                                                                 rel=1e-6)


@pytest.mark.parametrize("bad", [0, -1, float("nan"), 1e6])
def test_a_bad_scale_is_refused(proc, bad):
    with pytest.raises(ValueError, match="scale must be a number of metres per pixel"):
        procedure_ifc(proc, bad)


def test_a_procedure_of_too_many_openings_is_refused_with_its_count():
    huge = window_grid(80, 70, 1600, apart=True)
    with pytest.raises(MeshTooLarge, match=f"draws 5600 windows, doors and shop fronts; an IFC is made of at most "
                                           f"{MAX_OPENINGS}"):
        procedure_ifc(huge, 0.01)
