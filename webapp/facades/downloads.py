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


def photo_scale(proc: Procedure) -> tuple[float, str] | None:
    """The scale the procedure's photo gives (its real width or height over the pixels of the image the procedure
    was drawn on) and a line saying so; None without a photo or a real size. The image is the rectified one unless
    the procedure has the original's size (drawn before rectification)."""
    photo = proc.photo
    if photo is None or (photo.real_width_m is None and photo.real_height_m is None):
        return None
    size = (proc.data.get("width", 0), proc.data.get("height", 0))
    drawn_on = photo.working_size()
    if photo.rectified and (round(size[0]), round(size[1])) == (photo.width, photo.height):
        drawn_on = (photo.width, photo.height)
    scale = photo.metres_per_pixel(drawn_on)
    if scale is None:
        return None
    what = (f"the photo's real width, {photo.real_width_m:g} m" if photo.real_width_m is not None
            else f"the photo's real height, {photo.real_height_m:g} m")
    return scale, what


def _scale(proc: Procedure, tree: Tree, params: Params) -> tuple[float | None, str]:
    """The scale of a download and where it came from: ``metres_per_pixel`` if asked, else the photo's real size,
    else None (the writers' default: a storey 3 m tall, which they say)."""
    raw = params.get("metres_per_pixel")
    if raw is None:
        given = photo_scale(proc)
        if given is not None:
            try:
                return checked_scale(tree, given[0]), given[1]
            except ValueError:  # a real size over an image of a few pixels: the default rather than a 400
                pass
        return None, ""
    try:
        return checked_scale(tree, float(raw)), ""  # the writers say "given"
    except ValueError:
        raise ValidationError({"metres_per_pixel": "metres_per_pixel must be a number > 0 and at most "
                                                   f"{MAX_SCALE:g}"}) from None


def stem(proc: Procedure) -> str:
    return f"facaid-{str(proc.code)[:8]}"


def _cga(proc: Procedure, tree: Tree, params: Params) -> str:
    scale, source = _scale(proc, tree, params)
    return procedure_cga(tree, scale, name=proc.title or stem(proc), scale_from=source)


def _mesh_zip(proc: Procedure, tree: Tree, params: Params) -> bytes:
    try:
        scale, source = _scale(proc, tree, params)
        obj, mtl = procedure_mesh(tree, scale, mtl_name="facade.mtl", scale_from=source)
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
