import json

import pytest
import torch

import facaid
from facaid.cli import main
from facaid.generator import generate
from facaid.grammar import Procedure, validate
from facaid.model import FacaidConfig, FacaidModel, save_model
from facaid.pipeline import reconstruct
from facaid.tokenizer import Tokenizer, TokenizerConfig

CONFIG = TokenizerConfig(max_rects=1000, max_out=200)


@pytest.fixture(scope="module")
def tiny():
    torch.manual_seed(0)
    model = FacaidModel(FacaidConfig(d_model=16, encoder_layers=1, decoder_layers=1, heads=2, ffn=32,
                                     tokenizer=CONFIG.to_dict())).eval()
    return model, Tokenizer(CONFIG)


def test_reconstruct_returns_a_valid_sized_procedure(tiny):
    model, tok = tiny
    seg = generate(6).segmentation
    result = reconstruct(seg.to_dict(), model=model, tokenizer=tok, k=2)
    validate(result.procedure)
    assert result.accuracy >= result.accuracy_decoded
    assert set(result.timings) == {"flatten", "decode", "sizing", "total"}
    assert facaid.reconstruct is reconstruct


def test_cli_reconstruct(tiny, tmp_path, capsys):
    model, tok = tiny
    save_model(model, tok, tmp_path / "ckpt")
    seg_path = tmp_path / "seg.json"
    seg_path.write_text(generate(6).segmentation.to_json())
    out = tmp_path / "proc.json"
    assert main(["reconstruct", str(seg_path), "--out", str(out), "--png", str(tmp_path / "r.png"),
                 "--checkpoint", str(tmp_path / "ckpt"), "--k", "1", "--json", str(tmp_path / "m.json")]) == 0
    Procedure.from_json(out.read_text())
    assert (tmp_path / "r.png").is_file()
    assert 0 <= json.loads((tmp_path / "m.json").read_text())["accuracy"] <= 1
    seg_path.write_text('{"width": 5, "height": 5, "rects": [{"label": "window", "x0": 1, "y0": 1, "x1": 9, '
                        '"y1": 2}]}')
    assert main(["reconstruct", str(seg_path), "--out", str(out), "--checkpoint", str(tmp_path / "ckpt")]) == 2
    assert "0 <= x0 < x1 <= width=5" in capsys.readouterr().err
