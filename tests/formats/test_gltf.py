"""The glTF export, read back by trimesh (not the library that writes it): one node per element carrying its label
and tree path, a repeat's windows instances of one mesh placed where the procedure draws them, a material per
class, the scale stated, and the photo on the fronts where given."""

import io
import json
import struct
from collections import Counter

import numpy as np
import pytest
import trimesh
from format_helpers import window_grid

from facaid.formats import annotation
from facaid.formats.gltf import procedure_gltf
from facaid.formats.relief import DEPTHS, MAX_MESH_RECTS, MeshTooLarge, procedure_relief
from facaid.formats.render import render_segmentation
from facaid.generator import generate
from facaid.grammar.execute import to_segmentation
from facaid.labels import LABELS, PALETTE
from facaid.segmentation import rasterize

SCALE = 0.02


def load(data: bytes, kind: str = "glb") -> trimesh.Scene:
    return trimesh.load(io.BytesIO(data), file_type=kind, force="scene")


def elements(scene: trimesh.Scene) -> dict[str, dict]:
    """Each node that carries a label: its extras, its geometry's names and their world bounds."""
    labelled = {node: (parent, data["metadata"]) for (parent, node), data in scene.graph.transforms.edge_data.items()
                if "label" in data.get("metadata", {})}
    # trimesh copies a node's extras to the frames it makes for its primitives, beyond the first one
    found = {node: {"extras": extras, "geometry": [], "bounds": []} for node, (parent, extras) in labelled.items()
             if parent not in labelled}
    for node in scene.graph.nodes_geometry:  # a node of several primitives holds them in child frames
        transform, name = scene.graph[node]
        owner = found[node] if node in found else found[scene.graph.transforms.parents[node]]
        owner["geometry"].append(name)
        owner["bounds"].append(trimesh.transform_points(scene.geometry[name].bounds, transform))
    return found


def glb_json(data: bytes) -> dict:
    """The JSON chunk of a .glb, read by its layout (12-byte header, then a chunk's length and type)."""
    magic, version, _ = struct.unpack_from("<4sII", data)
    assert (magic, version) == (b"glTF", 2)
    length, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    return json.loads(data[20:20 + length])


@pytest.fixture(scope="module")
def proc():
    return generate(3).procedure


def test_one_node_per_element_with_its_label_path_and_place(proc):
    relief = procedure_relief(proc, SCALE)  # the elements the annotations hold, and the pieces of wall
    found = elements(load(procedure_gltf(proc, SCALE)))
    assert len(found) == len(relief.rows)
    assert sorted(tuple(e["extras"]["box_px"]) for e in found.values()) == sorted(map(tuple, relief.rows[:, 1:]
                                                                                      .tolist()))
    nodes = dict(proc.nodes())
    height = round(proc.height)
    for name, element in found.items():
        label, path, (x0, y0, x1, y1) = (element["extras"][k] for k in ("label", "path", "box_px"))
        assert nodes[path].is_leaf and nodes[path].label == label  # the path names a leaf that draws it
        parts = relief.parts_of(int(name.split()[-1]))[:, 1:]  # the node "window 12" is the relief's row 12
        assert parts.min(axis=0)[:2].tolist() >= [x0, y0] and parts.max(axis=0)[2:].tolist() <= [x1, y1]
        low, high = np.min([b[0] for b in element["bounds"]], axis=0), np.max([b[1] for b in element["bounds"]],
                                                                               axis=0)
        expected = np.array([[parts[:, 0].min() * SCALE, (height - parts[:, 3].max()) * SCALE, min(0, DEPTHS[label])],
                             [parts[:, 2].max() * SCALE, (height - parts[:, 1].min()) * SCALE, max(0, DEPTHS[label])]])
        assert np.allclose([low, high], expected, atol=1e-5), (label, path)


def test_repeated_windows_are_instances_of_one_mesh(proc):
    found = elements(load(procedure_gltf(proc, SCALE)))
    windows = [e for e in found.values() if e["extras"]["label"] == "window"]
    assert len(windows) == sum(LABELS[r.label] == "window" for r in annotation.elements(to_segmentation(proc))) == 30
    meshes = {e["geometry"][0] for e in windows}
    assert len(meshes) < len(windows) / 4  # 30 windows of a few sizes
    by_mesh = {m: [e for e in windows if e["geometry"][0] == m] for m in meshes}
    shared = max(by_mesh.values(), key=len)
    assert len(shared) >= 5
    assert max(Counter(e["extras"]["path"] for e in shared).values()) >= 2  # copies of one leaf of a repeat
    sizes = {tuple((e["bounds"][0][1] - e["bounds"][0][0]).round(6)) for e in shared}
    corners = {tuple(e["bounds"][0][0].round(6)) for e in shared}
    assert len(sizes) == 1 and len(corners) == len(shared)  # the same box, moved to each place


