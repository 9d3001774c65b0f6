"""What the heuristics plan before they grow a tree: the column layout every floor shares (`Layout`) and what one
type of upper floor looks like (`FloorType`), in metres."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["WALL", "FloorType", "Layout"]

WALL = "facade"


@dataclass(frozen=True)
class FloorType:
    """What the tiles of one upper floor look like (H_a, shared by every floor of this type)."""

    window_w: float  # metres
    window_h: float
    top_gap: float  # wall above the window unit
    hood: bool
    sill: bool
    deco: bool  # ornament above the hood
    balcony: str  # "none", "band" (across the floor) or "tile" (one per window)
    railing: bool  # balconette in front of the lower window
    roller: bool  # roller blind in the top of the window
    shutters: bool
    surround: bool  # a molding frame around the window
    band_below: bool  # a molding band under the floor


@dataclass(frozen=True)
class Layout:
    """The column layout every floor of a facade shares."""

    bays: int
    bay_w: float
    pillar_w: float
    margin_w: float
    symmetric: bool

    @property
    def width(self) -> float:
        pillars = (self.bays + 1) * self.pillar_w if self.pillar_w > 0 else 0.0
        return 2 * self.margin_w + self.bays * self.bay_w + pillars
