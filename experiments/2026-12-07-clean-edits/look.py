"""Render a dev facade's lattice reading, sized, before and after an edit, with the verdict.

    .venv/bin/python experiments/2026-12-07-clean-edits/look.py N floors|bays +1|-1 OUT.png [--nosize]
"""
import sys

from PIL import Image, ImageDraw

from facaid.editing.check import judge, label_map
from facaid.evaluation.real import DEV_FACADES, load_records
from facaid.formats.render import colorize
from facaid.editing.parameters import named_parameters, set_parameter
from facaid.paths import DEFAULT_CMP
from facaid.reading.lattice import read_lattice
from facaid.segmentation import flatten, rasterize
from facaid.sizing import fit_sizes

n, name, change, out = int(sys.argv[1]), sys.argv[2], int(sys.argv[3]), sys.argv[4]
assert 1 <= n <= DEV_FACADES
_, seg = load_records(DEFAULT_CMP, 1, n - 1)[0]
flat = flatten(seg)
read = read_lattice(flat)
proc = read if "--nosize" in sys.argv else fit_sizes(read, flat).procedure
value = {p.name: p.value for p in named_parameters(proc)}[name]
edited = set_parameter(proc, name, value + change)
verdict = judge(proc, edited, name, change)
print(verdict)
pics = [colorize(rasterize(flat)), colorize(label_map(proc)), colorize(label_map(edited))]
w = sum(p.width for p in pics) + 12
h = max(p.height for p in pics) + 20
im = Image.new("RGB", (w, h), "white")
x = 0
for p in pics:
    im.paste(p, (x, 20))
    x += p.width + 6
ImageDraw.Draw(im).text((4, 4), f"input | read | {name} {change:+d}: {verdict.reason} (at {verdict.at})", fill="black")
im.save(out)
