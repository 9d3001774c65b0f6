import json

import pytest

import facaid
from facaid.cli import main
from facaid.editing.check import Verdict, check_edits
from facaid.generator import generate
from facaid.grammar import Procedure, validate
from facaid.metrics import procedure_accuracy
from facaid.model import save_model
from facaid.pipeline import ReconstructOptions, reading_key, reconstruct
from facaid.segmentation import flatten
from facaid.tokenizer import Tokenizer, TokenizerConfig


def test_reconstruct_returns_a_valid_sized_procedure(tiny):
    model, tok = tiny
    seg = generate(6).segmentation
    result = reconstruct(seg.to_dict(), ReconstructOptions(k=2), model=model, tokenizer=tok)
    validate(result.procedure)
    assert result.accuracy >= result.accuracy_decoded
    assert set(result.timings) == {"flatten", "decode", "sizing", "lattice", "total"}
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


def test_a_real_facade_comes_back_editable_with_the_exact_one_beside(tiny):
    """Induction wins on a real-like annotation: the lattice reading is the editable procedure, sized, with floors
    and bays to edit; the exact one rides along, and ``structure="exact"`` swaps them."""
    from grammar_helpers import real_like

    from facaid.editing.parameters import named_parameters

    model, tok = tiny
    seg = real_like()
    editable = reconstruct(seg, ReconstructOptions(k=1, retry_k=0), model=model, tokenizer=tok)
    assert (editable.structure, editable.source) == ("editable", "lattice")
    assert {"floors", "bays"} <= {p.name for p in named_parameters(editable.procedure)}
    assert editable.accuracy == procedure_accuracy(editable.procedure, flatten(seg)) > 0.94
    assert editable.alternative is not None and editable.alternative_accuracy > 0.97
    assert editable.to_dict()["alternative_accuracy"] == editable.alternative_accuracy
    assert editable.procedure.meta["group"] == [1, 1]  # the grid as read: its edits are clean
    checks = check_edits(editable.procedure)
    assert checks["floors+1"].clean and checks["bays+1"].clean, checks
    exact = reconstruct(seg, ReconstructOptions(k=1, retry_k=0, structure="exact"), model=model, tokenizer=tok)
    assert exact.structure == "exact" and exact.accuracy == editable.alternative_accuracy
    assert exact.alternative.to_json() == editable.procedure.to_json()
    with pytest.raises(ValueError, match="structure must be one of editable, exact"):
        reconstruct(seg, ReconstructOptions(k=1, structure="tidy"), model=model, tokenizer=tok)


def test_fit_to_model_drops_the_smallest_elements():
    from facaid.pipeline import fit_to_model
    from facaid.segmentation import flatten

    seg = generate(6).segmentation
    small = Tokenizer(TokenizerConfig(max_rects=20))
    fitted = fit_to_model(seg, small)
    assert len(flatten(fitted, wall="footprint").rects) <= 20
    assert fit_to_model(seg, Tokenizer(TokenizerConfig(max_rects=1000))) is seg


def test_evaluate_real_on_cmp_records(tiny, tmp_path, cmp_records, capsys):
    model, tok = tiny
    data = tmp_path / "cmp.jsonl"
    data.write_text("\n".join(json.dumps(r) for r in cmp_records[:2]) + "\n")
    save_model(model, tok, tmp_path / "ckpt")
    out = tmp_path / "real.json"
    assert main(["evaluate-real", "--data", str(data), "--checkpoint", str(tmp_path / "ckpt"), "--k", "1",
                 "--gallery", str(tmp_path / "g" / "gallery.png"), "--json", str(out), "--quiet"]) == 0
    figures = json.loads(out.read_text())
    assert figures["facades"] == 2
    assert 0 < figures["baseline_all_wall"]["mean"] < 1
    assert figures["pixel_accuracy"]["mean"] >= 0
    assert (tmp_path / "g" / "gallery.png").is_file()
    assert "all-wall baseline" in capsys.readouterr().out


def test_second_chance_sizes_more_candidates_when_the_first_fits_badly(tiny):
    model, tok = tiny  # untrained: its structures fit badly, so the second chance runs
    seg = generate(6).segmentation
    first = reconstruct(seg, ReconstructOptions(k=2, retry_k=0, induce=False), model=model, tokenizer=tok)
    assert not first.retried and first.accuracy < 0.97
    again = reconstruct(seg, ReconstructOptions(k=2, retry_k=2, induce=False), model=model, tokenizer=tok)
    assert again.retried and again.to_dict()["retried"]
    assert again.accuracy >= first.accuracy
    validate(again.procedure)
    assert again.accuracy == procedure_accuracy(again.procedure, flatten(seg))
    never = reconstruct(seg, ReconstructOptions(k=2, retry_below=0.0, induce=False), model=model, tokenizer=tok)
    assert not never.retried and never.accuracy == first.accuracy