def test_materials_by_class_in_the_palette_colours(proc):
    scene = load(procedure_gltf(proc, SCALE))
    found = elements(scene)
    for element in found.values():
        material = scene.geometry[element["geometry"][0]].visual.material
        assert material.name == element["extras"]["label"]
    by_name = {g.visual.material.name: g.visual.material for g in scene.geometry.values()}
    for name, material in by_name.items():
        # glTF's colours are linear; trimesh gives them back as bytes
        linear = [255 * ((c / 255 + 0.055) / 1.055) ** 2.4 for c in PALETTE[name]]
        assert np.allclose(np.asarray(material.baseColorFactor)[:3], linear, atol=1), name


def test_the_scale_is_stated_and_the_text_form_reads_the_same(proc):
    glb = procedure_gltf(proc, SCALE, scale_from="the photo's real width, 8.88 m")
    about = glb_json(glb)["asset"]["extras"]["facaid"]
    assert about["metres_per_pixel"] == SCALE and about["units"] == "metres"
    assert about["scale"] == "0.02 m per pixel (the photo's real width, 8.88 m): 8.88 m x 15.94 m"
    text = procedure_gltf(proc, SCALE, binary=False)
    assert json.loads(text)["asset"]["extras"]["facaid"]["metres_per_pixel"] == SCALE
    assert len(elements(load(text, "gltf"))) == len(elements(load(glb)))


def test_the_photo_is_on_the_fronts_where_each_element_is(proc):
    seg = annotation.as_annotated(to_segmentation(proc))
    photo = render_segmentation(seg)  # a photo in the palette: each front must show its own label's colour
    painted = rasterize(seg)
    scene = load(procedure_gltf(proc, SCALE, photo=photo))
    found = elements(scene)
    assert len(found) == len(procedure_relief(proc, SCALE).rows)
    checked = 0
    for element in found.values():
        label = element["extras"]["label"]
        textured = [scene.geometry[name] for name in element["geometry"]
                    if getattr(scene.geometry[name].visual, "uv", None) is not None]
        assert len(textured) == 1 and len(element["geometry"]) == (1 if DEPTHS[label] == 0 else 2)
        front = textured[0]
        image = front.visual.material.baseColorTexture
        assert image.size == photo.size
        u, v = front.visual.uv.mean(axis=0)  # trimesh's v runs up from the image's bottom
        colour = image.convert("RGB").getpixel((int(u * image.width), int((1 - v) * image.height)))
        x0, y0, x1, y1 = element["extras"]["box_px"]
        shows = painted[(y0 + y1) // 2, (x0 + x1) // 2] == LABELS.index(label)  # not a window behind its blind
        if min(x1 - x0, y1 - y0) >= 6 and shows:  # JPEG blurs the colour of a sliver
            assert np.abs(np.subtract(colour, PALETTE[label])).max() <= 24, (label, colour)
            checked += 1
    assert checked > len(found) / 2


@pytest.mark.parametrize("bad", [0, -1, float("nan"), 1e6])
def test_a_bad_scale_is_refused(proc, bad):
    with pytest.raises(ValueError, match="scale must be a number of metres per pixel"):
        procedure_gltf(proc, bad)


def test_a_procedure_of_too_many_rectangles_is_refused_with_its_count():
    huge = window_grid(200, 60)
    with pytest.raises(MeshTooLarge, match=f"draws 24000 rectangles; a mesh is made of at most {MAX_MESH_RECTS}"):
        procedure_gltf(huge, 0.01)


@pytest.mark.parametrize("mode", ["RGBA", "RGB", "LA", "P"])
def test_a_large_photo_is_shrunk_strip_by_strip_as_a_whole_reduce_would(mode):
    """`shrunk_rgb` averages the same blocks as converting to RGB and reducing the whole (no full-size copy)."""
    from PIL import Image

    from facaid.formats.gltf import shrunk_rgb

    rng = np.random.default_rng(3)
    pixels = rng.integers(0, 256, size=(601, 803, 4), dtype=np.uint8)
    photo = Image.fromarray(pixels, "RGBA").convert(mode)
    for factor in (1, 2, 3):
        mine = np.asarray(shrunk_rgb(photo, factor, rows=40), dtype=int)
        whole = np.asarray(photo.convert("RGB").reduce(factor), dtype=int)
        assert mine.shape == whole.shape and np.abs(mine - whole).max() <= 1
