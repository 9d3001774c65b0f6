"""What a procedure can be downloaded as: a registry of name → `Download` (what it is, its content type, how it
is built from the procedure and the request's parameters). The API's download view and the procedure page's
buttons both read it; adding a format is adding an entry."""

from __future__ import annotations

import io
import zipfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from PIL import Image
from rest_framework.exceptions import ValidationError

from facaid import interchange
from facaid.cga import MAX_SCALE, checked_scale, procedure_cga
from facaid.grammar import Procedure as Tree
from facaid.grammar import to_segmentation
from facaid.mesh import MeshTooLarge, procedure_mesh
from facaid.render import segmentation_svg
from webapp.facades import rendering
from webapp.facades.models import Procedure
from webapp.facades.serializers import parse_procedure

Params = Mapping[str, str]


@dataclass(frozen=True)
class Download:
    help: str  # what it is, for the procedure page's buttons
    content_type: str
    build: Callable[[Procedure, Tree, Params], bytes | str] | None  # None: a picture kept in storage
    needs_photo: bool = False  # offered only where the procedure's photo is visible to the user


def _scale(tree: Tree, params: Params) -> float | None:
    raw = params.get("metres_per_pixel")
    try:
        return checked_scale(tree, None if raw is None else float(raw))
    except ValueError:
        raise ValidationError({"metres_per_pixel": "metres_per_pixel must be a number > 0 and at most "
                                                   f"{MAX_SCALE:g}"}) from None


def stem(proc: Procedure) -> str:
    return f"facaid-{str(proc.code)[:8]}"


def _cga(proc: Procedure, tree: Tree, params: Params) -> str:
    return procedure_cga(tree, _scale(tree, params), name=proc.title or stem(proc))


def _mesh_zip(proc: Procedure, tree: Tree, params: Params) -> bytes:
    try:
        obj, mtl = procedure_mesh(tree, _scale(tree, params), mtl_name="facade.mtl")
    except MeshTooLarge as exc:
        raise ValidationError({"name": str(exc)}) from None
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("facade.obj", obj)
        z.writestr("facade.mtl", mtl)
    return out.getvalue()


def _overlay(proc: Procedure, tree: Tree, params: Params) -> bytes:
    try:
        alpha = float(params.get("alpha", 0.5))
    except ValueError:
        alpha = -1.0
    if not 0.0 <= alpha <= 1.0:
        raise ValidationError({"alpha": "alpha must be a number between 0 and 1"})
    with proc.photo.working_image().open("rb") as f:
        return rendering.overlay_png(to_segmentation(tree), Image.open(f), alpha)


def _annotations(fmt: str) -> Callable[[Procedure, Tree, Params], bytes]:
    """The rectangles it draws as another tool's annotations, of the label map downloaded beside them."""
    return lambda proc, tree, params: interchange.write(to_segmentation(tree), fmt, image=f"{stem(proc)}-labels.png")


DOWNLOADS: dict[str, Download] = {
    "procedure.json": Download("the procedure: the tree with its sizes, to edit or reconstruct from",
                               "application/json", lambda proc, tree, params: tree.to_json(indent=2)),
    "segmentation.json": Download("the labelled rectangles it draws", "application/json",
                                  lambda proc, tree, params: to_segmentation(tree).to_json()),
    "segmentation.coco.json": Download("those rectangles as COCO object detection annotations", "application/json",
                                       _annotations("coco")),
    "segmentation.labelme.json": Download("those rectangles as a LabelMe file", "application/json",
                                          _annotations("labelme")),
    "segmentation.cvat.xml": Download("those rectangles as CVAT for images XML", "application/xml",
                                      _annotations("cvat")),
    "labels.png": Download("the label map as a picture", "image/png", None),
    "labels.svg": Download("the label map as vector rectangles, one group per class", "image/svg+xml",
                           lambda proc, tree, params: segmentation_svg(to_segmentation(tree))),
    "procedure.cga": Download("CityEngine CGA rules: apply Facade to a facade shape", "text/plain; charset=utf-8",
                              _cga),
    "mesh.zip": Download("a 3D relief mesh (OBJ and MTL) for Blender and other 3D tools", "application/zip",
                         _mesh_zip),
    "overlay.png": Download("the label map over the photo", "image/png", _overlay, needs_photo=True),
}


def build(name: str, proc: Procedure, params: Params) -> bytes | str:
    """The download ``name`` of a procedure (one with a builder); a `ValidationError` names a bad parameter."""
    return DOWNLOADS[name].build(proc, parse_procedure(proc.data), params)
