"""Executing procedures and flattening rectangles in C (`facaid/native/rects.c`), for the generator's hot path, and
writing them as JSON (`facaid/native/rects_json.c`).

- `flatten_rows`: `facaid.segmentation.flatten_array` without numpy's fixed cost per call, which dominates on
  the few hundred rectangles of a facade.
- `executed_rows`: a procedure executed, rounded and flattened in one call (`facaid.grammar.execute.flat_rows`):
  the tree goes over as arrays, breadth first, and the C walks it with the layout rules of
  `facaid.grammar.layout` in the same double arithmetic.

The Python paths stay the reference and the fallback (no compiler, ``FACAID_NATIVE=0``, or input the C declines);
the tests check both give the same rows on thousands of generated facades and random rectangles.
"""

from __future__ import annotations

import ctypes

import numpy as np

from facaid.labels import LABEL_ID, LABELS, PRIORITY
from facaid.native.build import load

_PRIORITY = np.asarray(PRIORITY, dtype=np.int64)
_NAMES = b"".join(name.encode() + b"\0" for name in LABELS)
_MODES = {"pieces": 0, "footprint": 1}
_RULES = {"leaf": 0, "split": 1, "repeat": 2, "mirror": 3}
_SIZE_MODES = {"abs": 0, "rel": 1, "flt": 2}


class _Unused:  # the size an exception's node holds in the arrays: never read
    mode, value = "abs", 0.0


_UNUSED = _Unused()
_NONE_I, _NONE_F = np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.float64)  # a tree without exceptions


def _declare(lib: ctypes.CDLL) -> None:
    lib.facaid_flatten.restype = ctypes.c_int64
    lib.facaid_flatten.argtypes = [ctypes.c_int64, ctypes.c_int64, ctypes.c_void_p, ctypes.c_int64, ctypes.c_void_p,
                                   ctypes.c_int, ctypes.c_void_p, ctypes.c_int64]
    lib.facaid_execute.restype = ctypes.c_int64
    lib.facaid_execute.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
                                   ctypes.c_void_p, ctypes.c_void_p, ctypes.c_double,
                                   ctypes.c_double, ctypes.c_int64, ctypes.c_int64, ctypes.c_int64, ctypes.c_int64,
                                   ctypes.c_void_p, ctypes.c_int, ctypes.c_void_p, ctypes.c_int64]


def _declare_json(lib: ctypes.CDLL) -> None:
    lib.facaid_rects_json.restype = ctypes.c_int64
    lib.facaid_rects_json.argtypes = [ctypes.c_void_p, ctypes.c_int64, ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int64]


def library() -> ctypes.CDLL | None:
    """``rects.c``: flattening and executing."""
    return load("rects", _declare)


def json_library() -> ctypes.CDLL | None:
    """``rects_json.c``: rectangles written as JSON."""
    return load("rects_json", _declare_json)


def flatten_rows(width: int, height: int, arr: np.ndarray, wall: str = "pieces") -> np.ndarray | None:
    """`flatten_array`'s rows computed in C; None when the library is unavailable or the rows are not plain
    (labels outside the 12, a rectangle with x1 < x0 or y1 < y0), which the numpy path then handles."""
    lib = library()
    if lib is None:
        return None
    rows = np.ascontiguousarray(arr, dtype=np.int64)
    return _call(lambda out, cap: lib.facaid_flatten(width, height, rows.ctypes.data, len(rows), _PRIORITY.ctypes.data,
                                                     _MODES[wall], out.ctypes.data, cap), 2 * len(rows) + 16)


def _call(fn, cap: int, row: tuple[int, ...] = (5,), dtype=np.int64) -> np.ndarray | None:
    """Call ``fn(out, cap)`` with room for ``cap`` rows of shape ``row``, again with more if it needs more; None when
    it declines its input (a negative code other than -1, which means memory ran out)."""
    while True:
        out = np.empty((cap, *row), dtype=dtype)
        n = fn(out, cap)
        if n == -1:
            raise MemoryError("the native rectangles library ran out of memory")
        if n < 0:
            return None
        if n <= cap:
            return out[:n]
        cap = n


