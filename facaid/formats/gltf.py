"""A procedure as glTF 2.0 (a binary .glb, or a .gltf text with its data inline): the relief facade for 3D tools,
game engines and the web.

The scene's root node ``facade`` holds one child node per element of the relief (`facaid.formats.relief`: the
elements the annotations hold, and the pieces of wall), named for its label and numbered, its ``extras`` carrying
the label, its node's path in the tree (``root/1/0``) and its rectangle in the procedure's pixels. Elements of one
label and size are instances of one mesh (a repeat's windows: one mesh and many nodes, each moved into place); a
mesh is the element's front and, where it sits back or stands out, the four sides that join it to the wall plane
(for each of its parts, where it is drawn in parts). One material per label in the palette's colour. With the rectified
photo, the fronts show it (a material ``photo``) and each element has its own mesh for its own texture coordinates,
the vertices still shared by the elements of one shape. Metres, x right, y up, z towards the viewer (glTF's own
axes); the scale is in the root node's and the asset's ``extras``.
"""

from __future__ import annotations

import base64
import io
from dataclasses import dataclass

import numpy as np
import pygltflib as gl
from PIL import Image

from facaid.formats.relief import DEPTHS, NORMALS, Relief, box_quads, procedure_relief
from facaid.grammar.procedure import Procedure
from facaid.labels import LABELS, PALETTE

MAX_TEXTURE = 4096  # pixels on the photo's longer side: what every GPU takes
PHOTO = -1  # the key of the photo's material


def _linear(channel: int) -> float:
    """An sRGB channel (0-255) in glTF's linear colour space."""
    c = channel / 255
    return round(c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4, 6)


class _Data:
    """The one buffer of a glTF and its views and accessors."""

    def __init__(self, gltf: gl.GLTF2):
        self.gltf, self.blob = gltf, bytearray()

    def view(self, data: bytes, target: int | None = None) -> int:
        self.blob += b"\0" * (-len(self.blob) % 4)
        self.gltf.bufferViews.append(gl.BufferView(buffer=0, byteOffset=len(self.blob), byteLength=len(data),
                                                   target=target))
        self.blob += data
        return len(self.gltf.bufferViews) - 1

    def accessor(self, array: np.ndarray, bounds: bool = False) -> int:
        """An accessor of float32 vectors (n, 2 or 3), or of uint32 indices (n,); ``bounds``: with min and max."""
        if array.ndim == 1:
            array = array.astype(np.uint32)
            kind, component, target = gl.SCALAR, gl.UNSIGNED_INT, gl.ELEMENT_ARRAY_BUFFER
        else:
            array = array.astype(np.float32)
            kind, component, target = (gl.VEC2, gl.VEC3)[array.shape[1] - 2], gl.FLOAT, gl.ARRAY_BUFFER
        extra = {"min": array.min(axis=0).tolist(), "max": array.max(axis=0).tolist()} if bounds else {}
        self.gltf.accessors.append(gl.Accessor(bufferView=self.view(array.tobytes(), target), componentType=component,
                                               count=len(array), type=kind, **extra))
        return len(self.gltf.accessors) - 1


