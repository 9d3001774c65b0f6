"""The pictures of docs/grammar.md, made by the project itself: ``python -m facaid.docs [OUT_DIR]``.

Each figure is a small procedure built here; the test suite re-renders them and compares them with the
committed PNGs, so the documentation cannot drift from the grammar.
"""

from __future__ import annotations

import sys
from pathlib import Path

from PIL import Image

from facaid.formats.render import legend, render_segmentation, side_by_side
from facaid.generator import STYLE_NAMES, generate
from facaid.grammar import Node, Procedure, Size, to_segmentation
from facaid.grammar.nodes import Override

A, R, F = (lambda v: Size("abs", v)), (lambda v: Size("rel", v)), (lambda v: Size("flt", v))
L = Node.leaf
DOCS_IMG = Path(__file__).resolve().parent.parent / "docs" / "img"


def _tile() -> Node:
    column = Node.split("y", [(F(20), L("facade")), (A(10), L("cornice")), (A(44), L("window")), (A(6), L("sill")),
                              (F(20), L("facade"))])
    return Node.split("x", [(F(1), L("facade")), (A(34), column), (F(1), L("facade"))], role="tile")


def figures() -> dict[str, list[Procedure]]:
    """Figure name -> the procedures drawn side by side in it."""
    split_x = Node.split("x", [(A(40), L("pillar")), (R(0.3), L("window")), (F(1), L("facade")), (F(2), L("shop"))])
    split_y = Node.split("y", [(A(20), L("molding")), (F(1), L("window")), (A(15), L("balcony"))])
    repeat = Node.repeat("x", 4, [(A(8), L("pillar")), (F(50), _tile())], tail=1, role="bay")
    fill = Node.repeat("x", "fill", [(A(8), L("pillar")), (F(50), _tile())], tail=1, role="bay")
    door_window = Node.split("x", [(A(14), L("door")), (F(1), L("window"))])
    mirror_c = Node.mirror("x", [(A(30), L("shop")), (F(1), door_window), (A(40), L("deco"))], center=True)
    mirror_n = Node.mirror("x", [(A(30), L("shop")), (F(1), door_window)], center=False)
    nested = Node.split("y", [
        (A(20), L("background", role="margin")),
        (A(12), L("molding", role="band")),
        (F(1), Node.repeat("y", 3, [(F(100), Node.repeat("x", 4, [(F(60), _tile())], role="floor")),
                                    (A(6), L("molding", role="band"))], role="floors")),
        (A(70), Node.mirror("x", [(A(10), L("facade")), (F(60), Node.split("y", [(A(10), L("facade")),
                                                                                   (F(1), L("shop"))])),
                                  (A(40), Node.split("y", [(F(1), L("facade")), (A(55), L("door"))]))],
                            center=True, role="ground")),
    ], role="facade")
    return {
        "leaf": [Procedure(60, 80, L("window"))],
        "split_x": [Procedure(240, 80, split_x), Procedure(360, 80, split_x)],
        "split_y": [Procedure(80, 120, split_y)],
        "repeat": [Procedure(260, 120, repeat)],
        "repeat_fill": [Procedure(200, 120, fill), Procedure(320, 120, fill), Procedure(440, 120, fill)],
        "mirror": [Procedure(260, 60, mirror_c), Procedure(260, 60, mirror_n)],
        "facade": [Procedure(300, 420, nested)],
        "exceptions": [Procedure(300, 300, _floors([])), Procedure(300, 300, _floors(EXCEPTIONS))],
    }


# the exceptions of the picture in docs/grammar.md, on the floors repeat of `_floors`
EXCEPTIONS = [
    Override(1, (0, 2, 1, 2), node=L("blind")),  # floor 1, tile 2: the blind closed
    Override(0, (0, 3, 1, 3), size=A(0), node=L("facade")),  # floor 0, tile 3: no sill
    Override(3, (0,), size=F(110)),  # floor 3 (the lowest): taller
    Override(2, (0, 0), node=Node.split("x", [(F(1), L("facade")), (A(34), Node.split("y", [
        (F(1), L("facade")), (A(60), L("door"))])), (F(1), L("facade"))], role="entrance")),  # a door
]


def _floors(exceptions: list[Override]) -> Node:
    """Four floors of four tiles; ``exceptions`` on the floors."""
    floors = Node.repeat("y", 4, [(F(70), Node.repeat("x", 4, [(F(60), _tile())], role="floor"))], role="floors")
    floors.exceptions = list(exceptions)
    return Node.split("y", [(A(14), L("molding", role="band")), (F(1), floors)], role="facade")


def render_figure(procs: list[Procedure], height: int = 160) -> Image.Image:
    images = [render_segmentation(to_segmentation(p), outline=True) for p in procs]
    return side_by_side(images, height=height)


def style_gallery(seed: int = 2) -> Image.Image:
    images = [render_segmentation(generate(seed + k, style).segmentation, outline=True)
              for k, style in enumerate(STYLE_NAMES)]
    return side_by_side(images, height=300)


def write_figures(out_dir: Path = DOCS_IMG) -> list[Path]:
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, procs in figures().items():
        path = out_dir / f"grammar_{name}.png"
        render_figure(procs, height=320 if name == "facade" else 160).save(path)
        written.append(path)
    for name, image in (("styles", style_gallery()), ("legend", legend())):
        path = out_dir / f"{name}.png"
        image.save(path)
        written.append(path)
    return written


if __name__ == "__main__":
    for p in write_figures(Path(sys.argv[1]) if len(sys.argv) > 1 else DOCS_IMG):
        print(p)
