"""What a procedure can be downloaded as: a registry of name → `Download` (what it is, its content type, how it
is built from the procedure and the request's parameters). The API's download view and the procedure page's
buttons both read it; adding a format is adding an entry."""

from __future__ import annotations

import io
import zipfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from facaid.formats import interchange
from facaid.formats.annotation import written_as
from facaid.formats.cga import MAX_SCALE, STOREY_M, checked_scale, default_scale, procedure_cga
from facaid.formats.cityjson import cityjson_text, procedure_cityjson
from facaid.formats.gltf import MAX_TEXTURE, procedure_gltf
from facaid.formats.ifc import procedure_ifc
from facaid.formats.mesh import MAX_MESH_RECTS, MeshTooLarge, procedure_mesh
from facaid.formats.render import segmentation_svg
from facaid.grammar import Procedure as Tree
from facaid.grammar import to_segmentation
from facaid.grammar.budget import charge
from facaid.grammar.layout import count_leaves
from facaid.photo.files import read_photo
from webapp.facades import access, disclosure, drawing
from webapp.facades.errors import Invalid
from webapp.facades.models import Procedure
from webapp.facades.parsing import parse_procedure

Params = Mapping[str, str]
# (the procedure, its tree, the request's parameters, the viewer) -> the file: what is in it may depend on who asks
Builder = Callable[[Procedure, Tree, Params, object], bytes | str]


@dataclass(frozen=True)
class Download:
    help: str  # what it is, for the procedure page's buttons
    content_type: str
    build: Builder | None  # None: a picture kept in storage
    needs_photo: bool = False  # offered only where the procedure's photo is visible to the user
    scaled: bool = False  # in metres: takes ``metres_per_pixel``, else the scale of `download_scale`
    per_leaf: int = 0  # work units (about a microsecond each) it takes a rectangle, charged before it is built


def drawn_on_original(proc: Procedure) -> bool:
    """Whether the procedure was drawn on its photo's original image, not the rectified one."""
    return proc.drawn_on_original()


def photo_scale(proc: Procedure, viewer) -> tuple[float, str] | None:
    """The scale the procedure's photo gives (`Procedure.photo_scale`) where ``viewer`` may see the photo: for a
    procedure without a scale of its own (one made before procedures kept theirs, migration 0009); None otherwise."""
    if not access.photo_visible_to(viewer, proc.photo):
        return None
    return proc.photo_scale()


def download_scale(proc: Procedure, tree: Tree, viewer) -> tuple[float, str]:
    """The scale the metric downloads take for ``viewer`` without ``metres_per_pixel`` and where it comes from: the
    procedure's own (`_scale`), else a storey 3 m tall."""
    scale, source = _scale(proc, tree, {}, viewer)
    if scale is None:
        return default_scale(tree), f"a storey is {STOREY_M:g} m tall"
    return scale, source


def _scale(proc: Procedure, tree: Tree, params: Params, viewer) -> tuple[float | None, str]:
    """The scale of a download and where it came from: ``metres_per_pixel`` if asked, else the procedure's own scale
    (`Procedure.metres_per_pixel`: its photo's real size when it was made, kept by edits and forks, and shown to all
    who may see the procedure), else the photo's real size where ``viewer`` may see the photo (`photo_scale`), else
    None (the writers' default: a storey 3 m tall, which they say)."""
    raw = params.get("metres_per_pixel")
    if raw is None:
        own = (proc.metres_per_pixel, proc.scale_from) if proc.metres_per_pixel is not None else None
        for given in (own, photo_scale(proc, viewer)):
            if given is not None:
                try:
                    return checked_scale(tree, given[0]), given[1] or "the procedure's own scale"
                except ValueError:  # a real size over an image of a few pixels: the default rather than a 400
                    pass
        return None, ""
    try:
        return checked_scale(tree, float(raw)), ""  # the writers say "given"
    except ValueError:
        raise Invalid(f"metres_per_pixel must be a number > 0 and at most {MAX_SCALE:g}", "metres_per_pixel") from None


def stem(proc: Procedure) -> str:
    return f"facaid-{str(proc.code)[:8]}"


def _name(proc: Procedure, viewer) -> str:
    """The name a file gives the facade: the procedure's title as ``viewer`` is shown it (`disclosure.title`)."""
    return disclosure.title(viewer, proc) or stem(proc)