def procedure_gltf(proc: Procedure, scale: float | None = None, *, binary: bool = True,
                   photo: Image.Image | None = None, scale_from: str = "", name: str = "") -> bytes:
    """The procedure as a .glb (``binary``) or .gltf (see the module's docstring); ``scale`` in metres per pixel
    (default `facaid.formats.cga.default_scale`) with ``scale_from``, where it came from; ``photo``: the rectified photo
    to show on the fronts (it covers the whole facade). `facaid.formats.relief.MeshTooLarge` for a procedure of too many
    rectangles, a ValueError for a bad scale."""
    relief = procedure_relief(proc, scale, scale_from)
    gltf = gl.GLTF2()
    data = _Data(gltf)
    about = {"units": "metres", "metres_per_pixel": relief.scale, "scale_from": relief.scale_from,
             "width_m": round(relief.width_m, 4), "height_m": round(relief.height_m, 4), "scale": relief.describe()}
    gltf.asset = gl.Asset(version="2.0", generator="FaçAID", extras={"facaid": about})
    labels = sorted(set(relief.rows[:, 0].tolist()))
    materials = {}
    for label in labels:
        materials[label] = len(gltf.materials)
        gltf.materials.append(gl.Material(name=LABELS[label], pbrMetallicRoughness=gl.PbrMetallicRoughness(
            baseColorFactor=[*(_linear(c) for c in PALETTE[LABELS[label]]), 1.0], metallicFactor=0.0,
            roughnessFactor=1.0)))
    if photo is not None:
        materials[PHOTO] = len(gltf.materials)
        _add_photo(gltf, data, photo)
    root = gl.Node(name=name or "facade", extras={"facaid": about}, children=[])
    gltf.nodes.append(root)
    gltf.scenes.append(gl.Scene(name=name or "facade", nodes=[0]))
    gltf.scene = 0
    shapes: dict[tuple[int, int, int], _Shape] = {}  # (label, width, height) in pixels: the elements of one box
    starts = np.searchsorted(relief.parts[:, 0], np.arange(len(relief.rows) + 1))  # each row's parts
    for i, (row, box, path) in enumerate(zip(relief.rows.tolist(), relief.boxes(), relief.paths, strict=True)):
        label, x0, y0, x1, y1 = row
        parts = relief.parts[starts[i]:starts[i + 1]]
        if len(parts) == 1:
            key = (label, x1 - x0, y1 - y0)
            if key not in shapes:
                shapes[key] = _shape(data, relief, label, np.array([[0.0, x1 - x0, 0.0, y1 - y0]]) * relief.scale)
            shape = shapes[key]
        else:  # drawn in parts, around what is painted over it: a mesh of its own
            shape = _shape(data, relief, label, relief.boxes(parts) - [box[0], box[0], box[2], box[2]])
        mesh = shape.mesh
        if mesh is None:
            mesh = _mesh(gltf, data, relief, shape, box, materials, photo is not None)
            if photo is None:  # the elements of one shape are instances of one mesh
                shape.mesh = mesh
        root.children.append(len(gltf.nodes))
        gltf.nodes.append(gl.Node(name=f"{LABELS[label]} {i}", mesh=mesh,
                                  translation=[round(float(box[0]), 6), round(float(box[2]), 6), 0.0],
                                  extras={"label": LABELS[label], "path": path, "box_px": [x0, y0, x1, y1]}))
    data.blob += b"\0" * (-len(data.blob) % 4)
    if binary:
        gltf.buffers.append(gl.Buffer(byteLength=len(data.blob)))
        gltf.set_binary_blob(bytes(data.blob))
        return b"".join(gltf.save_to_bytes())
    uri = "data:application/octet-stream;base64," + base64.b64encode(bytes(data.blob)).decode("ascii")
    gltf.buffers.append(gl.Buffer(byteLength=len(data.blob), uri=uri))
    return gltf.gltf_to_json(indent=None, separators=(",", ":")).encode("utf-8")


def _triangles(quads: np.ndarray) -> np.ndarray:
    """The indices of the quads numbered ``quads``, two triangles each, wound as the quads are."""
    return (4 * np.asarray(quads)[:, None] + np.array([0, 1, 2, 0, 2, 3])).reshape(-1)


@dataclass
class _Shape:
    """An element's box at the origin: the accessors of its corners and their normals, of the indices of the whole
    box, of its front and of its sides (None without); its corners; its mesh, once made (without the photo)."""

    label: int
    position: int
    normal: int
    whole: int
    front: int
    sides: int | None
    corners: np.ndarray
    mesh: int | None = None


def _shape(data: _Data, relief: Relief, label: int, boxes: np.ndarray) -> _Shape:
    """The shape of an element drawn as ``boxes`` (left, right, bottom, top in metres from its node's origin)."""
    quads, normals = box_quads(boxes, DEPTHS[LABELS[label]])
    corners = quads.reshape(-1, 3)
    k = len(normals)
    normal = np.tile(np.repeat(np.array([NORMALS[n] for n in normals], dtype=np.float32), 4, axis=0), (len(boxes), 1))
    numbers = np.arange(len(boxes) * k).reshape(len(boxes), k)  # each part's quads, its front first
    whole = data.accessor(_triangles(numbers.reshape(-1)))
    front = data.accessor(_triangles(numbers[:, 0])) if k > 1 else whole
    sides = data.accessor(_triangles(numbers[:, 1:].reshape(-1))) if k > 1 else None
    return _Shape(label, data.accessor(corners, bounds=True), data.accessor(normal), whole, front, sides, corners)


