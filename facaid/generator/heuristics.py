"""The heuristics that grow a facade's derivation tree from its style S.

H_p (which production) is every ``choose_*`` method: it picks the rule for a role (repeat or mirror a row, group
identical floors, where the entrance goes, ...). H_a (which arguments) is every ``sample_*`` method and the size
arithmetic around it. Both read S and the context so that facades stay coherent: every floor shares one column layout
(windows line up), floors of one type are identical, sizes follow architectural ranges. All lengths are sampled in
metres and emitted in pixels through `Builder.abs` and `Builder.flt`.
"""

from __future__ import annotations

import random
from dataclasses import replace

from facaid.generator.ground import GroundFloor
from facaid.generator.plan import WALL, FloorType, Layout
from facaid.generator.styles import Style
from facaid.grammar.floors import structure
from facaid.grammar.nodes import Node, Size


class Builder(GroundFloor):
    """Grows one derivation tree in metres; `facaid.generator.image.build_procedure` scales it to pixels."""

    def __init__(self, rng: random.Random):
        self.rng = rng
        self.balcony_h = 1.0

    # --- sizes and small helpers ---------------------------------------------------------------------
    @staticmethod
    def abs(metres: float) -> Size:
        return Size("abs", max(metres, 0.0))

    @staticmethod
    def flt(metres: float) -> Size:
        return Size("flt", max(metres, 0.01))

    def chance(self, p: float) -> bool:
        return self.rng.random() < p

    def centered(self, width: float, child: Node, role: str | None = None) -> Node:
        """``child`` of the given width centred in wall."""
        return Node.split("x", [(self.flt(1), Node.leaf(WALL)), (self.abs(width), child),
                                (self.flt(1), Node.leaf(WALL))], role=role)

    # --- H_a: the column layout and the floor types --------------------------------------------------
    def sample_layout(self, s: Style) -> Layout:
        bays = s.bays
        symmetric = s.symmetric and bays >= 3
        return Layout(bays, s.bay_w, s.pillar_w, s.margin_w, symmetric)

    def sample_floor_types(self, s: Style, layout: Layout) -> list[FloorType]:
        """One floor type per upper floor, top to bottom."""
        rng = self.rng
        base_w = min(layout.bay_w * s.window_w, layout.bay_w - 0.3)
        roller = self.chance(s.roller)
        railing = self.chance(s.railing)

        def make(height_factor: float, **kw) -> FloorType:
            window_h = s.floor_h * s.window_h * height_factor
            top_gap = max(0.15, (s.floor_h - window_h) * rng.uniform(0.25, 0.45))
            ft = FloorType(window_w=base_w, window_h=window_h, top_gap=top_gap, hood=s.hood, sill=s.sill,
                           deco=s.deco and s.hood and self.chance(0.5), balcony="none", railing=railing,
                           roller=roller, shutters=s.shutters, surround=s.surround, band_below=s.bands)
            return replace(ft, **kw)

        n = s.floors
        plain = make(1.0)
        types = [plain] * n  # bottom upper floor is index n - 1
        if s.balcony_floors == "haussmann":
            noble = make(1.12, hood=s.hood_noble, deco=s.deco, balcony="band", railing=False)
            top = make(0.92, balcony="band", railing=False, band_below=False)
            types[n - 1] = noble
            if n >= 4:
                types[0] = top
            if n >= 5 and self.chance(0.5):
                types[1] = make(0.96)
        elif s.balcony_floors == "modern" and self.chance(0.25):
            types = [make(1.0, balcony=self.rng.choice(["band", "tile"]), sill=False)] * n
        elif s.balcony_floors == "per_tile":
            with_balcony = make(1.0, balcony="tile", railing=False)
            types = [with_balcony if self.chance(0.3) else plain for _ in range(n)]
        elif s.balcony_floors == "rare" and n >= 2 and self.chance(0.3):
            types[n - 1] = make(1.05, hood=s.hood_noble, deco=s.deco, balcony=self.rng.choice(["band", "tile"]))
        elif s.hood_noble and not s.hood:
            types[n - 1] = make(1.05, hood=True, deco=s.deco)
        return types

    # --- tiles ---------------------------------------------------------------------------------------------
    def window_unit(self, ft: FloorType, height: float) -> tuple[Node, float]:
        """The window with its blinds or balconette (role window); returns (node, width)."""
        rng = self.rng
        node = Node.leaf("window")
        # blinds and railings are fractions (rel) of the window's slot, so that a window squeezed into a low
        # floor or above a balcony keeps its glass
        if ft.roller:
            blind = rng.uniform(0.15, 0.45)
            node = Node.split("y", [(Size("rel", blind), Node.leaf("blind")), (self.flt(height * (1 - blind)), node)])
        if ft.railing:
            rail = min(0.9 / height, 0.35)
            node = Node.split("y", [(self.flt(height * (1 - rail)), node), (Size("rel", rail), Node.leaf("balcony"))])
        width = ft.window_w
        if ft.surround:
            frame = rng.uniform(0.1, 0.22)
            node = Node.split("y", [(self.abs(frame), Node.leaf("molding")),
                                    (self.flt(height), Node.mirror("x", [(self.abs(frame), Node.leaf("molding")),
                                                                         (self.flt(width), node)], center=True))])
            width += 2 * frame
        if ft.shutters:
            shutter = ft.window_w * rng.uniform(0.4, 0.5)
            node = Node.split("x", [(self.abs(shutter), Node.leaf("blind")), (self.flt(ft.window_w), node),
                                    (self.abs(shutter), Node.leaf("blind"))])
            width += 2 * shutter
        node.role = "window"
        return node, width

    def tile(self, ft: FloorType, bay_w: float, floor_h: float) -> Node:
        """One window unit in its bay (role tile): hood, ornament, sill and balcony around the window."""
        rng = self.rng
        unit, unit_w = self.window_unit(ft, ft.window_h)
        unit_w = min(unit_w, bay_w * 0.96)
        overhang = min(rng.uniform(0.1, 0.3), (bay_w * 0.98 - unit_w) / 2) if (ft.hood or ft.sill) else 0.0
        col_w = unit_w + 2 * max(overhang, 0.0)
        window_h = ft.window_h
        items: list[tuple[Size, Node]] = []
        used = 0.0
        if ft.deco:
            h = rng.uniform(0.25, 0.5)
            items.append((self.abs(h), self.centered_in(col_w, unit_w * rng.uniform(0.5, 1.0), "deco")))
            used += h
        if ft.hood:
            h = rng.uniform(0.25, 0.55)
            items.append((self.abs(h), Node.leaf("cornice")))
            used += h
        if ft.balcony == "tile":
            bal = min(1.0, window_h * 0.4)
            items.append((self.abs(window_h - bal), self.pad(unit, unit_w, col_w)))
            items.append((self.abs(bal), Node.leaf("balcony")))
        else:
            items.append((self.abs(window_h), self.pad(unit, unit_w, col_w)))
            if ft.sill and ft.balcony != "band":
                h = rng.uniform(0.15, 0.3)
                items.append((self.abs(h), Node.leaf("sill")))
                used += h
        fixed = sum(size.value for size, _ in items)
        room = floor_h - 0.1
        if fixed > room:  # a tall window unit in a low floor: shrink it so every size takes effect
            f = room / fixed
            items = [(self.abs(size.value * f), node) for size, node in items]
            used, window_h = used * f, window_h * f
        top = ft.top_gap
        bottom = floor_h - top - used - window_h
        if ft.balcony == "band":
            top = max(0.1, floor_h - used - window_h)
            bottom = 0.0
        column_items = [(self.flt(top), Node.leaf(WALL))] + items
        if bottom > 0.05:
            column_items.append((self.flt(bottom), Node.leaf(WALL)))
        column = Node.split("y", column_items)
        return self.centered(col_w, column, role="tile")

    def pad(self, node: Node, width: float, outer: float) -> Node:
        """``node`` centred in wall inside a slightly wider column (a mirror split)."""
        side = (outer - width) / 2
        if side < 0.02:
            return node
        return Node.mirror("x", [(self.abs(side), Node.leaf(WALL)), (self.flt(width), node)], center=True)

    def centered_in(self, outer: float, width: float, label: str) -> Node:
        return self.pad(Node.leaf(label), width, outer)

    # --- rows and floors ---------------------------------------------------------------------------------
    def choose_row(self, layout: Layout, tile: Node, center: Node | None) -> Node:
        """H_p for a row of bays: a repeat, or a mirror around a distinct centre bay; pillars between bays."""
        pillar = layout.pillar_w > 0
        if center is not None and layout.bays % 2 == 1 and layout.bays >= 3:
            half = layout.bays // 2
            if pillar:
                side = Node.repeat("x", half, [(self.abs(layout.pillar_w), Node.leaf("pillar")),
                                                (self.flt(layout.bay_w), tile)])
                side_w = half * (layout.bay_w + layout.pillar_w)
                return Node.mirror("x", [(self.flt(side_w), side),
                                         (self.abs(layout.pillar_w), Node.leaf("pillar")),
                                         (self.flt(layout.bay_w), center)], center=True, role="bay")
            side = Node.repeat("x", half, [(self.flt(layout.bay_w), tile)])
            return Node.mirror("x", [(self.flt(half * layout.bay_w), side), (self.flt(layout.bay_w), center)],
                               center=True, role="bay")
        if pillar:
            return Node.repeat("x", layout.bays, [(self.abs(layout.pillar_w), Node.leaf("pillar")),
                                                  (self.flt(layout.bay_w), tile)], tail=1, role="bay")
        return Node.repeat("x", layout.bays, [(self.flt(layout.bay_w), tile)], role="bay")

    def with_margins(self, layout: Layout, row: Node, margin_label: str = WALL) -> Node:
        if layout.margin_w < 0.05:
            return row
        return Node.split("x", [(self.abs(layout.margin_w), Node.leaf(margin_label)),
                                (self.flt(layout.width - 2 * layout.margin_w), row),
                                (self.abs(layout.margin_w), Node.leaf(margin_label))])

    def floor(self, s: Style, layout: Layout, ft: FloorType) -> Node:
        tile = self.tile(ft, layout.bay_w, s.floor_h if ft.balcony != "band" else s.floor_h - self.balcony_h)
        center = None
        if layout.symmetric and self.chance(0.35):
            wider = replace(ft, window_w=min(ft.window_w * 1.25, layout.bay_w - 0.3), deco=ft.deco or ft.hood)
            if wider.deco != ft.deco or wider.window_w >= 1.1 * ft.window_w:  # else it would pass for a tile
                center = self.tile(wider, layout.bay_w, s.floor_h)
        row = self.with_margins(layout, self.choose_row(layout, tile, center))
        if ft.balcony == "band":
            return Node.split("y", [(self.flt(s.floor_h - self.balcony_h), row),
                                    (self.abs(self.balcony_h), self.balcony_band(layout))], role="floor")
        row.role = "floor"
        return row

    def balcony_band(self, layout: Layout) -> Node:
        inset = layout.margin_w * self.rng.uniform(0.3, 1.0) if layout.margin_w > 0.1 else 0.0
        if inset < 0.05:
            return Node.leaf("balcony", role="band")
        return Node.mirror("x", [(self.abs(inset), Node.leaf(WALL)), (self.flt(layout.width), Node.leaf("balcony"))],
                           center=True, role="band")

    def choose_floors(self, s: Style, layout: Layout, types: list[FloorType]) -> tuple[Node, float]:
        """H_p for the stack of upper floors: runs of identical floors become repeats. Returns (node, height)."""
        self.balcony_h = self.rng.uniform(0.8, 1.1)
        band_h = self.rng.uniform(0.15, 0.35)
        runs: list[tuple[FloorType, int, Node]] = []  # (type, floors, the floor node)
        for ft in types:
            if runs and runs[-1][0] is ft:
                runs[-1] = (ft, runs[-1][1] + 1, runs[-1][2])
                continue
            floor = self.floor(s, layout, ft)
            if runs and self.looks_alike(runs[-1], ft, floor):  # two runs a segmentation cannot tell apart
                runs[-1] = (runs[-1][0], runs[-1][1] + 1, runs[-1][2])
            else:
                runs.append((ft, 1, floor))
        items: list[tuple[Size, Node]] = []
        height = 0.0
        for ft, n, floor in runs:
            pattern = [(self.flt(s.floor_h), floor)]
            unit_h = s.floor_h
            if ft.band_below:
                pattern.append((self.abs(band_h), Node.leaf("molding", role="band")))
                unit_h += band_h
            if n > 1 or len(pattern) > 1:
                items.append((self.flt(n * unit_h), Node.repeat("y", n, pattern, role="floors")))
            else:
                items.append(pattern[0])
            height += n * unit_h
        if len(items) == 1:
            return items[0][1], height
        return Node.split("y", items, role="floors"), height

    @staticmethod
    def looks_alike(run: tuple[FloorType, int, Node], ft: FloorType, floor: Node) -> bool:
        """Whether a floor of type ``ft`` would pass for one more floor of ``run``: the same tree, the same band
        below, windows within 5 % of the same height."""
        other, _, other_floor = run
        return (other.band_below == ft.band_below and abs(other.window_h - ft.window_h) <= 0.05 * other.window_h
                and structure(other_floor) == structure(floor))

    # --- attic -----------------------------------------------------------------------------------------------
    def attic(self, s: Style, layout: Layout) -> tuple[Node, float]:
        """Roof storey with dormers above the main cornice (role attic). Returns (node, height)."""
        rng = self.rng
        roof_h = s.floor_h * rng.uniform(0.6, 1.0)
        cornice_h = rng.uniform(0.3, 0.6)
        if s.dormers:
            dw, dh = layout.bay_w * rng.uniform(0.3, 0.45), roof_h * rng.uniform(0.45, 0.65)
            dormer = Node.split("y", [(self.flt(roof_h - dh), Node.leaf(WALL)), (self.abs(dh), Node.leaf("window")),
                                      (self.flt(roof_h * 0.15), Node.leaf(WALL))])
            every = rng.choice([1, 1, 2]) if layout.bays >= 4 else 1
            row = Node.repeat("x", max(1, layout.bays // every),
                              [(self.flt(layout.bay_w * every), self.centered(dw, dormer, role="tile"))])
            roof = self.with_margins(layout, row)
        else:
            roof = Node.leaf(WALL)
        node = Node.split("y", [(self.flt(roof_h), roof), (self.abs(cornice_h), Node.leaf("molding", role="band"))],
                          role="attic")
        return node, roof_h + cornice_h

    # --- whole facades -----------------------------------------------------------------------------------------
    def facade(self, s: Style) -> tuple[Node, float, float]:
        """One building: attic, upper floors, ground floor. Returns (node, width, height) in metres."""
        layout = self.sample_layout(s)
        types = self.sample_floor_types(s, layout)
        items: list[tuple[Size, Node]] = []
        height = 0.0
        if s.attic:
            attic, h = self.attic(s, layout)
            items.append((self.flt(h), attic))
            height += h
        if s.floors > 0:
            floors, h = self.choose_floors(s, layout, types)
            items.append((self.flt(h), floors))
            height += h
        if s.bands and self.chance(0.6):
            h = self.rng.uniform(0.2, 0.45)
            items.append((self.abs(h), Node.leaf("molding", role="band")))
            height += h
        items.append((self.flt(s.ground_h), self.choose_ground(s, layout)))
        height += s.ground_h
        return Node.split("y", items, role="facade"), layout.width, height
