"""Completion: from the elements a person has drawn so far, propose the ones they have not drawn yet.

`complete(segmentation)` reads the structure the drawn elements imply and returns the missing elements as
rectangles of the segmentation contract with a ``score`` in (0, 1] and a ``reason``, best first, none repeating
a drawn one:

1. **Types**: drawn elements of one class and about one size (width and height within `SIZE_TOLERANCE`) are
   one type — the tall windows, the small attic windows, the sills.
2. **Floors**: two neighbouring rows of a type, one begun in the other's columns (at most `FLOOR_STRAYS` of its
   elements per aligned one off them): the fuller row's other columns are proposed in the row begun, at its height
   (score 0.9, reason ``floor``). On CMP's dev half (the simulated annotator below) these are right 408 times in 554.
3. **Lattice**: a type's elements fall into rows (their vertical extents overlapping by half) and columns. Where
   a row (column) has at least `MIN_GAPS` gaps that agree (`PITCH_TOLERANCE`; multiples read as skipped bays),
   its pitch continues the columns (rows) `EXTEND` pitch beyond the drawn ones while they fit in the facade (the
   drawn facade rectangles' bounds, else the image) and fills the whole pitches between them. Every
   crossing of a row and a column where nothing of the type is drawn is a proposal, spanning its drawn row's
   and column's median edges: score 0.9 (reason ``grid``) where both the row and the column were drawn in and the
   lattice is regular (`GRID_FILL` of its crossings drawn), else 0.75 (right 10 times in 89 on CMP's dev half);
   0.7 (``row`` or ``column``) where one was, 0.5 where neither.
4. **Companions**: an element drawn on or against every one of at least `COMPANION_MIN` drawn elements of
   another type (a sill under each window) is proposed at the same offset for the rest of them (``with
   window``; at most 0.8: right 7 times in 70 on CMP's dev half).
5. **The photo** (when given: the image the segmentation is drawn on, resized to its size) proposes: every place
   that looks like a type's drawn elements with the wall around them (`facaid.photo.appearance.search`, NCC at least
   `SEARCH_MATCH`, anywhere in the facade, rows and lattices or not) is proposed at the type's size (score
   `PHOTO_CONFIRMED`, reason ``looks like window``). On photo-like renders of 12 held-out generated facades this
   takes the effort from 0.72 (the structure, checked by the photo) to 0.443. And the drawn elements are carried
   along **the photo's repeats** (`facaid.photo.repeats`: the shifts they vote for, where they look like themselves on
   the contrast-normalised photo) to where they stand in a drawn row or column of their class: at NCC
   `REPEAT_MATCH` by how many of the two are drawn (`COMPANION_EXTRA` more for classes other than windows and
   blinds), scored from `COPY_SCORE` up (reason ``repeat of window``, ``photo`` its NCC). On
   CMP's own photos (dev, every 3rd facade) this takes the effort from 0.793 to 0.74-0.76.
6. **The photo checks** every proposal scored at least `PHOTO_CANDIDATE`, the searched ones too: it is moved to
   the best of 25 nearby places and compared with the drawn elements of its class (`facaid.photo.appearance`: normalized
   cross-correlation of 12 x 12 grey patches); at `PHOTO_MATCH` or more it scores at least `PHOTO_CONFIRMED`,
   below that half its score, and ``photo`` holds the similarity. A proposal the structure is sure of (scored
   `PHOTO_CONFIRMED` or more: a floor's, a full grid's) is only vetoed, below `VETO`: on CMP's own photos real copies
   score 0.72-0.86 (dev, every 3rd facade: effort 0.842 → 0.793, hit rate 0.75 kept; on photo-like renders
   0.443 → 0.471). Where the photo is flat (a rendered label map) it has no say.

Proposals outside the drawn facade rectangles' bounds (the image when none is drawn), cut by the image's edge, over
a drawn element of the same class, mostly under a drawn element of a class that paints over them, or near a
``rejected`` box are left out; those scored below ``min_score`` (`facaid.defaults.DEFAULT_MIN_SCORE`) are not
returned by `complete`. `explained` returns them too, from `DIM_SCORE` up (the places the structure gives and the
photo does not confirm, which the editor shows dimmed for a person to take), and where nothing is proposed says in
words what was tried: how long each kind's rows and columns are, and whether either has a pitch. The figures are of
the simulated annotator (`facaid.evaluation.assist`, `bench/bench_assist.py`).

Where each step lives: `kinds` (types, their lines and pitches), `structure` (floors, lattice, companions), `looks`
(the photo's search, repeats and check), `proposals` (the checks every proposal passes), `propose` (one call).
"""

from facaid.completion.kinds import MIN_GAPS, PITCH_TOLERANCE, SIZE_TOLERANCE
from facaid.completion.looks import (
                                     COMPANION_EXTRA,
                                     COPY_SCORE,
                                     PHOTO_CANDIDATE,
                                     PHOTO_CONFIRMED,
                                     PHOTO_MATCH,
                                     REPEAT_MATCH,
                                     SEARCH_MATCH,
                                     VETO,
)
from facaid.completion.proposals import MAX_DRAWN, MAX_PROPOSALS, Proposals, RejectedError, proposals_for
from facaid.completion.propose import DIM_SCORE, Completion, complete, explained
from facaid.completion.structure import COMPANION_MIN, EXTEND, FLOOR_STRAYS, GRID_FILL

__all__ = ["COMPANION_EXTRA", "COMPANION_MIN", "COPY_SCORE", "DIM_SCORE", "EXTEND", "FLOOR_STRAYS", "GRID_FILL",
           "MAX_DRAWN", "MAX_PROPOSALS", "MIN_GAPS", "PHOTO_CANDIDATE", "PHOTO_CONFIRMED", "PHOTO_MATCH",
           "PITCH_TOLERANCE", "REPEAT_MATCH", "SEARCH_MATCH", "SIZE_TOLERANCE", "VETO", "Completion", "Proposals",
           "RejectedError", "complete", "explained", "proposals_for"]