def _tree(root) -> tuple[list, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The tree as `rects.c` reads it: (nodes breadth first, node records, size modes, size values, exceptions,
    their paths, their size values)."""
    nodes: list[int] = []
    sizes: list = []
    overs: list[int] = []
    steps: list[int] = []
    ovalues: list[float] = []
    queue = [root]
    for node in queue:  # breadth first: a node's children are consecutive, and node k's size is at k - 1
        kids = node.children
        if node.rule == "leaf":  # most nodes are
            nodes += (0, 0, 0, 0, 0, LABEL_ID[node.label] if node.label else 0, 0, 0, 0, 0)
            continue
        count = node.count
        nodes += (_RULES[node.rule], node.axis == "y", -1 if count == "fill" else count or 0, node.tail,
                  node.center, 0, len(queue), len(kids), len(overs) // 6, len(node.exceptions))
        queue += kids
        sizes += node.sizes
        for o in node.exceptions or ():  # their nodes queue after the children, with an unused size each
            overs += (o.copy, len(steps), len(o.path), -1 if o.size is None else _SIZE_MODES[o.size.mode],
                      -1 if o.node is None else len(queue), len(ovalues))
            steps += o.path
            ovalues.append(0.0 if o.size is None else o.size.value)
            if o.node is not None:
                queue.append(o.node)
                sizes.append(_UNUSED)
    modes = [_SIZE_MODES[s.mode] for s in sizes] or [0]
    values = [s.value for s in sizes] or [0.0]
    if not overs:  # most trees: no arrays to make
        return (queue, np.array(nodes, dtype=np.int64), np.array(modes, dtype=np.int64),
                np.array(values, dtype=np.float64), _NONE_I, _NONE_I, _NONE_F)
    return (queue, np.array(nodes, dtype=np.int64), np.array(modes, dtype=np.int64),
            np.array(values, dtype=np.float64), np.array(overs, dtype=np.int64), np.array(steps, dtype=np.int64),
            np.array(ovalues, dtype=np.float64))


def executed_rows(root, extent: tuple[float, float], max_count: int, max_leaves: int,
                  wall: str = "pieces") -> np.ndarray | None:
    """The tree under ``root`` executed on ``extent`` (the procedure's width and height), its leaves rounded to
    whole pixels and flattened: ``flatten_array(w, h, leaf_array(...), wall)`` with the extent rounded (w, h).
    None when the library is unavailable, or the tree expands to more than ``max_leaves`` leaves or has a
    ``"fill"`` repeat of no length (the Python executor says which)."""
    lib = library()
    if lib is None:
        return None
    queue, tree, modes, values, overs, steps, ovalues = _tree(root)
    width, height = round(extent[0]), round(extent[1])
    return _call(lambda out, cap: lib.facaid_execute(
        tree.ctypes.data, modes.ctypes.data, values.ctypes.data, overs.ctypes.data, steps.ctypes.data,
        ovalues.ctypes.data, float(extent[0]), float(extent[1]), width, height,
        max_count, max_leaves, _PRIORITY.ctypes.data, _MODES[wall], out.ctypes.data, cap), max(1024, 8 * len(queue)))


def rects_json(rows: np.ndarray) -> bytes | None:
    """int rows (label, x0, y0, x1, y1) as the JSON of `facaid.segmentation.rect_dicts`, byte for byte what orjson
    writes for it; None when the library is unavailable or a label is not one of the 12."""
    lib = json_library()
    if lib is None:
        return None
    rows = np.ascontiguousarray(rows, dtype=np.int64)
    text = _call(lambda out, cap: lib.facaid_rects_json(rows.ctypes.data, len(rows), _NAMES, out.ctypes.data, cap),
                 160 * len(rows) + 2, row=(), dtype=np.uint8)
    return None if text is None else text.tobytes()
