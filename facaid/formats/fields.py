"""The fields of an annotation file read and checked, for `facaid.formats.interchange`'s readers: numbers, sides,
labels by name (with their aliases), boxes rounded and clipped, lists and objects, and the one image of a file of
several; every problem an `InterchangeError` naming the field."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import PurePosixPath
from typing import Any

from facaid.labels import LABEL_ID, LABELS
from facaid.segmentation import MAX_PIXELS, MAX_RECTS, MAX_SIDE, Rect, SegmentationError

ALIASES = {"moulding": "molding", "decoration": "deco"}


class InterchangeError(SegmentationError):
    """A file that cannot be read as annotations of the 12 classes; the message names the offending field."""


class SeveralImages(InterchangeError):
    """A file of several images read without naming one; ``names`` are theirs."""

    def __init__(self, names: list[str]):
        listing = ", ".join(names[:20]) + (f" and {len(names) - 20} more" if len(names) > 20 else "")
        super().__init__(f"the file holds {len(names)} images ({listing}): name the one to read")
        self.names = names


class Notes:
    """Warnings, one line per kind, naming the items."""

    def __init__(self):
        self.items: dict[str, list[str]] = {}

    def add(self, message: str, where: str) -> None:
        self.items.setdefault(message, []).append(where)

    def lines(self) -> tuple[str, ...]:
        return tuple(f"{message}: {', '.join(items[:10])}" + (f" and {len(items) - 10} more" if len(items) > 10
                                                               else "")
                     for message, items in self.items.items())


def number(value: Any, where: str) -> float:
    if isinstance(value, str):  # XML attributes
        try:
            value = float(value)
        except ValueError:
            raise InterchangeError(f"{where} must be a number, got {value[:40]!r}") from None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InterchangeError(f"{where} must be a number, got {type(value).__name__} {str(value)[:40]}")
    try:
        if math.isfinite(value):
            return value
    except OverflowError:  # an integer too large for a float
        pass
    raise InterchangeError(f"{where} must be a finite number, got {str(value)[:40]}")


def side(value: Any, where: str) -> int:
    if value is None:
        raise InterchangeError(f"{where} is missing: the image's size is needed")
    side = number(value, where)
    if side != int(side) or not 1 <= side <= MAX_SIDE:
        raise InterchangeError(f"{where} must be a whole number of pixels from 1 to {MAX_SIDE}, got {value!r}")
    return int(side)


def size_of(width: Any, height: Any, where: str, names=("width", "height")) -> tuple[int, int]:
    w, h = side(width, f"{where}.{names[0]}".lstrip(".")), side(height, f"{where}.{names[1]}".lstrip("."))
    if w * h > MAX_PIXELS:
        raise InterchangeError(f"{where or 'the image'} is too large: {w}x{h} is over {MAX_PIXELS} pixels")
    return w, h


def label_of(name: Any, where: str) -> int:
    if isinstance(name, str):
        key = " ".join(name.lower().replace("_", " ").replace("-", " ").split())
        for candidate in (key, key[:-3] + "y" if key.endswith("ies") else None, key[:-1] if key.endswith("s")
                          else None):
            candidate = ALIASES.get(candidate, candidate)
            if candidate in LABEL_ID:
                return LABEL_ID[candidate]
    raise InterchangeError(f"{where} {str(name)[:60]!r} is not one of the 12 labels: {', '.join(LABELS)}")


def rect(label: int, x0: Any, y0: Any, x1: Any, y1: Any, size: tuple[int, int], where: str, fields=None) -> Rect:
    """A box from its edges (``fields`` names them in the message), rounded to whole pixels and clipped."""
    names = fields or ("x0", "y0", "x1", "y1")
    x0, y0, x1, y1 = (number(v, f"{where}.{n}" if fields else where) for v, n in zip((x0, y0, x1, y1), names,
                                                                                        strict=True))
    w, h = size
    a, b, c, d = max(0, round(x0)), max(0, round(y0)), min(w, round(x1)), min(h, round(y1))
    if a >= c or b >= d:
        raise InterchangeError(f"{where} is empty once rounded to whole pixels and clipped to the {w}x{h} image: "
                               f"x {x0:g} to {x1:g}, y {y0:g} to {y1:g}")
    return Rect(label, a, b, c, d)


def as_list(value: Any, where: str) -> list:
    if not isinstance(value, list):
        raise InterchangeError(f"{where} must be a list, got {type(value).__name__}")
    return value


def as_object(value: Any, where: str) -> dict:
    if not isinstance(value, dict):
        raise InterchangeError(f"{where} must be an object, got {type(value).__name__}")
    return value


def check_count(rects: list, where: str) -> None:
    if len(rects) > MAX_RECTS:
        raise InterchangeError(f"too many {where}: more than {MAX_RECTS}")


@dataclass(frozen=True)
class Choice:
    image: str | None  # a name or id
    size: tuple[int, int] | None  # else the only image of this size


def whole(value: Any) -> int | None:
    try:
        return int(float(value))
    except (TypeError, ValueError, OverflowError):
        return None


def pick(names: list[str], ids: list[str], sizes: list[tuple], choice: Choice, where: str) -> int:
    """The index of the image to read: named by its name, its name without folders, or its id; else the only
    one, or the only one of the size asked for."""
    if not names:
        raise InterchangeError(f"{where}: the file holds no image")
    image = choice.image
    if image is None:
        fits = [i for i, (w, h) in enumerate(sizes) if choice.size == (whole(w), whole(h))]
        if len(names) == 1 or len(fits) == 1:
            return 0 if len(names) == 1 else fits[0]
        raise SeveralImages(names)
    for keys in (names, [PurePosixPath(n.replace("\\", "/")).name for n in names], ids):
        hits = [i for i, key in enumerate(keys) if key == image]
        if len(hits) == 1:
            return hits[0]
        if hits:
            raise InterchangeError(f"{len(hits)} images are named {image!r}: give the whole name")
    listing = ", ".join(names[:20]) + (f" and {len(names) - 20} more" if len(names) > 20 else "")
    raise InterchangeError(f"no image named {image!r}; the file holds {listing}")
