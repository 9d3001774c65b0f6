"""The ground floor's heuristics (H_p and H_a): shops, an entrance and windows in the column layout every floor
shares. A mixin of `facaid.generator.heuristics.Builder`, whose sampling helpers (``abs``, ``flt``, ``chance``,
``tile``, ``choose_row``, ``with_margins``) it uses."""

from __future__ import annotations

from facaid.generator.plan import WALL, FloorType, Layout
from facaid.generator.styles import Style
from facaid.grammar.nodes import Node, Size

__all__ = ["GroundFloor"]


class GroundFloor:
    """The ground floor's methods of `facaid.generator.heuristics.Builder`."""

    def entrance(self, bay_w: float, height: float, hood: bool) -> Node:
        rng = self.rng
        door_w = min(bay_w * 0.85, rng.uniform(1.1, 1.9))
        door_h = min(height - 0.3, rng.uniform(2.3, 3.2))
        items: list[tuple[Size, Node]] = [(self.flt(height - door_h), Node.leaf(WALL))]
        if hood and height - door_h > 0.5:
            items.append((self.abs(0.25), Node.leaf("cornice")))
        items.append((self.abs(door_h), Node.leaf("door")))
        return self.centered(door_w, Node.split("y", items), role="entrance")

    def shopfront(self, height: float) -> Node:
        rng = self.rng
        top = height * rng.uniform(0.1, 0.35)
        side = rng.uniform(0.05, 0.4)
        items = [(self.abs(top), Node.leaf(WALL))]
        if self.chance(0.3):  # a sign or ornament over the shop window
            sign = min(0.6, height * 0.15)
            items.append((self.abs(sign), Node.leaf("deco")))
            top += sign
        items.append((self.flt(height - top), Node.leaf("shop")))
        shop = Node.split("y", items)
        return Node.mirror("x", [(self.abs(side), Node.leaf(WALL)), (self.flt(2.0), shop)], center=True,
                           role="shopfront")

    def ground_window(self, s: Style, layout: Layout) -> Node:
        ft = FloorType(window_w=min(layout.bay_w * s.window_w, layout.bay_w - 0.3),
                       window_h=s.ground_h * self.rng.uniform(0.4, 0.55), top_gap=s.ground_h * 0.2,
                       hood=s.hood, sill=s.sill, deco=False, balcony="none", railing=False,
                       roller=self.chance(0.3), shutters=s.shutters, surround=s.surround, band_below=False)
        return self.tile(ft, layout.bay_w, s.ground_h)

    def choose_ground(self, s: Style, layout: Layout) -> Node:
        """H_p for the ground floor: shops, an entrance, windows, in the shared column layout."""
        h = s.ground_h
        kind = s.ground
        if kind == "mixed":
            kind = self.rng.choice(["shops_entrance", "house", "glass"])
        entrance = self.entrance(layout.bay_w, h, s.hood)
        if kind == "shops_entrance":
            bay = self.shopfront(h)
        elif kind == "glass":
            bay = self.shopfront(h) if self.chance(0.5) else Node.leaf("shop")
        elif kind == "commercial":
            shop = self.shopfront(h)
            inner = layout.width - 2 * layout.margin_w
            door_side = self.rng.random() < 0.5
            items = [(self.flt(inner - layout.bay_w), shop), (self.abs(layout.bay_w), entrance)]
            if door_side:
                items.reverse()
            return self.with_margins(layout, Node.split("x", items, role="ground"))
        else:  # house
            bay = self.ground_window(s, layout)
        if kind != "house" and self.chance(0.3):  # shops only, the entrance is elsewhere
            row = self.choose_row(layout, bay, None)
        elif layout.symmetric and layout.bays % 2 == 1:
            row = self.choose_row(layout, bay, entrance)
        else:
            door = self.rng.randrange(layout.bays)
            if layout.bays % 2 == 1 and layout.bays >= 3 and door == layout.bays // 2:  # symmetric after all
                return self.ground_row(layout, self.choose_row(layout, bay, entrance))
            bays = [bay.copy() for _ in range(layout.bays)]
            bays[door] = entrance
            pillar = layout.pillar_w > 0
            items: list[tuple[Size, Node]] = []
            for b in bays:
                if pillar:
                    items.append((self.abs(layout.pillar_w), Node.leaf("pillar")))
                items.append((self.flt(layout.bay_w), b))
            if pillar:
                items.append((self.abs(layout.pillar_w), Node.leaf("pillar")))
            row = Node.split("x", items, role="bay")
        return self.ground_row(layout, row)

    def ground_row(self, layout: Layout, row: Node) -> Node:
        node = self.with_margins(layout, row)
        node.role = "ground"
        return node
