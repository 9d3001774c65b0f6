"""Small C libraries for the hot paths, built on first use with the machine's C compiler.

- ``step.c``: the decoder step, one call per step instead of some 80 torch operations; `facaid.decoding.step`
  loads it (the model's weights are the decoding layer's, so its Python side lives there).
- `facaid.native.rects` (``rects.c``, ``rects_json.c``): executing and flattening labelled rectangles
  (`facaid.segmentation`), and writing them as JSON.

Each library is compiled once per source and machine into ``$FACAID_CACHE`` (default ``~/.cache/facaid``) with
``-O3 -march=native`` (`facaid.native.build`); without a C compiler, or with ``FACAID_NATIVE=0``, `load` returns
None and the callers keep their torch or numpy path, which the tests check the C against. This package imports
neither torch nor numpy.
"""

from facaid.native.build import build, cache_dir, load

__all__ = ["build", "cache_dir", "load"]
