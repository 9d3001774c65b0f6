"""`facaid vary` and `params`: a procedure's variations and its named parameters."""

from __future__ import annotations

import argparse
from pathlib import Path

from facaid.cli.common import CliError, read_json, write_json


def cmd_vary(args: argparse.Namespace) -> None:
    from facaid.editing.variation import vary
    from facaid.formats.render import render_segmentation, side_by_side
    from facaid.grammar.execute import to_segmentation
    from facaid.grammar.procedure import Procedure

    proc = Procedure.from_dict(read_json(args.input))
    variants = vary(proc, args.n, args.seed, dict(args.range) if args.range else None)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for i, v in enumerate(variants):
        (out / f"variant-{i:02d}.json").write_text(v.to_json(indent=1) + "\n")
        print(f"variant-{i:02d}.json  {v.meta['variation']:<7} {v.width:g}x{v.height:g}")
    images = [render_segmentation(to_segmentation(p)) for p in [proc, *variants]]
    side_by_side(images, height=256).save(out / "variants.png")
    print(f"wrote {len(variants)} variants and variants.png (the original first) to {out}/")


def _range(text: str) -> tuple[str, tuple[float, float]]:
    name, sep, span = text.partition("=")
    lo, dash, hi = span.partition("-")
    try:
        if not (sep and dash):
            raise ValueError
        return name.strip(), (float(lo), float(hi))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected NAME=LOW-HIGH (e.g. floors=4-7), got {text!r}") from None


def add_vary(sub) -> None:
    v = sub.add_parser("vary", help="variations of a procedure",
                       description="Write N variants of a procedure: floor and tile counts changed, the facade "
                                   "resized with its repeats adapting, tiles or floors swapped within the style.")
    v.add_argument("input", help="procedure JSON")
    v.add_argument("--n", type=int, default=8, help="number of variants (default 8)")
    v.add_argument("--seed", type=int, default=0)
    v.add_argument("--out", default="out/variants", help="output directory (default out/variants)")
    v.add_argument("--range", type=_range, action="append", metavar="NAME=LOW-HIGH",
                   help="draw this named parameter from a range in every variant, e.g. floors=4-7 (repeatable; "
                        "see facaid params)")
    v.set_defaults(func=cmd_vary)


def cmd_params(args: argparse.Namespace) -> None:
    from facaid.editing.parameters import named_parameters, set_parameters
    from facaid.grammar.procedure import Procedure

    proc = Procedure.from_dict(read_json(args.input))
    if args.set:
        if not args.out:
            raise CliError("--set needs --out FILE for the edited procedure")
        proc = set_parameters(proc, dict(args.set))
        Path(args.out).write_text(proc.to_json(indent=1) + "\n")
    params = named_parameters(proc)
    for p in params:
        value = f"{p.value:g}" if p.integer else f"{p.value:.1f} px"
        fixed = "  (fixed: no repeat lays them out)" if p.min == p.max else ""
        print(f"{p.name:<14} {value:>10}  {p.label}{fixed}")
    if args.set:
        print(f"wrote {args.out} ({proc.width:g}x{proc.height:g})")
    write_json(args.json, {"parameters": [p.to_dict() for p in params]})


def _assignment(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    try:
        if not sep:
            raise ValueError
        return name.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE (e.g. floors=6), got {text!r}") from None


def add_params(sub) -> None:
    pa = sub.add_parser("params", help="a procedure's named parameters (floors, floor height, ...), read or set",
                        description="List the named parameters of a procedure (upper floors, floor height, ground "
                                    "floor and attic heights, tiles per floor, tile width, facade width and height), "
                                    "or set some (--set floors=6 --out FILE): the other parts keep their size.")
    pa.add_argument("input", help="procedure JSON")
    pa.add_argument("--set", type=_assignment, action="append", metavar="NAME=VALUE",
                    help="set a named parameter (repeatable)")
    pa.add_argument("--out", help="where to write the edited procedure (with --set)")
    pa.add_argument("--json", help="write the parameters as JSON to this file")
    pa.set_defaults(func=cmd_params)
