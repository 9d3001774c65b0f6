"""A procedure as CityJSON (2.0, or 1.0 for older tools): the facade as an LoD3 building for GIS and city models.

One `Building` whose LoD3 `MultiSurface` is the relief (`facaid.formats.relief`): every element's front and the sides
that join it to the wall plane, each a rectangle wound counter-clockwise seen from outside. Each window and shop
front is a `Window` semantic surface of its own and each door a `Door` (its label, and its node's path in the
tree, beside its type; the front of an element drawn in parts is several rings of the one surface); everything
else, reveals included, is a `WallSurface`, one per label. Coordinates are local
metres (no reference system: place the facade in your model), x along the facade, y into the building, z up,
written as millimetres by the file's transform; the building's attributes say the scale.
"""

from __future__ import annotations

import json
import math

import numpy as np

from facaid.formats.relief import DEPTHS, box_quads, procedure_relief
from facaid.grammar.procedure import Procedure

VERSIONS = ("2.0", "1.0")
OPENINGS = {"window": "Window", "shop": "Window", "door": "Door"}  # label -> semantic surface; else WallSurface
UNIT = 0.001  # metres per integer of the vertices: millimetres, or finer for a scale under a centimetre a pixel


def procedure_cityjson(proc: Procedure, scale: float | None = None, scale_from: str = "", name: str = "",
                       version: str = "2.0") -> dict:
    """The procedure as a CityJSON object (see the module's docstring) of ``version`` (`VERSIONS`); ``scale`` in
    metres per pixel (default `cga.default_scale`) with ``scale_from``, where it came from; ``name`` titles
    it. `relief.MeshTooLarge` for a procedure of too many rectangles, a ValueError for a bad scale."""
    if version not in VERSIONS:
        raise ValueError(f"CityJSON version must be one of {', '.join(VERSIONS)}, got {version!r}")
    relief = procedure_relief(proc, scale, scale_from)
    labels = relief.labels()
    corners, semantics, values = [], [], []
    walls: dict[str, int] = {}  # label -> its WallSurface

    def wall(label: str) -> int:
        if label not in walls:
            walls[label] = len(semantics)
            semantics.append({"type": "WallSurface", "label": label})
        return walls[label]

    parts = relief.boxes(relief.parts)
    starts = np.searchsorted(relief.parts[:, 0], np.arange(len(labels) + 1))  # each row's parts, in row order
    for i, label in enumerate(labels):
        quads, _ = box_quads(parts[starts[i]:starts[i + 1]], DEPTHS[label])
        corners.append(quads.reshape(-1, 4, 3))  # (parts x k, 4, 3): each part's front first
        if label in OPENINGS:
            opening = len(semantics)
            semantics.append({"type": OPENINGS[label], "label": label, "path": relief.paths[i]})
            for _ in range(len(quads)):
                values += [opening] + [wall(label)] * (quads.shape[1] - 1)
        else:
            values += [wall(label)] * (quads.shape[0] * quads.shape[1])
    quads = np.concatenate(corners) if corners else np.zeros((0, 4, 3))
    unit = min(UNIT, 10.0 ** math.floor(math.log10(relief.scale / 10)))  # a tenth of a pixel at least
    # relief x right, y up, z towards the viewer -> x along the facade, y into the building, z up (a rotation:
    # every ring stays counter-clockwise seen from outside)
    points = np.rint(np.stack([quads[..., 0], -quads[..., 2], quads[..., 1]], axis=-1) / unit).astype(np.int64)
    vertices, index = np.unique(points.reshape(-1, 3), axis=0, return_inverse=True)
    rings = index.reshape(-1, 4).tolist()
    title = name or "FaçAID facade"
    geometry = {"type": "MultiSurface", "lod": "3" if version == "2.0" else 3,
                "boundaries": [[ring] for ring in rings], "semantics": {"surfaces": semantics, "values": values}}
    building = {"type": "Building", "attributes": {
        "name": title, "facaid_metres_per_pixel": relief.scale, "facaid_scale_from": relief.scale_from,
        "facaid_scale": relief.describe(), "facaid_width_m": round(relief.width_m, 4),
        "facaid_height_m": round(relief.height_m, 4)}, "geometry": [geometry] if rings else []}
    out = {"type": "CityJSON", "version": version, "transform": {"scale": [unit] * 3, "translate": [0.0] * 3},
           "CityObjects": {"facade": building}, "vertices": vertices.tolist()}
    if version == "2.0":
        out["metadata"] = {"title": f"{title} at {relief.describe()}"}
    return out


def cityjson_text(obj: dict) -> str:
    return json.dumps(obj, separators=(",", ":"), ensure_ascii=False)