def _mesh(gltf: gl.GLTF2, data: _Data, relief: Relief, shape: _Shape, box: np.ndarray, materials: dict[int, int],
          textured: bool) -> int:
    """A mesh of ``shape``: one primitive in the label's material, or, ``textured``, the front showing the photo
    where the element is (``box``: left, right, bottom, top in metres) and the sides in the label's material."""
    attributes = {"POSITION": shape.position, "NORMAL": shape.normal}
    material = materials[shape.label]
    if not textured:
        primitives = [gl.Primitive(attributes=gl.Attributes(**attributes), indices=shape.whole, material=material)]
    else:
        corners = shape.corners
        uv = np.stack([(box[0] + corners[:, 0]) / relief.width_m, 1 - (box[2] + corners[:, 1]) / relief.height_m],
                      axis=1)
        primitives = [gl.Primitive(attributes=gl.Attributes(**attributes, TEXCOORD_0=data.accessor(uv)),
                                   indices=shape.front, material=materials[PHOTO])]
        if shape.sides is not None:
            primitives.append(gl.Primitive(attributes=gl.Attributes(**attributes), indices=shape.sides,
                                           material=material))
    gltf.meshes.append(gl.Mesh(name=LABELS[shape.label], primitives=primitives))
    return len(gltf.meshes) - 1


def shrunk_rgb(photo: Image.Image, factor: int, rows: int = 256) -> Image.Image:
    """``photo`` in RGB, ``factor`` times smaller (each block of factor x factor pixels averaged), made strip by
    strip: PIL's own `reduce` of an image with alpha premultiplies a full-size copy first, and a conversion first
    makes a full-size RGB copy."""
    w, h = photo.size
    out = Image.new("RGB", (-(-w // factor), -(-h // factor)))
    step = factor * rows
    for y in range(0, h, step):
        strip = photo.crop((0, y, w, min(h, y + step))).convert("RGB")
        out.paste(strip.reduce(factor) if factor > 1 else strip, (0, y // factor))
    return out


def _add_photo(gltf: gl.GLTF2, data: _Data, photo: Image.Image) -> None:
    """The photo as a JPEG texture and the material ``photo`` that shows it. A large photo is shrunk before it is
    converted (a JPEG decoded at a reduced scale; others reduced by a whole factor, which averages each channel on
    its own: no full-size premultiplied or converted copy), so the call holds one decoded copy at most."""
    photo.draft("RGB", (MAX_TEXTURE, MAX_TEXTURE))
    if photo.width * photo.height > MAX_TEXTURE**2:  # no converted (or premultiplied) full-size copy
        image = shrunk_rgb(photo, -(-max(photo.size) // MAX_TEXTURE))
    else:
        image = photo.convert("RGB")
    image.thumbnail((MAX_TEXTURE, MAX_TEXTURE))
    out = io.BytesIO()
    image.save(out, "JPEG", quality=90)
    gltf.images.append(gl.Image(bufferView=data.view(out.getvalue()), mimeType="image/jpeg", name="photo"))
    gltf.samplers.append(gl.Sampler(magFilter=gl.LINEAR, minFilter=gl.LINEAR_MIPMAP_LINEAR, wrapS=gl.CLAMP_TO_EDGE,
                                    wrapT=gl.CLAMP_TO_EDGE))
    gltf.textures.append(gl.Texture(sampler=0, source=0))
    gltf.materials.append(gl.Material(name="photo", pbrMetallicRoughness=gl.PbrMetallicRoughness(
        baseColorTexture=gl.TextureInfo(index=0), metallicFactor=0.0, roughnessFactor=1.0)))
