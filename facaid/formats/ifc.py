"""A procedure as IFC4 (with IfcOpenShell): the facade as a wall with its windows and doors, for BIM tools.

The wall (`IfcWall`) spans the procedure's elements (background left out), `WALL_M` thick, its outer face in the
plane y = 0 facing -y, x along the facade and z up, in metres at the relief's scale (`relief`). Each window,
door and shop front is an `IfcOpeningElement` through the wall, voiding it, filled by an `IfcWindow` or `IfcDoor`
of the opening's size (`OverallWidth`, `OverallHeight`), set back by its label's depth; shop fronts are windows of
the user-defined type "shop front". Every filling carries its label and its node's path in the tree in the
property set ``FacAID_Element``; the wall and the project say the scale (``FacAID_Export``, the project's
description). The other elements (cornices, balconies, ...) are in the glTF, OBJ and CityJSON exports, not here.
"""

from __future__ import annotations

from facaid.formats.relief import DEPTHS, MeshTooLarge, procedure_relief
from facaid.grammar.procedure import Procedure

WALL_M = 0.3  # the wall's thickness
PANE_M = 0.06  # a window's or a door's thickness
CUT_M = 0.01  # an opening reaches this far out of either face, so that its boolean never leaves a skin
# label -> IFC class, predefined type, object type
FILLINGS = {"window": ("IfcWindow", "WINDOW", None), "door": ("IfcDoor", "DOOR", None),
            "shop": ("IfcWindow", "USERDEFINED", "shop front")}


MAX_OPENINGS = 5_000  # 5,000 openings take about 7 s here; a real facade has a few hundred at most


class _Writer:
    """Boxes placed in an IFC file, written entity by entity (the API's functions take ten times as long)."""

    def __init__(self, f, body):
        self.f, self.body = f, body
        self.up = f.createIfcDirection((0.0, 0.0, 1.0))
        self.profiles: dict[tuple[float, float], object] = {}

    def placement(self, relative_to, x: float, y: float, z: float):
        point = self.f.createIfcCartesianPoint((float(x), float(y), float(z)))
        return self.f.createIfcLocalPlacement(relative_to, self.f.createIfcAxis2Placement3D(point, None, None))

    def box(self, width: float, height: float, thickness: float):
        """A body of ``width`` along x, ``thickness`` along y and ``height`` up, from its placement's origin."""
        key = (round(width, 9), round(thickness, 9))
        if key not in self.profiles:
            centre = self.f.createIfcAxis2Placement2D(self.f.createIfcCartesianPoint((width / 2, thickness / 2)))
            self.profiles[key] = self.f.createIfcRectangleProfileDef("AREA", None, centre, width, thickness)
        solid = self.f.createIfcExtrudedAreaSolid(self.profiles[key], None, self.up, height)
        shape = self.f.createIfcShapeRepresentation(self.body, "Body", "SweptSolid", [solid])
        return self.f.createIfcProductDefinitionShape(None, None, [shape])

    def product(self, ifc_class: str, name: str, placement, shape, **attributes):
        import ifcopenshell.guid

        return self.f.create_entity(ifc_class, GlobalId=ifcopenshell.guid.new(), Name=name,
                                    ObjectPlacement=placement, Representation=shape, **attributes)

    def properties(self, element, name: str, values: dict[str, str]) -> None:
        import ifcopenshell.guid

        single = [self.f.createIfcPropertySingleValue(key, None, self.f.createIfcLabel(value), None)
                  for key, value in values.items()]
        pset = self.f.createIfcPropertySet(ifcopenshell.guid.new(), None, name, None, single)
        self.f.createIfcRelDefinesByProperties(ifcopenshell.guid.new(), None, None, None, [element], pset)


