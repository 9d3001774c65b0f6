"""The 12 classes of the CMP facade database, their palette and their paint order.

Label ids are the CMP ids minus one, so that background is 0 and a label map is a uint8 array whose
values index `LABELS`.
"""

from __future__ import annotations

LABELS: tuple[str, ...] = (
    "background",
    "facade",
    "window",
    "door",
    "cornice",
    "sill",
    "balcony",
    "blind",
    "deco",
    "molding",
    "pillar",
    "shop",
)
LABEL_ID: dict[str, int] = {name: i for i, name in enumerate(LABELS)}
BACKGROUND = LABEL_ID["background"]
FACADE = LABEL_ID["facade"]

# Flattening paints by class priority, bottom to top. This order reproduces all 378 CMP label maps.
PAINT_ORDER: tuple[str, ...] = (
    "background",
    "facade",
    "molding",
    "cornice",
    "pillar",
    "window",
    "door",
    "sill",
    "blind",
    "balcony",
    "shop",
    "deco",
)
PRIORITY: tuple[int, ...] = tuple(PAINT_ORDER.index(name) for name in LABELS)  # indexed by label id
GLASS: tuple[int, ...] = (LABEL_ID["window"], LABEL_ID["blind"])  # a window with its blinds, one element to the eye

# RGB colours used by every renderer of the project (Tango-like, chosen to stay distinct).
PALETTE: dict[str, tuple[int, int, int]] = {
    "background": (30, 30, 40),
    "facade": (214, 200, 178),
    "window": (52, 101, 164),
    "door": (143, 89, 2),
    "cornice": (245, 121, 0),
    "sill": (252, 233, 79),
    "balcony": (204, 0, 0),
    "blind": (78, 154, 6),
    "deco": (173, 127, 168),
    "molding": (193, 125, 17),
    "pillar": (136, 138, 133),
    "shop": (32, 180, 180),
}
PALETTE_ARRAY: tuple[tuple[int, int, int], ...] = tuple(PALETTE[name] for name in LABELS)


def hex_colour(label: str) -> str:
    """A label's palette colour as ``#rrggbb`` (SVG fills, CGA colours)."""
    return "#{:02x}{:02x}{:02x}".format(*PALETTE[label])


def label_id(name: str) -> int:
    """Return the id of a label name; raise ValueError naming the valid labels otherwise."""
    try:
        return LABEL_ID[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown label {name!r}; expected one of {', '.join(LABELS)}") from None
