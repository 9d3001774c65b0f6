"""Procedures the format and download tests share."""

from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure


def window_grid(columns: int, rows: int, size: int = 2000, apart: bool = False) -> Procedure:
    """``rows`` rows of ``columns`` windows, each beside a piece of wall: ``2 * columns * rows`` rectangles;
    window_grid(200, 60) draws 24,000, past every 3D export's cap. The windows of a column touch, so they are one
    element each column (one window, to an annotator); ``apart``: a band of wall under each row, so that each window
    is one (``rows`` rectangles more)."""
    row = Node.repeat("x", columns, [(Size("flt", 1), Node.leaf("window")), (Size("flt", 1), Node.leaf("facade"))])
    band = [(Size("flt", 1), Node.leaf("facade"))] if apart else []
    return Procedure(width=size, height=size, root=Node.repeat("y", rows, [(Size("flt", 1), row), *band]))