def test_progress_hears_each_stage_in_order(tiny):
    model, tok = tiny  # untrained: its structures fit badly, so the second chance samples
    seg = generate(6).segmentation
    heard = []
    reconstruct(seg, ReconstructOptions(k=2, retry_k=2, induce=False), model=model, tokenizer=tok,
                progress=lambda f, stage: heard.append((f, stage)))
    assert [s for _, s in heard] == ["decoding up to 2 candidates", "sizing", "sampling 2 more candidates"]
    assert [f for f, _ in heard] == sorted(f for f, _ in heard) and heard[0][0] >= 0 and heard[-1][0] < 1
    heard.clear()
    reconstruct(seg, ReconstructOptions(k=1, retry_k=0, induce=False), model=model, tokenizer=tok,
                progress=lambda f, stage: heard.append((f, stage)))
    assert [s for _, s in heard] == ["decoding 1 candidate", "sizing"]


def test_bad_real_input_gets_a_procedure_or_a_clear_error():
    """Issue 42's bad inputs: an empty annotation, one without a facade rectangle, boxes all over each other, and
    20,000 rectangles: a procedure that reproduces the input, or an error that names the limit."""
    import random

    from facaid.grammar import validate
    from facaid.segmentation import Rect, Segmentation

    cases = [Segmentation(400, 300, ()),
             Segmentation(400, 300, tuple(Rect(2, 20 + 60 * i, 40, 60 + 60 * i, 100) for i in range(5))),
             Segmentation(400, 300, tuple(Rect(2 + i % 9, 0, 0, 400, 300) for i in range(30)))]
    for seg in cases:
        result = reconstruct(seg, ReconstructOptions(k=2))
        validate(result.procedure)
        assert result.accuracy > 0.99
    rng = random.Random(1)
    many = []
    for i in range(20_000):
        x, y = rng.randrange(0, 1990), rng.randrange(0, 1990)
        many.append(Rect(2 + i % 10, x, y, x + rng.randrange(1, 10), y + rng.randrange(1, 10)))
    with pytest.raises(ValueError, match=r"too many rectangles for the model: \d+ after flattening \(at most 640\)"):
        reconstruct(Segmentation(2000, 2000, tuple(many)), ReconstructOptions(k=2))


def test_a_reading_is_ranked_by_its_clean_edits_and_floor_pitch_then_its_accuracy():
    clean, broken = Verdict(True, "one floor like the others"), Verdict(False, "the new bay is like no bay")
    grid = reading_key([clean, broken], 0.95)  # the grid as read: its new floor is clean
    pairs = reading_key([broken, broken], 0.99)  # floors two by two: a little more accurate, no edit clean
    both = reading_key([clean, clean], 0.90)
    assert both > grid > pairs
    assert reading_key([clean, broken], 0.96) > grid
    # issue 67: a floor height that is the floors' pitch counts like a clean edit: the grid as read, one edit clean
    # and its floor one storey, against floors read two by two, both edits clean and their floor two storeys: the
    # more accurate wins
    assert reading_key([clean, broken], 0.97, True) > reading_key([clean, clean], 0.96, False)
    assert reading_key([clean, broken], 0.95, True) < reading_key([clean, clean], 0.96, False)
    assert reading_key([clean, broken], 0.95, True) > grid
    assert reading_key([clean, clean], 0.9, None) == both


def test_reconstruct_options_are_one_frozen_object_checked_when_made():
    """Issue 69: how `reconstruct` reads is one options object, not eleven keywords; a bad one is refused when it is
    made, naming the problem, and a prefix given as a list is kept as a tuple (the options are hashable)."""
    options = ReconstructOptions(k=2, prefix=[3, 4])
    assert options.prefix == (3, 4) and not options.free and hash(options)
    assert ReconstructOptions().free and ReconstructOptions().structure == "editable"
    with pytest.raises(ValueError, match="structure must be one of editable, exact, got 'tidy'"):
        ReconstructOptions(structure="tidy")
    with pytest.raises(AttributeError):
        options.k = 3
