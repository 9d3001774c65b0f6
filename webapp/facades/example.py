"""The front page's example of what FaçAID does, made from the demo (`manage.py demo`): the demo's photo, the
procedure the worker reconstructed from it, and three variations of that procedure, each with what it drew."""

from __future__ import annotations

import base64
import logging

from django.core.cache import caches

from facaid.editing.parameters import named_parameters
from facaid.editing.variation import vary
from facaid.grammar import to_segmentation
from facaid.grammar.budget import WorkLimitError, work_budget
from facaid.grammar.procedure import ProcedureError
from webapp.facades.access import DEMO_USERNAME
from webapp.facades.drawing import label_map_png
from webapp.facades.errors import Invalid
from webapp.facades.models import Procedure, Visibility
from webapp.facades.parsing import parse_procedure

DEMO_PASSWORD = "demo-facade"
VARIANTS = 3
SIDE = 240  # the variations' pictures, at most this many pixels a side
log = logging.getLogger(__name__)


def demo_procedure() -> Procedure | None:
    """The demo's first public procedure made from its public photo, if the worker has made it."""
    return (Procedure.objects.filter(owner__username=DEMO_USERNAME, visibility=Visibility.PUBLIC,
                                     photo__visibility=Visibility.PUBLIC)
            .select_related("photo").order_by("created").first())


def _caption(tree) -> str:
    found = {p.name: p.value for p in named_parameters(tree)}
    parts = []
    if "floors" in found:
        parts.append(f"{found['floors']:g} upper floor{'s' if found['floors'] != 1 else ''}")
    if "bays" in found:
        parts.append(f"{found['bays']:g} tile{'s' if found['bays'] != 1 else ''} a floor")
    return ", ".join(parts) or f"{tree.width:g} x {tree.height:g} px"


def _variations(tree, caption: str) -> list[tuple]:
    """Variations that show what the numbers do, each with its caption: the floors and the tiles a floor drawn around
    the procedure's own (seed 0; ``caption`` is the procedure's), each one unlike the others and the procedure; any
    variation where it has neither."""
    ranges = {p.name: (max(p.min, p.value - 2), min(p.max, p.value + 3)) for p in named_parameters(tree)
              if p.name in ("floors", "bays") and p.min < p.max}
    if not ranges:
        return [(v, _caption(v)) for v in vary(tree, VARIANTS, seed=0)]
    out, seen = [], {caption}
    for variant in vary(tree, 4 * VARIANTS, seed=0, ranges=ranges):
        said = _caption(variant)
        if said not in seen and len(out) < VARIANTS:
            seen.add(said)
            out.append((variant, said))
    return out


# what the front page's pictures may cost: a fraction of a request's budget (the demo's tree, 12 variations of it and 3
# pictures: 0.03-0.15 s of CPU and 1,200-21,000 instances for generator seeds 0-5), so no tree the demo holds makes it
# slow. 1 s, not 0.5: under the test suite's load on 2 cores, seed 3's pictures (0.115 s alone) once took over 0.5
EXAMPLE_WORK, EXAMPLE_SECONDS = 400_000, 1.0
RETRY_SECONDS = 600  # a tree whose pictures could not be drawn is tried again after this long, not on every visit


def _draw(proc: Procedure) -> dict:
    tree = parse_procedure(proc.data)
    caption = _caption(tree)
    return {"caption": caption, "variations": [
        {"picture": "data:image/png;base64," + base64.b64encode(label_map_png(to_segmentation(t), SIDE)).decode(),
         "caption": said} for t, said in _variations(tree, caption)]}


def _pictures(proc: Procedure) -> dict:
    """The procedure's caption and three variations of it (`_variations`), each a PNG data URI with its caption, kept in
    the cache by the tree's digest: the front page pays for them once per tree. Drawn within a budget of their own
    (`EXAMPLE_WORK`, `EXAMPLE_SECONDS`); a tree that is past it, or cannot be drawn, shows no pictures, and that too
    is kept (for `RETRY_SECONDS`), so that the front page never fails, nor pays again on the next visit."""
    key = f"front-example:{proc.code}:{proc.digest}"
    cache = caches["pages"]
    found = cache.get(key)
    if found is None:
        try:
            with work_budget(EXAMPLE_WORK, EXAMPLE_SECONDS):
                found = _draw(proc)
            cache.set(key, found, None)
        except (ProcedureError, ValueError, Invalid, WorkLimitError) as exc:
            log.warning("the front page's example %s is shown without its pictures: %s", proc.code, exc)
            found = {"caption": "", "variations": []}
            cache.set(key, found, RETRY_SECONDS)
    return found


def front_page_example() -> dict | None:
    """The example the front page shows: the demo's procedure, its photo, its caption and its variations; None
    before the worker has made the procedure."""
    proc = demo_procedure()
    if proc is None:
        return None
    return {"procedure": proc, "photo": proc.photo, **_pictures(proc)}