def _cga(proc: Procedure, tree: Tree, params: Params, viewer) -> str:
    scale, source = _scale(proc, tree, params, viewer)
    return procedure_cga(tree, scale, name=_name(proc, viewer), scale_from=source)


def _metric(write: Callable[[Procedure, Tree, float | None, str, str], bytes | str]) -> Builder:
    """A builder of a download in metres: ``write(proc, tree, scale, scale_from, name)`` at the request's scale; a
    procedure too large for it is a bad request."""
    def build(proc: Procedure, tree: Tree, params: Params, viewer) -> bytes | str:
        scale, source = _scale(proc, tree, params, viewer)
        try:
            return write(proc, tree, scale, source, _name(proc, viewer))
        except MeshTooLarge as exc:
            raise Invalid(str(exc), "name") from None
    return build


def _procedure_json(proc: Procedure, tree: Tree, params: Params, viewer) -> str:
    """The tree in pixels; where a real scale is known (the procedure's own, its photo's real size, or
    ``metres_per_pixel``), its meta names it, ``"scale": {"metres_per_pixel": .., "from": ..}``, so that a tool
    reading it can measure in metres."""
    scale, source = _scale(proc, tree, params, viewer)
    tree.meta = {k: v for k, v in tree.meta.items() if k != "scale"}  # never a scale of another download
    if disclosure.hidden(viewer, proc):  # nor the accuracy against a segmentation the viewer may not see
        tree.meta = disclosure.tree({"meta": tree.meta})["meta"]
    if scale is not None:
        tree.meta["scale"] = {"metres_per_pixel": scale, "from": source or "given"}
    return tree.to_json(indent=2)


def _mesh_zip(proc: Procedure, tree: Tree, scale: float | None, source: str, name: str) -> bytes:
    obj, mtl = procedure_mesh(tree, scale, mtl_name="facade.mtl", scale_from=source)
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("facade.obj", obj)
        z.writestr("facade.mtl", mtl)
    return out.getvalue()


def _gltf(binary: bool, photo: bool = False) -> Callable[[Procedure, Tree, float | None, str, str], bytes]:
    def write(proc: Procedure, tree: Tree, scale: float | None, source: str, name: str) -> bytes:
        if not photo:
            return procedure_gltf(tree, scale, binary=binary, scale_from=source, name=name)
        drawn = proc.photo.image if drawn_on_original(proc) else proc.photo.working_image()
        with drawn.open("rb") as f:  # read at the texture's size (`gltf.MAX_TEXTURE`), not at full size first
            texture = read_photo(f, mode="RGB", max_side=MAX_TEXTURE)
            return procedure_gltf(tree, scale, binary=binary, photo=texture, scale_from=source, name=name)
    return write


def _ifc(proc: Procedure, tree: Tree, scale: float | None, source: str, name: str) -> str:
    return procedure_ifc(tree, scale, scale_from=source, name=name)


def _cityjson(proc: Procedure, tree: Tree, scale: float | None, source: str, name: str) -> str:
    return cityjson_text(procedure_cityjson(tree, scale, scale_from=source, name=name))


def _overlay(proc: Procedure, tree: Tree, params: Params, viewer) -> bytes:
    try:
        alpha = float(params.get("alpha", 0.5))
    except ValueError:
        alpha = -1.0
    if not 0.0 <= alpha <= 1.0:
        raise Invalid("alpha must be a number between 0 and 1", "alpha")
    with proc.photo.working_image().open("rb") as f:
        return drawing.overlay_png(to_segmentation(tree), f, alpha)


def picture_name(proc: Procedure, tree: Tree, viewer) -> str:
    """The picture a procedure's annotations name: its photo (`Photo.file_name`: its title, as the site knows it),
    the original image or the rectified one, whichever the procedure was drawn on and has the size of; to a viewer
    who may not see the photo, a neutral name (``facaid-<code>-photo.jpg``: neither its title nor its ID,
    `disclosure`); the label map downloaded beside them (``facaid-<code>-labels.png``) for a procedure without a
    photo or of another size than it (a variation made larger)."""
    photo = proc.photo
    if photo is not None:
        original = proc.drawn_on_original() or not photo.rectified
        if (round(tree.width), round(tree.height)) == ((photo.width, photo.height) if original else
                                                        photo.working_size()):
            if disclosure.hidden(viewer, proc):
                field = photo.image if original else photo.rectified
                return f"{stem(proc)}-photo.{field.name.rsplit('.', 1)[-1].lower()}"
            return photo.file_name(rectified=not original)
    return f"{stem(proc)}-labels.png"


