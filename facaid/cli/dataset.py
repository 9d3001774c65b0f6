"""`facaid generate`, `render` and `demo`: generated facades, and pictures of segmentations and procedures."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from facaid.cli.common import CliError, load_segmentation_or_procedure, open_photo, read_json, write_json
from facaid.generator import STYLE_NAMES
from facaid.paths import DEFAULT_CMP


def cmd_generate(args: argparse.Namespace) -> None:
    if args.stats:
        return _generate_stats(args)
    if not args.out:
        raise CliError("--out DIR is required (or use --stats)")
    from facaid.generator.dataset import write_dataset

    t0 = time.perf_counter()
    paths = write_dataset(args.out, args.count, args.seed, style=args.style, shard_size=args.shard_size,
                          workers=args.workers, progress=not args.quiet)
    dt = time.perf_counter() - t0
    print(f"wrote {args.count} facades in {len(paths)} shard(s) to {args.out} "
          f"in {dt:.1f} s ({args.count / dt:.0f} facades/s)")


def _generate_stats(args: argparse.Namespace) -> None:
    from tqdm import tqdm

    from facaid.augmentation import cmp_annotation
    from facaid.generator import generate
    from facaid.generator.dataset import sample_seed
    from facaid.generator.stats import class_stats, distance, format_table, irregularity, load_cmp

    cmp_path = Path(args.cmp)
    if not cmp_path.is_file():
        raise CliError(f"CMP annotations not found at {cmp_path} (pass --cmp PATH)")
    segs = [generate(sample_seed(args.seed, i), args.style).segmentation
            for i in tqdm(range(args.count), desc="generate", disable=args.quiet)]
    generated = class_stats(segs)
    cmp_segs = load_cmp(cmp_path)
    real = class_stats(cmp_segs)
    print(f"{args.count} generated facades (seed {args.seed}) vs {real.facades} CMP facades")
    print(format_table(generated, real))
    annotated = [cmp_annotation(seg, i) for i, seg in enumerate(segs)]
    spread = {"generated": irregularity(segs), "generated, annotated as on CMP": irregularity(annotated),
              "CMP": irregularity(cmp_segs)}
    print("windows off the grid (median over rows and columns of >= 3 windows; spreads as a share of the side):")
    for name, figures in spread.items():
        print(f"  {name:<31} row tops {figures['row_top']:.4f}  column lefts {figures['column_left']:.4f}  "
              f"heights cv {figures['row_height_cv']:.3f}  widths cv {figures['column_width_cv']:.3f}")
    write_json(args.json, {"generated": generated.to_dict(), "cmp": real.to_dict(),
                            "area_distance": distance(generated, real), "irregularity": spread})


def add_generate(sub) -> None:
    g = sub.add_parser("generate", help="generate facades with their procedures (sharded dataset)",
                       description="Generate facades with their derivation trees into sharded .jsonl.gz files, "
                                   "or with --stats compare generated statistics with the CMP annotations.")
    g.add_argument("--count", type=int, default=1000, help="number of facades (default 1000)")
    g.add_argument("--seed", type=int, default=0, help="dataset seed (default 0)")
    g.add_argument("--out", help="output directory")
    g.add_argument("--style", choices=STYLE_NAMES, help="one style preset (default: all, picked per facade)")
    g.add_argument("--shard-size", type=int, default=1000, help="facades per shard file (default 1000)")
    g.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    g.add_argument("--stats", action="store_true", help="report per-class statistics against CMP instead")
    g.add_argument("--cmp", default=str(DEFAULT_CMP), help="CMP annotations.jsonl for --stats")
    g.add_argument("--json", help="write the --stats figures to this JSON file")
    g.add_argument("--quiet", action="store_true", help="no progress bar")
    g.set_defaults(func=cmd_generate)


def cmd_render(args: argparse.Namespace) -> None:
    from PIL import Image

    from facaid.formats.render import legend, overlay, render_segmentation
    from facaid.segmentation import rasterize

    seg = load_segmentation_or_procedure(read_json(args.input))
    if args.out.lower().endswith(".svg"):
        if args.photo or args.legend or args.outline:
            raise CliError("--photo, --legend and --outline draw PNGs; an .svg output is the labels alone")
        from facaid.formats.render import segmentation_svg

        Path(args.out).write_text(segmentation_svg(seg), encoding="utf-8")
        print(f"wrote {args.out} ({seg.width}x{seg.height}, {len(seg.rects)} rectangles)")
        return
    if args.photo:
        image = overlay(open_photo(args.photo), rasterize(seg), args.alpha)
    else:
        image = render_segmentation(seg, outline=args.outline)
    if args.legend:
        strip = legend()
        canvas = Image.new("RGB", (max(image.width, strip.width), image.height + strip.height), (255, 255, 255))
        canvas.paste(image, (0, 0))
        canvas.paste(strip, (0, image.height))
        image = canvas
    image.save(args.out)
    print(f"wrote {args.out} ({image.width}x{image.height})")


def add_render(sub) -> None:
    r = sub.add_parser("render", help="render a segmentation or procedure JSON to PNG or SVG",
                       description="Render a segmentation, a procedure or a dataset sample to a PNG in the "
                                   "documented palette, or as an overlay on a photo; to an SVG of one group of "
                                   "rectangles per class when the output ends in .svg.")
    r.add_argument("input", help="segmentation or procedure JSON file")
    r.add_argument("--out", required=True, help="output PNG, or SVG when it ends in .svg")
    r.add_argument("--photo", help="draw the labels over this photo")
    r.add_argument("--alpha", type=float, default=0.5, help="overlay opacity (default 0.5)")
    r.add_argument("--outline", action="store_true", help="outline element rectangles")
    r.add_argument("--legend", action="store_true", help="add a legend strip")
    r.set_defaults(func=cmd_render)


def cmd_demo(args: argparse.Namespace) -> None:
    from facaid.formats.cga import procedure_cga
    from facaid.formats.mesh import procedure_mesh
    from facaid.formats.render import render_segmentation, side_by_side
    from facaid.generator import generate

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    images = []
    for k, style in enumerate(STYLE_NAMES):
        sample = generate(args.seed + k, style)
        (out / f"{style}.procedure.json").write_text(sample.procedure.to_json(indent=1) + "\n")
        (out / f"{style}.segmentation.json").write_text(json.dumps(sample.segmentation.to_dict()) + "\n")
        (out / f"{style}.cga").write_text(procedure_cga(sample.procedure, name=style))
        obj, mtl = procedure_mesh(sample.procedure, mtl_name=f"{style}.mtl")
        (out / f"{style}.obj").write_text(obj)
        (out / f"{style}.mtl").write_text(mtl)
        image = render_segmentation(sample.segmentation, outline=True)
        image.save(out / f"{style}.png")
        images.append(image)
        print(f"{style:<11} {sample.procedure.width}x{sample.procedure.height} px, "
              f"{sum(1 for _ in sample.procedure.nodes())} nodes, {len(sample.segmentation.rects)} rectangles")
    side_by_side(images, height=320).save(out / "gallery.png")
    print(f"wrote procedures, segmentations, pictures, CGA rules and meshes to {out}/ (gallery.png shows them all)")


def add_demo(sub) -> None:
    d = sub.add_parser("demo", help="generate one facade per style with pictures",
                       description="Generate one facade per style preset and write procedures, "
                                   "segmentations and PNGs.")
    d.add_argument("--out", default="out/demo", help="output directory (default out/demo)")
    d.add_argument("--seed", type=int, default=1)
    d.set_defaults(func=cmd_demo)
