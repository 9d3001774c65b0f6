"""What `facaid export` writes, by the output's extension: the procedure itself, the rectangles it draws (ours, COCO,
LabelMe, CVAT), its label map as a picture (alone or over the photo), and the formats of other tools, the 3D ones in
metres at a scale each file states. The same set as the site's downloads (`webapp.facades.downloads`), where the
OBJ and its MTL come zipped (`mesh.zip`) and the textured glTF is `facade-photo.glb`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from PIL import Image

    from facaid.grammar.procedure import Procedure


@dataclass(frozen=True)
class Export:
    what: str  # what the file is, for --help and the line printed
    write: Callable[[Procedure, Path, float | None, Image.Image | None], list[Path]]  # the files written
    scaled: bool = True  # in metres, at --metres-per-pixel
    photo: bool = False  # takes --photo
    needs_photo: bool = False  # and cannot do without it


def _text(path: Path, text: str | bytes) -> list[Path]:
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    return [path]


def _json(proc, path, scale, photo):
    return _text(path, proc.to_json(indent=1) + "\n")


def _png(proc, path, scale, photo):
    from facaid.formats.render import render_segmentation
    from facaid.grammar.execute import to_segmentation

    render_segmentation(to_segmentation(proc)).save(path, "PNG")
    return [path]


def _segmentation(fmt: str):
    def write(proc, path, scale, photo):
        from facaid.formats.annotation import written_as
        from facaid.formats.interchange import write as write_annotations
        from facaid.grammar.execute import to_segmentation

        picture = path.name[: -len(export_for(path)[0])] + ".png"  # the label map `--out NAME.png` writes beside it
        return _text(path, write_annotations(written_as(to_segmentation(proc), fmt), fmt, image=picture))
    return write


def _overlay(proc, path, scale, photo):
    from facaid.formats.render import overlay
    from facaid.grammar.execute import to_segmentation
    from facaid.segmentation import rasterize

    overlay(photo, rasterize(to_segmentation(proc))).save(path, "PNG")
    return [path]


def _svg(proc, path, scale, photo):
    from facaid.formats.render import segmentation_svg
    from facaid.grammar.execute import to_segmentation

    return _text(path, segmentation_svg(to_segmentation(proc)))


def _cga(proc, path, scale, photo):
    from facaid.formats.cga import procedure_cga

    return _text(path, procedure_cga(proc, scale, name=path.name))


def _obj(proc, path, scale, photo):
    from facaid.formats.mesh import procedure_mesh

    mtl = path.with_suffix(".mtl")
    obj, materials = procedure_mesh(proc, scale, mtl_name=mtl.name)
    return _text(path, obj) + _text(mtl, materials)


def _gltf(binary: bool):
    def write(proc, path, scale, photo):
        from facaid.formats.gltf import procedure_gltf

        return _text(path, procedure_gltf(proc, scale, binary=binary, photo=photo, name=path.name))
    return write


def _ifc(proc, path, scale, photo):
    from facaid.formats.ifc import procedure_ifc

    return _text(path, procedure_ifc(proc, scale, name=path.name))


def _cityjson(proc, path, scale, photo):
    from facaid.formats.cityjson import cityjson_text, procedure_cityjson

    return _text(path, cityjson_text(procedure_cityjson(proc, scale, name=path.name)))


EXPORTS: dict[str, Export] = {  # the longest extension that a file name ends in wins
    ".json": Export("the procedure JSON", _json, scaled=False),
    ".segmentation.json": Export("the labelled rectangles it draws", _segmentation("segmentation"), scaled=False),
    ".coco.json": Export("its elements as COCO object detection annotations, one box each", _segmentation("coco"),
                         scaled=False),
    ".labelme.json": Export("the same boxes as a LabelMe file", _segmentation("labelme"), scaled=False),
    ".cvat.xml": Export("the same boxes as CVAT for images XML", _segmentation("cvat"), scaled=False),
    ".png": Export("the label map as a picture", _png, scaled=False),
    ".overlay.png": Export("the label map over --photo, half opaque", _overlay, scaled=False, photo=True,
                           needs_photo=True),
    ".svg": Export("the label map as vector rectangles", _svg, scaled=False),
    ".cga": Export("CityEngine CGA rules", _cga),
    ".obj": Export("a relief mesh (OBJ, with its MTL beside it)", _obj),
    ".glb": Export("glTF binary: one node per element, repeats as instances", _gltf(True), photo=True),
    ".gltf": Export("glTF text with its data inline", _gltf(False), photo=True),
    ".ifc": Export("IFC4: a wall with its windows and doors in openings", _ifc),
    ".city.json": Export("CityJSON 2.0: an LoD3 building with wall, window and door surfaces", _cityjson),
}


def export_for(path: str | Path) -> tuple[str, Export] | None:
    """The extension and the export of a file name, None when it names none."""
    name = Path(path).name.lower()
    found = [ext for ext in EXPORTS if name.endswith(ext) and len(name) > len(ext)]
    if not found:
        return None
    ext = max(found, key=len)
    return ext, EXPORTS[ext]