def _annotations(fmt: str) -> Builder:
    """The elements it draws as another tool's annotations, one box each (`annotation.written_as`), naming the
    picture they annotate (`picture_name`)."""
    return lambda proc, tree, params, viewer: interchange.write(written_as(to_segmentation(tree), fmt), fmt,
                                                                image=picture_name(proc, tree, viewer))


DOWNLOADS: dict[str, Download] = {
    "procedure.json": Download("the procedure: the tree with its sizes in pixels, to edit or reconstruct from; its "
                               "meta names the metres per pixel where the procedure's own scale (or "
                               "metres_per_pixel) gives them", "application/json", _procedure_json),
    "segmentation.json": Download("the labelled rectangles it draws", "application/json",
                                  lambda proc, tree, params, viewer: to_segmentation(tree).to_json(), per_leaf=5),
    "segmentation.coco.json": Download("its elements as COCO object detection annotations, one box each (pieces of "
                                       "one element merged, the wall under them)", "application/json",
                                       _annotations("coco"), per_leaf=15),
    "segmentation.labelme.json": Download("the same boxes as a LabelMe file", "application/json",
                                          _annotations("labelme"), per_leaf=15),
    "segmentation.cvat.xml": Download("the same boxes as CVAT for images XML", "application/xml",
                                      _annotations("cvat"), per_leaf=15),
    "labels.png": Download("the label map as a picture", "image/png", None),
    "labels.svg": Download("the label map as vector rectangles, one group per class", "image/svg+xml",
                           lambda proc, tree, params, viewer: segmentation_svg(to_segmentation(tree)), per_leaf=3),
    "procedure.cga": Download("CityEngine CGA rules: apply Facade to a facade shape", "text/plain; charset=utf-8",
                              _cga, scaled=True),
    "mesh.zip": Download("a 3D relief mesh (OBJ and MTL) for Blender and other 3D tools", "application/zip",
                         _metric(_mesh_zip), scaled=True, per_leaf=10),
    "facade.glb": Download("the relief as glTF (binary) for 3D tools and the web: a node per element with its label "
                           "and tree path, repeated ones as instances of one mesh, a material per class",
                           "model/gltf-binary", _metric(_gltf(binary=True)), scaled=True, per_leaf=20),
    "facade.gltf": Download("the same glTF as text, its data inline", "model/gltf+json", _metric(_gltf(binary=False)),
                            scaled=True, per_leaf=20),
    "facade-photo.glb": Download("that glTF with the photo on the fronts", "model/gltf-binary",
                                 _metric(_gltf(binary=True, photo=True)), needs_photo=True, scaled=True, per_leaf=20),
    "facade.ifc": Download("IFC4 for BIM tools: a wall whose openings hold its windows and doors", "application/x-step",
                           _metric(_ifc), scaled=True, per_leaf=100),
    "facade.city.json": Download("CityJSON 2.0 for GIS: an LoD3 building with wall, window and door surfaces",
                                 "application/city+json", _metric(_cityjson), scaled=True, per_leaf=80),
    "overlay.png": Download("the label map over the photo", "image/png", _overlay, needs_photo=True),
}


def build(name: str, proc: Procedure, params: Params, viewer) -> bytes | str:
    """The download ``name`` of a procedure (one with a builder) as ``viewer`` may have it (no title of a photo they
    may not see); `Invalid` names a bad parameter."""
    download, tree = DOWNLOADS[name], parse_procedure(proc.data)  # the tree's own units charged as it is read
    if download.per_leaf:  # and what writing its rectangles costs, before any of it is written (the 3D formats
        # refuse more than MAX_MESH_RECTS once they are laid out, so no more are charged: those say how many)
        leaves = count_leaves(tree.root, tree.width, tree.height)
        charge(download.per_leaf * (min(leaves, MAX_MESH_RECTS) if download.scaled else leaves))
    return download.build(proc, tree, params, viewer)
