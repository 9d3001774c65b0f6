"""Pictures of edits of the editable reading (`facaid.pipeline.best_reading`) of CMP facades: the drawing, the
procedure, `floors` + 1 and `bays` + 1, one PNG a facade, all at one scale (the edited facade is taller or wider),
each edit captioned with the self-check's verdict (`facaid.editing.check`). Label maps only, never a photo.

    .venv/bin/python experiments/2026-12-07-clean-edits/edit_pictures.py 0190,0210,0230,0250,0270 OUT_DIR 189

(the facades' numbers, the folder, and the first record read: 189 for the test half)."""
import sys
from pathlib import Path
from PIL import Image, ImageDraw
from facaid.evaluation.real import load_records
from facaid.segmentation import flatten, rasterize
from facaid.pipeline import best_reading
from facaid.editing.parameters import named_parameters, set_parameter
from facaid.editing.check import check_edits, MORE
from facaid.grammar.execute import to_segmentation
from facaid.formats.render import colorize
ids = sys.argv[1].split(","); outdir = Path(sys.argv[2]); start = int(sys.argv[3]); outdir.mkdir(parents=True, exist_ok=True)
for rid, seg in load_records("../shared/data/cmp/annotations.jsonl", 189, start):
    if rid[-4:] not in ids: continue
    flat = flatten(seg); b = best_reading(flat)
    p = {q.name: q.value for q in named_parameters(b.procedure)}
    v = check_edits(b.procedure, MORE)
    pics = [("drawn", colorize(rasterize(flat))), ("procedure", colorize(rasterize(to_segmentation(b.procedure))))]
    for name in ("floors", "bays"):
        e = set_parameter(b.procedure, name, p[name] + 1)
        pics.append((f"{name} {p[name]:.0f} -> {p[name] + 1:.0f}: {'clean' if v[name + '+1'].clean else 'NOT clean'}",
                     colorize(rasterize(to_segmentation(e)))))
    s = 360 / max(im.height for _, im in pics)
    ims = [(t, im.resize((max(1, round(im.width * s)), max(1, round(im.height * s))), Image.NEAREST)) for t, im in pics]
    W = sum(im.width for _, im in ims) + 10 * len(ims); H = max(im.height for _, im in ims) + 40
    sheet = Image.new("RGB", (W, H), (255, 255, 255)); d = ImageDraw.Draw(sheet); x = 0
    for t, im in ims:
        sheet.paste(im, (x, 40 + (H - 40 - im.height))); d.text((x + 2, 4), t, fill=(0, 0, 0)); x += im.width + 10
    d.text((2, 20), f"{rid}  floor_height {p.get('floor_height', 0):.0f} px", fill=(0, 0, 0))
    sheet.save(outdir / f"{rid}.png"); print(rid, {k: x.clean for k, x in v.items()})
