"""The ``facaid`` command line: ``facaid <command> --help`` describes each command."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

from facaid.defaults import DEFAULT_K, DEFAULT_MIN_COPY, DEFAULT_MIN_SCORE, STRUCTURES
from facaid.generator import STYLE_NAMES
from facaid.paths import DEFAULT_CHECKPOINT, DEFAULT_CMP


class CliError(Exception):
    pass


def _read_json(path: str) -> Any:
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise CliError(f"cannot read {path}: {exc.strerror}") from None
    except UnicodeDecodeError:
        raise CliError(f"{path} is not a UTF-8 text file") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise CliError(f"{path}: malformed JSON: {exc}") from None


def load_segmentation_or_procedure(obj: Any):
    """A segmentation from a segmentation, a procedure, or a dataset sample record."""
    from facaid.grammar.execute import to_segmentation
    from facaid.grammar.procedure import Procedure
    from facaid.segmentation import Segmentation

    if isinstance(obj, dict) and "procedure" in obj and "format" not in obj:
        obj = obj["procedure"]
    if isinstance(obj, dict) and obj.get("format") is not None:
        return to_segmentation(Procedure.from_dict(obj))
    return Segmentation.from_dict(obj)


def _write_json(path: str | None, payload: dict) -> None:
    if path:
        Path(path).parent.mkdir(parents=True, exist_ok=True)  # a long run's figures are not lost to a missing folder
        Path(path).write_text(json.dumps(payload, indent=2) + "\n")
        print(f"wrote {path}")


def _open_photo(path: str):
    from PIL import Image

    try:
        photo = Image.open(path)
        photo.load()
    except (OSError, Image.DecompressionBombError) as exc:
        raise CliError(f"cannot read photo {path}: {exc}") from None
    return photo


# --- commands -----------------------------------------------------------------------------------------------

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
    _write_json(args.json, {"generated": generated.to_dict(), "cmp": real.to_dict(),
                            "area_distance": distance(generated, real), "irregularity": spread})


def cmd_render(args: argparse.Namespace) -> None:
    from PIL import Image

    from facaid.formats.render import legend, overlay, render_segmentation
    from facaid.segmentation import rasterize

    seg = load_segmentation_or_procedure(_read_json(args.input))
    if args.out.lower().endswith(".svg"):
        if args.photo or args.legend or args.outline:
            raise CliError("--photo, --legend and --outline draw PNGs; an .svg output is the labels alone")
        from facaid.formats.render import segmentation_svg

        Path(args.out).write_text(segmentation_svg(seg), encoding="utf-8")
        print(f"wrote {args.out} ({seg.width}x{seg.height}, {len(seg.rects)} rectangles)")
        return
    if args.photo:
        image = overlay(_open_photo(args.photo), rasterize(seg), args.alpha)
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


def cmd_train(args: argparse.Namespace) -> None:
    from facaid.training import train

    last = train(args.config, out=args.out, resume=args.resume, steps=args.steps, until=args.until,
                 max_hours=args.max_hours, workers=args.workers, progress=not args.quiet)
    print(f"checkpoint: {last}")


def cmd_evaluate(args: argparse.Namespace) -> None:
    import torch

    from facaid.evaluation.synthetic import evaluate_synthetic, write_report
    from facaid.model import load_model

    if args.ceiling and args.best_of < 2:
        raise CliError("--ceiling measures the candidates of best of K: give --best-of K (K >= 2) too")
    if args.threads:
        torch.set_num_threads(args.threads)
    model, tokenizer = load_model(args.checkpoint)
    result = evaluate_synthetic(model, tokenizer, args.count, args.seed, noise_count=args.noise_count,
                                unconstrained_count=args.unconstrained_count, best_of=args.best_of,
                                ceiling=args.ceiling, progress=not args.quiet, records=args.records)
    result["checkpoint"] = str(args.checkpoint)
    report = write_report(result, args.report)
    print(report.read_text().split("## Noise")[0].strip())
    print(f"report: {report}")
    _write_json(args.json, result)


def cmd_compare(args: argparse.Namespace) -> None:
    from facaid.evaluation.compare import compare_records, format_comparison

    result = compare_records(args.a, args.b)
    print(format_comparison(result))
    _write_json(args.json, result)


def cmd_reconstruct(args: argparse.Namespace) -> None:
    from facaid.formats.render import render_segmentation
    from facaid.grammar.execute import to_segmentation
    from facaid.model import load_model
    from facaid.pipeline import reconstruct
    from facaid.segmentation import Segmentation

    seg = Segmentation.from_dict(_read_json(args.input), clip=args.clip)
    model, tokenizer = load_model(args.checkpoint)
    result = reconstruct(seg, model=model, tokenizer=tokenizer, k=args.k, sizing=not args.no_sizing,
                         seed=args.seed, induce=not args.no_induce, structure=args.structure)
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
    _write_json(args.json, result.to_dict())


def cmd_complete(args: argparse.Namespace) -> None:
    from facaid.completion import complete
    from facaid.segmentation import Segmentation

    seg = Segmentation.from_dict(_read_json(args.input), clip=args.clip)
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

        try:  # read once, as grey levels of a bounded size (the site's API reads it the same way)
            photo = levels(args.photo, seg.width, seg.height)
        except (OSError, Image.DecompressionBombError) as exc:
            raise CliError(f"cannot read photo {args.photo}: {exc}") from None
    if args.unit is not None:
        from facaid.photo.copies import UnitError, find_copies

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
    _write_json(args.json, {"proposals": proposals})


def cmd_vary(args: argparse.Namespace) -> None:
    from facaid.formats.render import render_segmentation, side_by_side
    from facaid.grammar.execute import to_segmentation
    from facaid.grammar.procedure import Procedure
    from facaid.variation import vary

    proc = Procedure.from_dict(_read_json(args.input))
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


def _assignment(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    try:
        if not sep:
            raise ValueError
        return name.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE (e.g. floors=6), got {text!r}") from None


def cmd_params(args: argparse.Namespace) -> None:
    from facaid.grammar.procedure import Procedure
    from facaid.parameters import named_parameters, set_parameters

    proc = Procedure.from_dict(_read_json(args.input))
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
    _write_json(args.json, {"parameters": [p.to_dict() for p in params]})


def cmd_cga(args: argparse.Namespace) -> None:
    from facaid.formats.cga import default_scale, procedure_cga
    from facaid.grammar.procedure import Procedure

    proc = Procedure.from_dict(_read_json(args.input))
    scale = args.metres_per_pixel if args.metres_per_pixel is not None else default_scale(proc)
    text = procedure_cga(proc, args.metres_per_pixel, name=Path(args.input).name)
    Path(args.out).write_text(text, encoding="utf-8")
    print(f"wrote {args.out} ({text.count(' -->')} rules, {proc.width * scale:.2f} m x {proc.height * scale:.2f} m "
          f"at {scale:.4g} m per pixel)")


def cmd_mesh(args: argparse.Namespace) -> None:
    from facaid.formats.mesh import procedure_mesh
    from facaid.grammar.procedure import Procedure

    out = Path(args.out)
    if out.suffix.lower() != ".obj":
        raise CliError(f"--out must be a file name that ends in .obj (its materials go beside it), got {args.out}")
    proc = Procedure.from_dict(_read_json(args.input))
    mtl_path = out.with_suffix(".mtl")
    obj, mtl = procedure_mesh(proc, args.metres_per_pixel, mtl_name=mtl_path.name)
    out.write_text(obj, encoding="utf-8")
    mtl_path.write_text(mtl, encoding="utf-8")
    print(f"wrote {out} ({obj.count(chr(10) + 'f ')} faces) and {mtl_path}")


def cmd_export(args: argparse.Namespace) -> None:
    from facaid.formats.cga import STOREY_M, checked_scale
    from facaid.formats.exports import EXPORTS, export_for
    from facaid.grammar.procedure import Procedure

    found = export_for(args.out)
    if found is None:
        raise CliError(f"--out {args.out}: the format comes from the file's extension, one of {' '.join(EXPORTS)}")
    ext, export = found
    if args.metres_per_pixel is not None and not export.scaled:
        raise CliError(f"--metres-per-pixel sets the scale of the exports in metres; a {ext} file is in pixels")
    if args.photo and not export.photo:
        raise CliError(f"--photo is the texture of a .glb or .gltf, or under an .overlay.png; a {ext} file has none")
    if export.needs_photo and not args.photo:
        raise CliError(f"a {ext} file is drawn over the photo: give it with --photo")
    proc = Procedure.from_dict(_read_json(args.input))
    photo = _open_photo(args.photo) if args.photo else None
    if photo is not None and abs(photo.width * proc.height / (photo.height * proc.width) - 1) > 0.02:
        print(f"warning: the photo ({photo.width}x{photo.height}) is stretched over the procedure "
              f"({proc.width:g}x{proc.height:g}): give the rectified photo it was drawn on", file=sys.stderr)
    note = ""
    if export.scaled:
        try:
            scale = checked_scale(proc, args.metres_per_pixel)
        except ValueError as exc:
            raise CliError(f"--metres-per-pixel: {exc}") from None
        source = "given" if args.metres_per_pixel is not None else f"a storey {STOREY_M:g} m tall"
        note = f", {proc.width * scale:.2f} m x {proc.height * scale:.2f} m at {scale:.4g} m per pixel ({source})"
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    paths = export.write(proc, out, args.metres_per_pixel, photo)
    print(f"wrote {' and '.join(str(p) for p in paths)}: {export.what}{note}")


def _corners_arg(text: str) -> list[list[float]]:
    """``--corners``: a JSON list of four [x, y] points, or "x,y x,y x,y x,y"."""
    try:
        value = json.loads(text) if text.lstrip().startswith("[") else [
            [float(v) for v in point.split(",")] for point in text.split()]
    except ValueError:
        raise CliError(f"--corners: give four points as \"x,y x,y x,y x,y\" or a JSON list, got {text!r}") from None
    return value


def cmd_rectify(args: argparse.Namespace) -> None:
    from PIL import Image, ImageOps, UnidentifiedImageError

    from facaid.photo.rectify import output_size, propose_corners, rectify

    if not (args.propose or args.corners):
        raise CliError("give --propose (find the corners) or --corners (use these)")
    if args.corners and args.propose:
        raise CliError("give --propose or --corners, not both")
    try:
        with Image.open(args.photo) as raw:
            photo = ImageOps.exif_transpose(raw)  # corners are where a viewer shows them
            photo.load()
    except FileNotFoundError:
        raise CliError(f"cannot read {args.photo}: no such file") from None
    except (UnidentifiedImageError, OSError, Image.DecompressionBombError) as exc:
        raise CliError(f"{args.photo}: not an image PIL reads ({exc})") from None
    if args.propose:
        found = propose_corners(photo)
        corners = found["corners"]
        print(f"proposed corners (TL, TR, BR, BL) of the {photo.width}x{photo.height} photo: "
              + " ".join(f"{x:g},{y:g}" for x, y in corners) + f"; confidence {found['confidence']:.2f}")
        for note in found["notes"]:
            print(f"note: {note}")
    else:
        corners = _corners_arg(args.corners)
        found = {"corners": corners}
    try:
        out = rectify(photo, corners) if args.out else None
        output_size(corners)
    except ValueError as exc:
        raise CliError(f"--corners: {exc}") from None
    if out is not None:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        try:
            out.save(args.out)
        except (ValueError, OSError) as exc:  # an extension PIL has no writer for
            raise CliError(f"--out {args.out}: {exc}") from None
        print(f"wrote {args.out} ({out.width}x{out.height})")
    _write_json(args.json, {**found, "width": photo.width, "height": photo.height})


def cmd_convert(args: argparse.Namespace) -> None:
    from facaid.formats import interchange

    fmt = args.to or interchange.format_for_name(args.out)
    if fmt is None:
        raise CliError(f"say the format of {args.out} with --to, or end its name in .coco.json, .labelme.json, "
                       f".cvat.xml or .json")
    try:
        data = Path(args.input).read_bytes()
    except OSError as exc:
        raise CliError(f"cannot read {args.input}: {exc.strerror}") from None
    try:
        loaded = interchange.load(data, image=args.image)
        seg, source, name, warnings = loaded.segmentation, loaded.format, loaded.image, loaded.warnings
    except interchange.SeveralImages as exc:
        raise CliError(f"{args.input}: {exc} with --image NAME") from None
    except interchange.InterchangeError:
        obj = _json_object(data)
        if not (isinstance(obj, dict) and ("procedure" in obj or obj.get("format") is not None)):
            raise
        from facaid.formats.annotation import written_as

        seg, source, name, warnings = written_as(load_segmentation_or_procedure(obj), fmt), "procedure", None, ()
    for line in warnings:
        print(f"warning: {line}", file=sys.stderr)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(interchange.write(seg, fmt, image=name or args.image or "facade.png"))
    print(f"wrote {out} ({fmt}, {seg.width}x{seg.height}, {len(seg.rects)} rectangles, read as {source})")


def cmd_validate_cityjson(args: argparse.Namespace) -> None:
    from facaid.formats.cityjson_check import SCHEMAS, check_cityjson

    invalid = 0
    for path in args.files:
        try:
            report = check_cityjson(Path(path).read_bytes())
        except OSError as exc:
            raise CliError(f"cannot read {path}: {exc.strerror}") from None
        if report.valid:
            schema = SCHEMAS[report.version].split(".min")[0]
            print(f"{path}: valid CityJSON {report.version} (schema {schema}, vertices, semantics, "
                  f"parents and children): {report.summary()}")
        else:
            invalid += 1
            print(f"{path}: not valid")
        for line in report.errors:
            print(f"  error: {line}")
        for line in report.warnings:
            print(f"  warning: {line}")
    if invalid:
        raise CliError(f"{invalid} of {len(args.files)} files are not valid CityJSON")


def _json_object(data: bytes) -> Any:
    try:
        return json.loads(data)
    except (ValueError, RecursionError):
        return None


def cmd_evaluate_real(args: argparse.Namespace) -> None:
    from facaid.evaluation.real import evaluate_real, format_summary
    from facaid.model import load_model

    if not Path(args.data).is_file():
        raise CliError(f"annotations not found at {args.data} (pass --data PATH)")
    gallery = args.gallery or None  # --gallery "": none
    if gallery and Path(gallery).suffix.lower() != ".png":  # refused now, not after the whole run
        raise CliError(f"--gallery must name a .png file (or be empty for none), got {gallery!r}")
    model, tokenizer = load_model(args.checkpoint)
    result = evaluate_real(model, tokenizer, args.data, k=args.k, limit=args.limit, gallery=gallery,
                           progress=not args.quiet, induce=not args.no_induce, perturb=args.perturb,
                           structure=args.structure, start=args.start)
    result["checkpoint"] = str(args.checkpoint)
    print(format_summary(result))
    if gallery:
        print(f"gallery (input | reconstruction): {gallery}")
    _write_json(args.json, result)


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


# --- parser ---------------------------------------------------------------------------------------------------

def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="facaid", description="FaçAID: facade segmentations to procedures.")
    sub = parser.add_subparsers(dest="command", required=True)

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

    t = sub.add_parser("train", help="train the transformer on freshly generated facades",
                       description="Train the encoder-decoder transformer per a TOML config ([model], [tokenizer], "
                                   "[train]); checkpoints to OUT/last, resumable.")
    t.add_argument("--config", required=True, help="TOML config, e.g. configs/small.toml")
    t.add_argument("--out", help="run directory (default: the config's train.out)")
    t.add_argument("--resume", action="store_true", help="continue from OUT/last")
    t.add_argument("--steps", type=int, help="override train.steps (the schedule's length)")
    t.add_argument("--until", type=int, help="stop after this step (resume later with --resume)")
    t.add_argument("--max-hours", type=float, help="override train.max_hours: stop and save after this much "
                                                     "wall time (resume later with --resume)")
    t.add_argument("--workers", type=int, help="override train.workers: processes generating samples (0: in the "
                                               "training process; on a GPU machine, about its CPU cores)")
    t.add_argument("--quiet", action="store_true", help="no progress bar")
    t.set_defaults(func=cmd_train)

    e = sub.add_parser("evaluate", help="evaluate a checkpoint on held-out generated facades",
                       description="NLL with and without nullification, validity, exact structure rate, tree edit "
                                   "distance, production frequencies, noise robustness, latency; writes a "
                                   "Markdown report with PNG plots.")
    e.add_argument("--checkpoint", default=str(DEFAULT_CHECKPOINT), help="checkpoint directory (default: shipped)")
    e.add_argument("--count", type=int, default=1000, help="facades (default 1000)")
    e.add_argument("--seed", type=int, default=1000, help="held-out dataset seed (default 1000)")
    e.add_argument("--noise-count", type=int, default=100, help="facades in the noise curve (default 100)")
    e.add_argument("--unconstrained-count", type=int, default=200,
                   help="facades decoded without the grammar mask (default 200)")
    e.add_argument("--best-of", type=int, default=0, metavar="K",
                   help=f"also decode best of K (greedy + K-1 samples ranked by reproduction), as reconstruct does "
                        f"(which decodes {DEFAULT_K})")
    e.add_argument("--ceiling", action="store_true",
                   help="with --best-of: also the figures of the truth's pick among the trees best of K chose from "
                        "(how far a better ranking of the same candidates could go)")
    e.add_argument("--report", default="out/evaluate", help="report directory (default out/evaluate)")
    e.add_argument("--json", help="write the figures to this JSON file")
    e.add_argument("--records", metavar="FILE",
                   help="append each facade's figures to FILE (JSON lines) as they are measured, and resume from "
                        "it: a stopped run started again with the same arguments goes on where it stopped")
    e.add_argument("--threads", type=int, default=0, help="torch threads (default: all cores)")
    e.add_argument("--quiet", action="store_true", help="no progress bar")
    e.set_defaults(func=cmd_evaluate)

    p = sub.add_parser("compare", help="compare two evaluation runs facade by facade",
                       description="Paired comparison of two `evaluate --records` files of the same held-out "
                                   "facades (same --seed): per figure, how many facades B decodes better and "
                                   "worse than A, and the mean change of the tree edit distance (B - A) with a "
                                   "bootstrap 95 % interval.")
    p.add_argument("a", help="records file of run A (the reference)")
    p.add_argument("b", help="records file of run B")
    p.add_argument("--json", help="write the figures to this JSON file")
    p.set_defaults(func=cmd_compare)

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

    exports = (
        ("cga", cmd_cga, "a procedure as CityEngine CGA rules", "output .cga file",
         "Write a procedure as a CGA rule file: apply its start rule Facade to a facade shape in CityEngine. Fixed "
         "sizes keep their metres, floating ones share the rest and repeats lay out as many copies as fit "
         "(docs/pipeline.md)."),
        ("mesh", cmd_mesh, "a procedure as a relief mesh (OBJ and MTL)",
         "output .obj file; the .mtl of the same name is written beside it",
         "Write a procedure as a Wavefront OBJ relief mesh with its MTL beside it: windows, doors and shops set back, "
         "cornices, sills, pillars and balconies standing out, one material per label (docs/pipeline.md)."),
    )
    for name, func, summary, out_help, description in exports:
        e = sub.add_parser(name, help=summary, description=description)
        e.add_argument("input", help="procedure JSON")
        e.add_argument("--out", required=True, help=out_help)
        e.add_argument("--metres-per-pixel", type=float, default=None,
                       help="the scale (default: a storey, from the floors or the rows of windows, is 3 m tall; "
                            "12 m for the whole facade when it has neither)")
        e.set_defaults(func=func)

    from facaid.formats.exports import EXPORTS

    x = sub.add_parser("export", help="a procedure in another format, chosen by the output's extension",
                       description="Write a procedure as " + "; ".join(f"{ext} {e.what}" for ext, e in EXPORTS.items())
                                   + ". The 3D formats and the CGA rules are in metres (docs/pipeline.md).")
    x.add_argument("input", help="procedure JSON")
    x.add_argument("--out", required=True, help="the file to write; its extension says the format")
    x.add_argument("--metres-per-pixel", type=float, default=None,
                   help="the scale of the metric formats (default: a storey, from the floors or the rows of windows, "
                        "is 3 m tall; 12 m for the whole facade when it has neither)")
    x.add_argument("--photo", help="the rectified photo the procedure was drawn on, shown on the fronts of a .glb or "
                                   ".gltf, or under an .overlay.png")
    x.set_defaults(func=cmd_export)

    rc = sub.add_parser("rectify", help="propose a photo's four facade corners, or rectify it from four corners",
                        description="Find the facade's four corners in a photo from its straight lines and vanishing "
                                    "points (--propose), or take them (--corners), and write the fronto-parallel "
                                    "image (--out) and the corners (--json). Corners are top-left, top-right, "
                                    "bottom-right, bottom-left, in the photo's pixels as a viewer shows it (EXIF "
                                    "orientation applied).")
    rc.add_argument("photo", help="the photo (JPEG, PNG, WebP, ...)")
    rc.add_argument("--propose", action="store_true", help="find the corners from the photo's lines")
    rc.add_argument("--corners", help='four points: "x,y x,y x,y x,y" or a JSON list [[x, y], ...]')
    rc.add_argument("--out", help="write the rectified image to this file (its format from the extension)")
    rc.add_argument("--json", help="write the corners (with the proposal's confidence and notes) to this JSON file")
    rc.set_defaults(func=cmd_rectify)

    cv = sub.add_parser("convert", help="convert annotations between COCO, LabelMe, CVAT and our segmentation",
                        description="Read rectangle annotations (COCO object detection JSON, LabelMe JSON, CVAT for "
                                    "images XML, a segmentation, or a procedure's), the format found from the "
                                    "content, and write them in another (docs/interchange.md). Edges are rounded to "
                                    "whole pixels and clipped to the image; polygons become their bounding boxes, "
                                    "with a warning.")
    cv.add_argument("input", help="annotation file")
    cv.add_argument("--out", required=True,
                    help="file to write; its format from --to, else from its name: .coco.json, .labelme.json, "
                         ".cvat.xml, or .json for the segmentation contract")
    cv.add_argument("--to", choices=("coco", "labelme", "cvat", "segmentation"), help="the format to write")
    cv.add_argument("--image", metavar="NAME",
                    help="the image to read from a COCO or CVAT file of several (its file name, with or without "
                         "folders, or its id); also names the image in the output where the input does not")
    cv.set_defaults(func=cmd_convert)

    vc = sub.add_parser("validate-cityjson", help="check CityJSON files as the official validator (cjval) does",
                        description="Check CityJSON 2.0 and 1.0 files: the JSON, the official schema of their "
                                    "version (shipped), vertex indices, semantics arrays, parents and children; "
                                    "warn of duplicate and unused vertices. Exit status 2 when a file is not valid.")
    vc.add_argument("files", nargs="+", metavar="FILE", help="a .city.json file")
    vc.set_defaults(func=cmd_validate_cityjson)

    r2 = sub.add_parser("evaluate-real", help="reconstruct the CMP facades and compare (evaluation only)",
                        description="Reconstruct every facade of an annotations.jsonl (CMP format) and report mean "
                                    "pixel accuracy, per-class IoU and time per facade beside the all-wall "
                                    "baseline, with a gallery PNG (input | reconstruction).")
    r2.add_argument("--data", default=str(DEFAULT_CMP), help="annotations.jsonl (default: the shared CMP file)")
    r2.add_argument("--checkpoint", default=str(DEFAULT_CHECKPOINT), help="checkpoint directory")
    r2.add_argument("--k", type=int, default=DEFAULT_K, help=f"candidates per facade (default {DEFAULT_K})")
    r2.add_argument("--limit", type=int, help="only the first N facades")
    r2.add_argument("--start", type=int, default=0, help="skip the first N facades (--start 189: the test half)")
    r2.add_argument("--structure", choices=STRUCTURES, default="editable",
                    help="which procedure to score (default editable); the other's accuracy is reported beside")
    r2.add_argument("--no-induce", action="store_true", help="only the model's structures (the model alone)")
    r2.add_argument("--perturb", type=int, metavar="SEED",
                    help="annotate each input as people do first (edges moved up to 1 %% of the side, 10 %% of the "
                         "elements left out, 2 spurious boxes), seeded; compare with the clean annotation")
    r2.add_argument("--gallery", default="out/evaluate-real/gallery.png",
                    help='gallery PNG of the first 20 ("" for none)')
    r2.add_argument("--json", help="write the figures to this JSON file")
    r2.add_argument("--quiet", action="store_true", help="no progress bar")
    r2.set_defaults(func=cmd_evaluate_real)

    d = sub.add_parser("demo", help="generate one facade per style with pictures",
                       description="Generate one facade per style preset and write procedures, "
                                   "segmentations and PNGs.")
    d.add_argument("--out", default="out/demo", help="output directory (default out/demo)")
    d.add_argument("--seed", type=int, default=1)
    d.set_defaults(func=cmd_demo)
    return parser


def main(argv: list[str] | None = None) -> int:
    from facaid.grammar.procedure import ProcedureError
    from facaid.segmentation import SegmentationError

    args = build_parser().parse_args(argv)
    try:
        args.func(args)
    except (CliError, ProcedureError, SegmentationError, ValueError, FileNotFoundError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
