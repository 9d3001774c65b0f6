"""Photos made here for the photo code's tests: a stucco wall with a lattice of windows (`GRID`) under a lighting
gradient, with noise, closed blinds and, asked for, reflections."""

import numpy as np
from PIL import Image

GRID = [(40 + 110 * i, 30 + 120 * j, 100 + 110 * i, 110 + 120 * j) for j in range(4) for i in range(6)]
CLOSED = {9, 20}  # windows whose blinds are down: they look like no other


def lattice_photo(seed: int = 0, gradient: bool = True, reflections: bool = False, grid=GRID,
                  closed=CLOSED) -> Image.Image:
    """A stucco wall (noise) lit from the left (a gradient from 0.55 to 1.25 of its brightness), each window of
    ``grid`` dark glass with a light frame and a cross of mullions over a stone sill; the ``closed`` ones a plain grey
    blind. With ``reflections``, a bright diagonal band across each glass at its own place: no two windows look the
    same."""
    rng = np.random.default_rng(seed)
    pixels = 175 + rng.normal(0, 8, (520, 700))
    for k, (x0, y0, x1, y1) in enumerate(grid):
        pixels[y0 - 4:y1 + 4, x0 - 4:x1 + 4] = 225  # the frame
        if k in closed:
            pixels[y0:y1, x0:x1] = 140 + rng.normal(0, 3, (y1 - y0, x1 - x0))
        else:
            pixels[y0:y1, x0:x1] = 45 + rng.normal(0, 8, (y1 - y0, x1 - x0))
            pixels[y0:y1, (x0 + x1) // 2 - 2:(x0 + x1) // 2 + 2] = 210
            pixels[(y0 + y1) // 2 - 2:(y0 + y1) // 2 + 2, x0:x1] = 210
        if reflections and k not in closed:
            yy, xx = np.mgrid[y0:y1, x0:x1]
            pixels[y0:y1, x0:x1] += 40 * (np.abs(xx - x0 - 0.7 * (yy - y0) - rng.uniform(-20, 60)) < 8)
        pixels[y1 + 4:y1 + 12, x0 - 8:x1 + 8] = 110  # the sill's shadowed face
    if gradient:
        pixels *= np.linspace(0.55, 1.25, 700)[None, :]
    return Image.fromarray(np.clip(pixels, 0, 255).astype(np.uint8), "L")


def sill_of(box):
    """The sill `lattice_photo` paints under the window ``box``."""
    x0, y0, x1, y1 = box
    return (x0 - 8, y1 + 4, x1 + 8, y1 + 12)
