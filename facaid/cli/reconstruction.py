"""`facaid reconstruct` and `complete`: a segmentation to a procedure, and what is not drawn yet."""

from __future__ import annotations

import argparse
from pathlib import Path

from facaid.cli.common import CliError, read_json, write_json
from facaid.defaults import DEFAULT_K, DEFAULT_MIN_COPY, DEFAULT_MIN_SCORE, STRUCTURES
from facaid.paths import DEFAULT_CHECKPOINT


def cmd_reconstruct(args: argparse.Namespace) -> None:
    from facaid.formats.render import render_segmentation
    from facaid.grammar.execute import to_segmentation
    from facaid.model import load_model
    from facaid.pipeline import ReconstructOptions, reconstruct
    from facaid.segmentation import Segmentation

    seg = Segmentation.from_dict(read_json(args.input), clip=args.clip)
    model, tokenizer = load_model(args.checkpoint)
    options = ReconstructOptions(k=args.k, sizing=not args.no_sizing, seed=args.seed, induce=not args.no_induce,
                                 structure=args.structure)
    result = reconstruct(seg, options, model=model, tokenizer=tokenizer)
    Path(args.out).write_text(result.procedure.to_json(indent=1) + "\n")
    print(f"wrote {args.out}: pixel accuracy {100 * result.accuracy:.2f} % "
          f"(decoded {100 * result.accuracy_decoded:.2f} %), {1000 * result.timings['total']:.0f} ms, "
          f"{result.structure} ({result.source} structure)")
    if result.alternative is not None:
        other = "exact" if result.structure == "editable" else "editable"
        print(f"the {other} procedure reproduces {100 * result.alternative_accuracy:.2f} % "
              f"(--structure {other} writes it)")
    if args.png:
        render_segmentation(to_segmentation(result.procedure), outline=True).save(args.png)
        print(f"wrote {args.png}")
    write_json(args.json, result.to_dict())


def add_reconstruct(sub) -> None:
    c = sub.add_parser("reconstruct", help="reconstruct a procedure from a segmentation JSON",
                       description="Flatten, decode with the grammar-constrained transformer (best of K), fit the "
                                   "sizes, and write the procedure JSON (and a PNG of its execution).")
    c.add_argument("input", help="segmentation JSON")
    c.add_argument("--out", required=True, help="procedure JSON to write")
    c.add_argument("--png", help="also render the reconstruction to this PNG")
    c.add_argument("--k", type=int, default=DEFAULT_K, help=f"candidates decoded and reranked (default {DEFAULT_K})")
    c.add_argument("--seed", type=int, default=0, help="sampling seed (default 0)")
    c.add_argument("--no-sizing", action="store_true", help="skip the sizing optimizer")
    c.add_argument("--structure", choices=STRUCTURES, default="editable",
                   help="editable: floors of tiles with exceptions, what the named parameters edit (default); "
                        "exact: the annotation as drawn")
    c.add_argument("--no-induce", action="store_true",
                   help="only the model's structures (no induced structure when they fit badly)")
    c.add_argument("--clip", action="store_true", help="clip rectangles that reach outside the image")
    c.add_argument("--checkpoint", default=str(DEFAULT_CHECKPOINT), help="checkpoint directory (default: shipped)")
    c.add_argument("--json", help="write the figures (accuracy, IoU, timings) to this JSON file")
    c.set_defaults(func=cmd_reconstruct)


def cmd_complete(args: argparse.Namespace) -> None:
    from facaid.completion import complete
    from facaid.segmentation import Segmentation

    seg = Segmentation.from_dict(read_json(args.input), clip=args.clip)
    if args.photo and not Path(args.photo).is_file():
        raise CliError(f"photo not found at {args.photo}")
    if args.unit is not None and not args.photo:
        raise CliError("--unit finds the unit's copies in the photo: give --photo too")
    min_score = args.min_score
    if min_score is None:
        min_score = DEFAULT_MIN_SCORE if args.unit is None else DEFAULT_MIN_COPY
    if not 0 <= min_score <= 1:
        raise CliError(f"--min-score must be in [0, 1], got {min_score}")
    photo = None
    if args.photo:
        from PIL import Image

        from facaid.photo.appearance import levels

        try:  # read once, upright, as grey levels of a bounded size (the site's API reads it the same way)
            photo = levels(args.photo, seg.width, seg.height)
        except (OSError, Image.DecompressionBombError) as exc:
            raise CliError(f"cannot read photo {args.photo}: {exc}") from None
    if args.unit is not None:
        from facaid.completion.copies import UnitError, find_copies

        try:
            unit = [int(i) for i in args.unit.split(",")]
            proposals = find_copies(seg, photo, unit, min_score=min_score)
        except (ValueError, UnitError) as exc:
            raise CliError(f"--unit: {exc}") from None
    else:
        proposals = complete(seg, photo, min_score=min_score)
    counts: dict[str, int] = {}
    for p in proposals:
        counts[p["label"]] = counts.get(p["label"], 0) + 1
    print(f"{len(proposals)} proposal{'s' if len(proposals) != 1 else ''} for {len(seg.rects)} drawn rectangles"
          + (": " + ", ".join(f"{n} {label}" for label, n in sorted(counts.items())) if counts else ""))
    write_json(args.json, {"proposals": proposals})


def add_complete(sub) -> None:
    cp = sub.add_parser("complete", help="propose the elements not drawn yet in a partial segmentation",
                        description="Read the rows, columns and companions of the elements drawn so far and propose "
                                    "the missing ones, each with a score, none repeating a drawn one.")
    cp.add_argument("input", help="segmentation JSON drawn so far")
    cp.add_argument("--photo", help="the rectified photo the segmentation is drawn on: it proposes what looks like "
                                    "the drawn elements and confirms or rejects each proposal")
    cp.add_argument("--unit", help="comma-separated indices of the rectangles of one unit (a window and what is drawn "
                                   "around it): propose its copies in the photo instead")
    cp.add_argument("--min-score", type=float, default=None,
                    help=f"leave out proposals scored lower (default {DEFAULT_MIN_SCORE}; {DEFAULT_MIN_COPY} with "
                         "--unit)")
    cp.add_argument("--clip", action="store_true", help="clip rectangles reaching outside the image")
    cp.add_argument("--json", help="write the proposals to this JSON file ({\"proposals\": [...]})")
    cp.set_defaults(func=cmd_complete)
