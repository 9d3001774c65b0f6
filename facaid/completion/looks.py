"""What the photo says, where completion is given one: places that look like a type's drawn elements anywhere in the
facade (`search`), the drawn elements carried along the photo's repeats (`carried`), and each proposal the
structure is sure enough of moved to where it looks most like its class, confirmed or not (`checked`)."""

from __future__ import annotations

import numpy as np

from facaid.completion.kinds import Kind
from facaid.completion.proposals import Proposals
from facaid.labels import GLASS, LABELS
from facaid.photo import appearance, repeats

MAX_SEARCH_TYPES = 64  # the photo is searched for at most this many types, those drawn most often (CMP: 58 at most)
PHOTO_CANDIDATE = 0.7  # proposals scored at least this by the structure are shown to the photo
PHOTO_MATCH = 0.9  # NCC against the drawn examples of the class at which the photo confirms a proposal
PHOTO_CONFIRMED = 0.9  # ... and the score it has at least then
VETO = 0.75  # ... and below this NCC the photo vetoes a proposal the structure is sure of
SEARCH_MATCH = 0.93  # NCC at which a place anywhere in the photo that looks like a type's elements is proposed
REPEAT_MATCH = (2.0, 0.8, 0.6)  # NCC a repeat needs standing in neither, one or both of a drawn row and column
COMPANION_EXTRA = 0.1  # ... and this much more for a class other than a window or blind (a sill, a cornice)
ALIGNED = 0.15  # ... in which its edges agree with a drawn element's within this share of its size
COPY_SCORE = 0.85  # the score of a repeat as alike as it needs to be (`REPEAT_MATCH`) ...
COPY_SLOPE = 0.3  # ... and what each unit of NCC above that adds


def search(levels: appearance.Levels, types: list[Kind], props: Proposals) -> None:
    """Where the photo looks like a type's drawn elements (`facaid.photo.appearance.search`, NCC at least
    `SEARCH_MATCH`), anywhere in the facade: each such place is proposed at the type's size (``looks like``). The
    `MAX_SEARCH_TYPES` types drawn most often are searched for (in their order), so that a call costs at most that
    many searches however many types are drawn."""
    most = sorted(range(len(types)), key=lambda i: -len(types[i].boxes))[:MAX_SEARCH_TYPES]
    for t in (types[i] for i in sorted(most)):
        boxes, _ = appearance.search(levels, t.boxes, (t.width, t.height), SEARCH_MATCH)
        for box in boxes:
            props.add(t.label, box, PHOTO_CONFIRMED, f"looks like {LABELS[t.label]}")


def carried(levels: appearance.Levels, props: Proposals) -> None:
    """The drawn elements carried by the photo's repeats (`facaid.photo.repeats`) where it looks like them: proposed
    where they also stand in a drawn row or column of their class (`REPEAT_MATCH`: the alike a copy must be, by how
    many of its row and column are drawn; one in neither is not proposed)."""
    for label, box, sim in repeats.repeats(levels, props.drawn):
        same = props.against(label)[0]
        w, h = box[2] - box[0], box[3] - box[1]
        row = bool(((np.abs(same[:, 1] - box[1]) <= ALIGNED * h) & (np.abs(same[:, 3] - box[3]) <= ALIGNED * h)).any())
        col = bool(((np.abs(same[:, 0] - box[0]) <= ALIGNED * w) & (np.abs(same[:, 2] - box[2]) <= ALIGNED * w)).any())
        need = REPEAT_MATCH[row + col] + (0.0 if label in GLASS else COMPANION_EXTRA)
        if sim >= need:
            props.add(label, box, round(min(1.0, COPY_SCORE + COPY_SLOPE * (sim - need)), 3),
                      f"repeat of {LABELS[label]}", sim)


def checked(levels: appearance.Levels, props: Proposals) -> dict[int, tuple[float, float, np.ndarray]]:
    """{item: (score, similarity, box)} for the proposals the photo has a say on: each is moved to where it looks
    most like the drawn elements of its class (`appearance.refine`); one that looks like them scores at least
    `PHOTO_CONFIRMED`, one that does not half its structural score and stays where the structure put it; a flat
    place or class keeps its score."""
    out: dict[int, tuple[float, float]] = {}
    items = [i for i, item in enumerate(props.items) if item[2] >= PHOTO_CANDIDATE and not item[3].startswith("repeat")]
    for label in sorted({props.items[i][0] for i in items}):
        mine = [i for i in items if props.items[i][0] == label]
        examples = props.drawn[props.drawn[:, 0] == label, 1:]
        boxes, sims = appearance.refine(levels, props.boxes[mine], examples)
        for i, box, sim in zip(mine, boxes, sims.tolist(), strict=True):
            if np.isnan(sim):
                continue
            score = props.items[i][2]
            bar = VETO if score >= PHOTO_CONFIRMED else PHOTO_MATCH  # a sure structure: the photo only vetoes
            if sim < bar:  # not confirmed: where the structure puts it (the best of nearby places is any of them)
                score, box = 0.5 * score, props.boxes[i]
            else:
                score = max(score, PHOTO_CONFIRMED)
            out[i] = (round(float(score), 3), round(float(sim), 3), box)
    return out


__all__ = ["PHOTO_CONFIRMED", "PHOTO_MATCH", "SEARCH_MATCH", "VETO", "carried", "checked", "search"]
