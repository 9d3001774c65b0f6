import gzip
import json
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from PIL import Image

from facaid.cli import main
from facaid.formats.render import colorize, legend, overlay, render_segmentation, segmentation_svg
from facaid.generator import generate
from facaid.labels import LABELS, PALETTE
from facaid.segmentation import Segmentation, rasterize


def test_colorize_uses_the_documented_palette():
    label_map = np.arange(12, dtype=np.uint8).reshape(3, 4)
    image = np.asarray(colorize(label_map))
    for i, name in enumerate(LABELS):
        assert tuple(image[i // 4, i % 4]) == PALETTE[name]


def test_render_and_overlay_sizes():
    seg = generate(3).segmentation
    image = render_segmentation(seg, outline=True)
    assert image.size == (seg.width, seg.height)
    photo = Image.new("RGB", (seg.width // 2, seg.height // 2), (255, 255, 255))
    blended = overlay(photo, rasterize(seg), alpha=1.0)
    assert np.array_equal(np.asarray(blended), np.asarray(colorize(rasterize(seg))))
    with pytest.raises(ValueError, match="alpha"):
        overlay(photo, rasterize(seg), alpha=2)
    assert legend().width == 96 * 12


def _paint_svg(text: str) -> np.ndarray:
    """Paint an SVG of `segmentation_svg` rectangle by rectangle in document order, as a browser does."""
    ns = "{http://www.w3.org/2000/svg}"
    root = ET.fromstring(text)
    out = np.full((int(root.get("height")), int(root.get("width"))), -1, dtype=np.int64)
    colour = {_hex: i for i, _hex in enumerate("#{:02x}{:02x}{:02x}".format(*PALETTE[n]) for n in LABELS)}
    parent_fill = None
    for el in root.iter():
        if el.tag == f"{ns}rect":
            fill = el.get("fill") or parent_fill
            x, y = int(el.get("x", 0)), int(el.get("y", 0))
            out[y : y + int(el.get("height")), x : x + int(el.get("width"))] = colour[fill]
        elif el.tag == f"{ns}g":
            parent_fill = el.get("fill")
            assert el.get("id") == LABELS[colour[parent_fill]]  # a group is its class, by name and colour
    return out


OVERLAPPING = Segmentation.from_dict({"width": 40, "height": 30, "rects": [  # drawn in the paint order, not this
    {"label": "window", "x0": 5, "y0": 5, "x1": 20, "y1": 20},
    {"label": "facade", "x0": 0, "y0": 2, "x1": 40, "y1": 30},
    {"label": "door", "x0": 15, "y0": 10, "x1": 25, "y1": 30},
    {"label": "sill", "x0": 4, "y0": 19, "x1": 21, "y1": 22}]})


@pytest.mark.parametrize("seg", [generate(11, "tenement").segmentation, generate(4, "wings").segmentation,
                                 generate(7, "haussmann").segmentation, OVERLAPPING])
def test_svg_draws_what_the_png_paints(seg):
    text = segmentation_svg(seg)
    assert np.array_equal(_paint_svg(text), rasterize(seg))
    groups = [g.get("id") for g in ET.fromstring(text) if g.tag.endswith("g")]
    assert len(groups) == len(set(groups)) and "window" in groups and "facade" in groups  # one group per class
    assert text.count("<rect") == len(seg.rects) + 1  # and the background


def test_cli_renders_svg_and_refuses_png_options_for_it(tmp_path, capsys):
    sample = generate(11, "tenement")
    proc_path = tmp_path / "p.json"
    proc_path.write_text(sample.procedure.to_json())
    assert main(["render", str(proc_path), "--out", str(tmp_path / "p.svg")]) == 0
    assert np.array_equal(_paint_svg((tmp_path / "p.svg").read_text()), rasterize(sample.segmentation))
    assert main(["render", str(proc_path), "--out", str(tmp_path / "q.svg"), "--legend"]) == 2
    assert "an .svg output is the labels alone" in capsys.readouterr().err
    assert not (tmp_path / "q.svg").exists()


def test_cli_render_procedure_segmentation_and_overlay(tmp_path, capsys):
    sample = generate(11, "tenement")
    proc_path = tmp_path / "p.json"
    proc_path.write_text(sample.procedure.to_json())
    seg_path = tmp_path / "s.json"
    seg_path.write_text(sample.segmentation.to_json())
    assert main(["render", str(proc_path), "--out", str(tmp_path / "p.png"), "--legend"]) == 0
    assert main(["render", str(seg_path), "--out", str(tmp_path / "s.png")]) == 0
    a = np.asarray(Image.open(tmp_path / "s.png"))
    assert a.shape == (sample.segmentation.height, sample.segmentation.width, 3)
    # a procedure renders exactly like its flattened execution
    b = np.asarray(Image.open(tmp_path / "p.png"))[: a.shape[0], : a.shape[1]]
    assert np.array_equal(a, b)
    photo = tmp_path / "photo.jpg"
    Image.new("RGB", (50, 60), (10, 200, 30)).save(photo)
    assert main(["render", str(seg_path), "--out", str(tmp_path / "o.png"), "--photo", str(photo),
                 "--alpha", "0.3"]) == 0


@pytest.mark.parametrize(
    "content, message",
    [
        ("{not json", "malformed JSON"),
        ('{"width": 10, "height": 10, "rects": [{"label": "window", "x0": 5, "y0": 0, "x1": 2, "y1": 3}]}',
         "rects[0] needs 0 <= x0 < x1"),
        ('{"format": "facaid-procedure", "version": 1, "grammar": "facaid-split-1", "width": 10, "height": 10,'
         ' "root": {"rule": "leaf", "label": "sky"}}', "node root: leaf label 'sky'"),
        ('{"format": "facaid-procedure", "version": 1, "grammar": "facaid-split-1", "width": 4096, "height": 4096,'
         ' "root": {"rule": "repeat", "axis": "x", "count": 256, "sizes": [["flt", 1]], "children": [{"rule": "repeat",'
         ' "axis": "y", "count": 256, "sizes": [["flt", 1]], "children": ['
         + '{"rule": "split", "axis": "y", "sizes": [["flt", 1]], "children": [' * 29 + '{"rule": "leaf", "label": '
         '"window"}' + "]}" * 29 + "]}]}}", "expands to more than 100000 node instances"),  # issue 56's crafted tree
    ],
)
def test_cli_rejects_bad_input_with_a_message(tmp_path, capsys, content, message):
    path = tmp_path / "bad.json"
    path.write_text(content)
    assert main(["render", str(path), "--out", str(tmp_path / "x.png")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "x.png").exists()


def test_cli_missing_and_binary_files(tmp_path, capsys):
    assert main(["render", str(tmp_path / "nope.json"), "--out", str(tmp_path / "x.png")]) == 2
    assert "cannot read" in capsys.readouterr().err
    binary = tmp_path / "b.json"
    binary.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe")
    assert main(["render", str(binary), "--out", str(tmp_path / "x.png")]) == 2
    assert "not a UTF-8 text file" in capsys.readouterr().err


def test_cli_generate_writes_shards(tmp_path, capsys):
    out = tmp_path / "ds"
    assert main(["generate", "--count", "12", "--seed", "3", "--out", str(out), "--shard-size", "5",
                 "--workers", "1", "--quiet"]) == 0
    assert "wrote 12 facades in 3 shard(s)" in capsys.readouterr().out
    with gzip.open(out / "shard-00002.jsonl.gz", "rt") as f:
        lines = [json.loads(x) for x in f]
    assert len(lines) == 2
    Segmentation.from_dict(lines[0]["segmentation"])
    assert main(["generate", "--count", "3"]) == 2
    assert "--out DIR is required" in capsys.readouterr().err


def test_cli_stats(tmp_path, capsys, cmp_records):
    small = tmp_path / "cmp.jsonl"
    small.write_text("\n".join(json.dumps(r) for r in cmp_records[:5]) + "\n")
    report = tmp_path / "not" / "yet" / "stats.json"  # folders are made rather than the figures lost
    assert main(["generate", "--stats", "--count", "20", "--cmp", str(small), "--json", str(report),
                 "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "20 generated facades" in out and "5 CMP facades" in out
    figures = json.loads(report.read_text())
    assert figures["generated"]["facades"] == 20
    assert set(figures["generated"]["classes"]) == set(LABELS)
    assert "windows off the grid" in out
    assert figures["irregularity"]["generated"]["row_top"] == 0.0
    assert figures["irregularity"]["generated, annotated as on CMP"]["row_top"] > 0.0


def test_demo_and_console_script(tmp_path):
    assert main(["demo", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "gallery.png").is_file()
    assert (tmp_path / "haussmann.procedure.json").is_file()
    assert "@StartRule" in (tmp_path / "haussmann.cga").read_text()
    assert "mtllib haussmann.mtl" in (tmp_path / "haussmann.obj").read_text()
    assert "newmtl window" in (tmp_path / "haussmann.mtl").read_text()
    done = subprocess.run([sys.executable, "-m", "facaid.cli", "--help"], capture_output=True, text=True)
    assert done.returncode == 0 and "generate" in done.stdout


def test_cli_evaluate_real_refuses_a_gallery_it_cannot_write_before_the_run(tmp_path, capsys):
    data = tmp_path / "annotations.jsonl"
    data.write_text(json.dumps({"id": "g1", **generate(1, "house").segmentation.to_dict()}) + "\n")
    assert main(["evaluate-real", "--data", str(data), "--gallery", str(tmp_path / "g.jpg"), "--quiet"]) == 2
    assert "--gallery must name a .png file" in capsys.readouterr().err
    out = tmp_path / "r.json"
    assert main(["evaluate-real", "--data", str(data), "--gallery", "", "--k", "1", "--quiet", "--perturb", "3",
                 "--json", str(out)]) == 0
    result = json.loads(out.read_text())
    assert result["perturb"] == 3 and result["facades"] == 1 and "input_accuracy" in result["per_facade"][0]
