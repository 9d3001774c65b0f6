"""Style presets: the distributions of the style parameters S, and sampling one facade's S from them.

Lengths are in metres; the builder scales them to pixels. Probabilities are per facade unless the name
says per floor. A preset is a plain dict of ranges so that it reads like a description of the style.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

# (low, high) ranges are sampled uniformly; ints inclusive.
PRESETS: dict[str, dict] = {
    "haussmann": dict(
        floors=(4, 6), bays=(4, 9), floor_h=(2.9, 3.4), ground_h=(4.0, 5.2), bay_w=(2.6, 3.4),
        window_w=(0.42, 0.55), window_h=(0.58, 0.72), pillar=0.0, pillar_w=(0.0, 0.0),
        sill=0.9, hood=0.5, hood_noble=1.0, deco=0.8, shutters=0.1, roller=0.35, railing=0.4, surround=0.45,
        balcony_floors="haussmann", bands=0.7, attic=0.95, dormers=0.8, ground="shops_entrance",
        symmetric=0.8, margin=(0.0, 0.6), sky=(0.0, 0.12), side_bg=0.25,
    ),
    "tenement": dict(
        floors=(3, 5), bays=(4, 8), floor_h=(3.0, 3.6), ground_h=(3.4, 4.4), bay_w=(2.4, 3.2),
        window_w=(0.40, 0.52), window_h=(0.48, 0.60), pillar=0.85, pillar_w=(0.25, 0.5),
        sill=0.95, hood=0.9, hood_noble=1.0, deco=0.6, shutters=0.25, roller=0.25, railing=0.1, surround=0.5,
        balcony_floors="rare", bands=0.8, attic=0.6, dormers=0.5, ground="mixed",
        symmetric=0.5, margin=(0.0, 0.8), sky=(0.0, 0.15), side_bg=0.3,
    ),
    "modernist": dict(
        floors=(5, 11), bays=(6, 14), floor_h=(2.8, 3.3), ground_h=(3.5, 5.0), bay_w=(1.6, 2.6),
        window_w=(0.65, 0.92), window_h=(0.50, 0.68), pillar=0.35, pillar_w=(0.15, 0.35),
        sill=0.25, hood=0.0, hood_noble=0.0, deco=0.05, shutters=0.0, roller=0.3, railing=0.15, surround=0.15,
        balcony_floors="modern", bands=0.35, attic=0.2, dormers=0.0, ground="glass",
        symmetric=0.3, margin=(0.0, 1.0), sky=(0.0, 0.1), side_bg=0.2,
    ),
    "house": dict(
        floors=(1, 2), bays=(2, 4), floor_h=(2.7, 3.2), ground_h=(2.8, 3.4), bay_w=(2.6, 3.8),
        window_w=(0.35, 0.5), window_h=(0.45, 0.6), pillar=0.0, pillar_w=(0.0, 0.0),
        sill=0.85, hood=0.35, hood_noble=0.35, deco=0.3, shutters=0.45, roller=0.2, railing=0.1, surround=0.25,
        balcony_floors="rare", bands=0.3, attic=0.8, dormers=0.5, ground="house",
        symmetric=0.5, margin=(0.2, 1.2), sky=(0.08, 0.3), side_bg=0.7,
    ),
    "commercial": dict(
        floors=(2, 5), bays=(3, 8), floor_h=(2.9, 3.5), ground_h=(4.0, 5.5), bay_w=(2.4, 3.4),
        window_w=(0.45, 0.7), window_h=(0.5, 0.65), pillar=0.3, pillar_w=(0.2, 0.4),
        sill=0.7, hood=0.3, hood_noble=0.4, deco=0.4, shutters=0.1, roller=0.3, railing=0.3, surround=0.3,
        balcony_floors="per_tile", bands=0.6, attic=0.4, dormers=0.3, ground="commercial",
        symmetric=0.4, margin=(0.0, 0.8), sky=(0.0, 0.12), side_bg=0.25,
    ),
    "wings": dict(
        floors=(2, 6), bays=(2, 5), floor_h=(2.8, 3.6), ground_h=(3.2, 4.8), bay_w=(2.2, 3.4),
        window_w=(0.4, 0.7), window_h=(0.45, 0.68), pillar=0.35, pillar_w=(0.2, 0.45),
        sill=0.7, hood=0.45, hood_noble=0.5, deco=0.4, shutters=0.2, roller=0.3, railing=0.25, surround=0.3,
        balcony_floors="rare", bands=0.5, attic=0.5, dormers=0.4, ground="mixed",
        symmetric=0.2, margin=(0.0, 0.6), sky=(0.0, 0.12), side_bg=0.2, wings=(2, 3),
    ),
}
STYLE_NAMES: tuple[str, ...] = tuple(PRESETS)


@dataclass
class Style:
    """S: the style parameters of one facade (or one wing), sampled from a preset."""

    name: str
    floors: int  # upper floors, attic excluded
    bays: int  # tiles per floor
    floor_h: float
    ground_h: float
    bay_w: float
    window_w: float  # fraction of the bay width
    window_h: float  # fraction of the floor height
    pillar_w: float  # 0: no pillars
    margin_w: float  # wall at each side of the bays
    sill: bool
    hood: bool  # hoods above the windows of ordinary floors
    hood_noble: bool  # hoods above the windows of the first upper floor
    deco: bool
    shutters: bool  # blinds beside the windows
    surround: bool  # molding frames around the windows
    roller: float  # per-floor chance of roller blinds
    railing: float  # per-floor chance of balconettes in front of windows
    balcony_floors: str
    bands: bool  # molding bands between floors
    attic: bool
    dormers: bool
    ground: str
    symmetric: bool
    sky: float  # fraction of the image height above the building
    side_bg: bool  # background beside the building
    wings: int = 1


def sample_style(rng: random.Random, name: str) -> Style:
    """Draw one facade's style parameters from the named preset."""
    if name not in PRESETS:
        raise ValueError(f"unknown style {name!r}; expected one of {', '.join(STYLE_NAMES)}")
    p = PRESETS[name]

    def u(key: str) -> float:
        lo, hi = p[key]
        return rng.uniform(lo, hi)

    def chance(key: str) -> bool:
        return rng.random() < p[key]

    pillar = chance("pillar")
    return Style(
        name=name,
        floors=rng.randint(*p["floors"]),
        bays=rng.randint(*p["bays"]),
        floor_h=u("floor_h"),
        ground_h=u("ground_h"),
        bay_w=u("bay_w"),
        window_w=u("window_w"),
        window_h=u("window_h"),
        pillar_w=u("pillar_w") if pillar else 0.0,
        margin_w=u("margin"),
        sill=chance("sill"),
        hood=chance("hood"),
        hood_noble=chance("hood_noble"),
        deco=chance("deco"),
        shutters=chance("shutters"),
        surround=chance("surround"),
        roller=p["roller"],
        railing=p["railing"],
        balcony_floors=p["balcony_floors"],
        bands=chance("bands"),
        attic=chance("attic"),
        dormers=chance("dormers"),
        ground=p["ground"],
        symmetric=chance("symmetric"),
        sky=u("sky"),
        side_bg=chance("side_bg"),
        wings=rng.randint(*p["wings"]) if "wings" in p else 1,
    )