def procedure_ifc(proc: Procedure, scale: float | None = None, scale_from: str = "", name: str = "") -> str:
    """The procedure as an IFC4 file's text (see the module's docstring); ``scale`` in metres per pixel (default
    `facaid.formats.cga.default_scale`) with ``scale_from``, where it came from; ``name`` names the project.
    `facaid.formats.relief.MeshTooLarge` for a procedure of too many rectangles or openings, a ValueError for a bad
    scale."""
    import ifcopenshell.guid  # a large library: imported when an IFC is written
    from ifcopenshell import api
    from ifcopenshell.api import aggregate, context, project, root, unit  # noqa: F401

    relief = procedure_relief(proc, scale, scale_from)
    labels = relief.labels()
    openings = [i for i, label in enumerate(labels) if label in FILLINGS]
    if len(openings) > MAX_OPENINGS:
        raise MeshTooLarge(f"the procedure draws {len(openings)} windows, doors and shop fronts; an IFC is made of "
                           f"at most {MAX_OPENINGS}")
    f = api.project.create_file(version="IFC4")
    ifc_project = api.root.create_entity(f, ifc_class="IfcProject", name=name or "FaçAID facade")
    ifc_project.Description = f"A facade written by FaçAID at {relief.describe()}"
    api.unit.assign_unit(f, units=[api.unit.add_si_unit(f, unit_type=kind)
                                   for kind in ("LENGTHUNIT", "AREAUNIT", "VOLUMEUNIT")])
    model = api.context.add_context(f, context_type="Model")
    body = api.context.add_context(f, context_type="Model", context_identifier="Body", target_view="MODEL_VIEW",
                                   parent=model)
    parent = ifc_project
    for ifc_class, title in (("IfcSite", "site"), ("IfcBuilding", "building"), ("IfcBuildingStorey", "facade")):
        part = api.root.create_entity(f, ifc_class=ifc_class, name=title)
        api.aggregate.assign_object(f, relating_object=parent, products=[part])
        parent = part
    storey = parent
    write = _Writer(f, body)
    boxes = relief.boxes()
    left, right, bottom, top = ((boxes[:, 0].min(), boxes[:, 1].max(), boxes[:, 2].min(), boxes[:, 3].max())
                                if len(boxes) else (0.0, relief.width_m, 0.0, relief.height_m))
    wall_at = write.placement(None, left, 0.0, bottom)
    wall = write.product("IfcWall", "facade", wall_at, write.box(right - left, top - bottom, WALL_M),
                         PredefinedType="SOLIDWALL")
    write.properties(wall, "FacAID_Export", {"MetresPerPixel": f"{relief.scale:.6g}", "ScaleFrom": relief.scale_from,
                                             "Scale": relief.describe()})
    fillings = [wall]
    for i in openings:
        label, (x0, x1, y0, y1) = labels[i], boxes[i].tolist()
        ifc_class, kind, object_type = FILLINGS[label]
        opening_at = write.placement(wall_at, x0 - left, -CUT_M, y0 - bottom)
        opening = write.product("IfcOpeningElement", f"{label} {i} opening", opening_at,
                                write.box(x1 - x0, y1 - y0, WALL_M + 2 * CUT_M), PredefinedType="OPENING")
        f.createIfcRelVoidsElement(ifcopenshell.guid.new(), None, None, None, wall, opening)
        filling = write.product(ifc_class, f"{label} {i}", write.placement(opening_at, 0.0, CUT_M - DEPTHS[label], 0.0),
                                write.box(x1 - x0, y1 - y0, PANE_M), PredefinedType=kind, ObjectType=object_type,
                                OverallWidth=x1 - x0, OverallHeight=y1 - y0)
        f.createIfcRelFillsElement(ifcopenshell.guid.new(), None, None, None, opening, filling)
        write.properties(filling, "FacAID_Element", {"Label": label, "TreePath": relief.paths[i]})
        fillings.append(filling)
    f.createIfcRelContainedInSpatialStructure(ifcopenshell.guid.new(), None, None, None, fillings, storey)
    return f.to_string()
