import json

import pytest

from facaid.augmentation import changed_fraction, perturb
from facaid.cli import main
from facaid.decoding import decode
from facaid.evaluation.records import RecordsError
from facaid.evaluation.synthetic import by_style, evaluate_synthetic, nll
from facaid.evaluation.synthetic_report import write_report
from facaid.generator import generate
from facaid.model import save_model
from facaid.segmentation import flatten


@pytest.mark.parametrize("level", [0.05, 0.1, 0.2])
def test_noise_hits_its_level(level):
    seg = generate(12, "tenement").segmentation
    noisy, measured = perturb(seg, level, seed=3)
    assert abs(measured - level) < 0.35 * level
    assert measured == pytest.approx(changed_fraction(flatten(seg, wall="footprint"), noisy))
    assert perturb(seg, level, seed=3)[0] == noisy  # seeded
    with pytest.raises(ValueError, match="between 0 and 1"):
        perturb(seg, 1.5)


def test_nullification_never_raises_the_nll(tiny):
    model, tok = tiny
    examples = []
    for seed in range(40):
        s = generate(seed)
        tokens = tok.encode_procedure(s.procedure)
        if len(tokens[0]) <= tok.config.max_out:
            examples.append({"rows": tok.encode_segmentation(s.segmentation), "tokens": tokens,
                             "width": s.procedure.width, "height": s.procedure.height})
    plain, nullified = nll(model, tok, examples[:4])
    assert 0 < nullified < plain


def test_unconstrained_decoding_reports_invalid_sequences(tiny):
    model, tok = tiny
    c = decode(model, tok, generate(2).segmentation, constrained=False)[0]
    assert c.procedure is None and c.error  # an untrained model breaks the grammar at once


def test_evaluate_and_report(tiny, tmp_path):
    model, tok = tiny
    result = evaluate_synthetic(model, tok, count=3, seed=1000, noise_count=1, unconstrained_count=1,
                                best_of=3, progress=False)
    assert result["count"] == 3 and result["validity"]["constrained"] == 1.0
    assert result["validity"]["unconstrained"] == 0.0
    assert 0.0 <= result["exact_structure_rate"] <= 1.0
    assert [p["level"] for p in result["noise"]] == [0.0, 0.05, 0.1, 0.15, 0.2]
    assert sum(result["ted"]["histogram"].values()) == 3
    report = write_report(result, tmp_path / "report")
    text = report.read_text()
    assert "NLL per token, with nullification" in text
    best = result["best_of"]
    assert best["k"] == 3 and 0.0 <= best["exact_structure_rate"] <= 1.0 and best["latency_ms"]["median"] > 0
    assert [p["count"] for p in best["noise"]] == [1] * 5
    assert "exact structure (TED = 0), best of 3" in text and "Mean TED under noise, best of 3" in text
    for png in ("ted.png", "productions.png", "noise.png"):
        assert (tmp_path / "report" / png).stat().st_size > 1000
    styles = result["by_style"]
    assert sum(st["count"] for st in styles.values()) == 3
    assert all(set(st) == {"count", "greedy", "best_of"} for st in styles.values())
    assert "## By style" in text and "best of 3: exact" in text


def test_ceiling_is_the_truths_pick_among_the_trees_best_of_k_chose_from(tiny, tmp_path):
    from facaid.decoding import ranked_candidates
    from facaid.evaluation.synthetic import held_out
    from facaid.evaluation.ted import tree_edit_distance

    model, tok = tiny
    kw = dict(seed=1000, noise_count=1, unconstrained_count=0, best_of=4, progress=False)
    path = tmp_path / "records.jsonl"
    result = evaluate_synthetic(model, tok, count=3, ceiling=True, records=path, **kw)
    records = [json.loads(line) for line in path.read_text().splitlines()]
    assert records[0]["settings"]["ceiling"] is True
    for i, (rec, ex) in enumerate(zip(records[1:], held_out(tok, 1000), strict=False)):
        truth = ex["sample"].procedure.root
        teds = [tree_edit_distance(truth, c.procedure.root)
                for c in ranked_candidates(model, tok, ex["sample"].segmentation, 4, seed=i)]
        assert rec["best"]["ted"] == teds[0] and rec["best"]["ceiling"] == min(teds)
    assert len(records[1]["noise"][0]) == 4 and records[1]["noise"][1][3] <= records[1]["noise"][1][2]
    ceiling, best = result["best_of"]["ceiling"], result["best_of"]
    assert ceiling["ted_mean"] == pytest.approx(sum(r["best"]["ceiling"] for r in records[1:]) / 3)
    assert ceiling["ted_mean"] <= best["ted_mean"] and [p["count"] for p in ceiling["noise"]] == [1] * 5
    assert all("ceiling" in st for st in result["by_style"].values())
    text = write_report(result, tmp_path / "report").read_text()
    best_table = text.split("## Noise robustness")[0].split("Best of 4")[1]
    assert "| the truth's pick among the trees best of 4 chose from" in best_table  # in best of K's table
    assert "Mean TED under noise, the truth's pick" in text and "truth's pick: exact" in text
    # without it, the settings and records are as before, so that earlier records files still resume
    plain = evaluate_synthetic(model, tok, count=1, records=tmp_path / "plain.jsonl", **kw)
    head, rec = (json.loads(line) for line in (tmp_path / "plain.jsonl").read_text().splitlines())
    assert "ceiling" not in head["settings"] and "ceiling" not in rec["best"] and len(rec["noise"][0]) == 3
    assert "ceiling" not in plain["best_of"] and "truth's pick" not in write_report(plain, tmp_path / "r2").read_text()


def test_figures_by_style():
    figures = by_style(["wings", "house", "wings", "house"], [0, 3, 12, 0], [0, 0, 6, 0])
    assert list(figures) == ["house", "wings"]
    assert figures["house"] == {"count": 2, "greedy": {"exact_structure_rate": 0.5, "ted_le5": 1.0, "ted_mean": 1.5},
                                "best_of": {"exact_structure_rate": 1.0, "ted_le5": 1.0, "ted_mean": 0.0}}
    assert figures["wings"]["greedy"] == {"exact_structure_rate": 0.5, "ted_le5": 0.5, "ted_mean": 6.0}
    assert "best_of" not in by_style(["house"], [1])["house"]


def test_cli_evaluate(tiny, tmp_path, capsys):
    model, tok = tiny
    save_model(model, tok, tmp_path / "ckpt")
    out = tmp_path / "figures.json"
    assert main(["evaluate", "--checkpoint", str(tmp_path / "ckpt"), "--count", "2", "--noise-count", "0",
                 "--unconstrained-count", "1", "--best-of", "2", "--report", str(tmp_path / "rep"), "--json", str(out),
                 "--quiet"]) == 0
    figures = json.loads(out.read_text())
    assert figures["count"] == 2 and figures["best_of"]["k"] == 2
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "Not measured (`--noise-count 0`)." in text and "Mean TED under noise" not in text
    assert main(["evaluate", "--checkpoint", str(tmp_path / "missing"), "--count", "2"]) == 2
    assert "no checkpoint" in capsys.readouterr().err
    assert main(["evaluate", "--checkpoint", str(tmp_path / "ckpt"), "--count", "2", "--ceiling"]) == 2
    assert "give --best-of K" in capsys.readouterr().err


def _without_latency(result):
    out = {k: v for k, v in result.items() if k != "latency_ms"}
    out["best_of"] = {k: v for k, v in result["best_of"].items() if k != "latency_ms"}
    return out


def test_records_resume_a_stopped_run_with_the_figures_of_one_run(tiny, tmp_path):
    model, tok = tiny
    kw = dict(seed=1000, noise_count=2, unconstrained_count=1, best_of=2, progress=False)
    whole = evaluate_synthetic(model, tok, count=4, **kw)
    path = tmp_path / "runs" / "records.jsonl"
    evaluate_synthetic(model, tok, count=2, records=path, **kw)
    lines = path.read_text().splitlines()
    assert len(lines) == 3 and json.loads(lines[0])["settings"]["best_of"] == 2
    path.write_text("\n".join(lines[:2]) + "\n" + lines[2][: len(lines[2]) // 2])  # stopped while writing
    resumed = evaluate_synthetic(model, tok, count=4, records=path, **kw)
    records = [json.loads(line) for line in path.read_text().splitlines()[1:]]
    assert [r["i"] for r in records] == [0, 1, 2, 3]
    assert ["noise" in r for r in records] == [True, True, False, False]
    assert _without_latency(resumed) == _without_latency(whole)
    # the records answer a smaller count without measuring anything
    assert evaluate_synthetic(model, tok, count=3, records=path, **kw)["count"] == 3
    assert len(path.read_text().splitlines()) == 5


def test_records_of_other_settings_or_weights_are_refused(tiny, tmp_path):
    import torch

    model, tok = tiny
    path = tmp_path / "records.jsonl"
    kw = dict(noise_count=0, unconstrained_count=0, best_of=0, progress=False, records=path)
    evaluate_synthetic(model, tok, count=1, seed=1000, **kw)
    before = path.read_text()
    with pytest.raises(RecordsError, match=r"other settings \(seed differ\)"):
        evaluate_synthetic(model, tok, count=1, seed=1001, **kw)
    other = type(model)(model.config).eval()
    other.load_state_dict(model.state_dict())
    with torch.no_grad():
        next(other.parameters()).add_(1e-3)
    with pytest.raises(RecordsError, match=r"\(model differ\)"):
        evaluate_synthetic(other, tok, count=1, seed=1000, **kw)
    assert path.read_text() == before  # nothing lost
    bad = tmp_path / "notes.txt"
    bad.write_text("my notes\n")
    with pytest.raises(RecordsError, match="not an evaluation records file"):
        evaluate_synthetic(model, tok, count=1, seed=1000, **{**kw, "records": bad})
    assert bad.read_text() == "my notes\n"
    lines = before.splitlines()
    path.write_text("\n".join([lines[0], "{broken", lines[1]]) + "\n")  # damage before the last line is not dropped
    with pytest.raises(RecordsError, match="line 2 is not JSON"):
        evaluate_synthetic(model, tok, count=2, seed=1000, **kw)


def test_cli_evaluate_records(tiny, tmp_path, capsys):
    model, tok = tiny
    save_model(model, tok, tmp_path / "ckpt")
    records = tmp_path / "records.jsonl"
    args = ["evaluate", "--checkpoint", str(tmp_path / "ckpt"), "--count", "2", "--noise-count", "0",
            "--unconstrained-count", "0", "--report", str(tmp_path / "rep"), "--records", str(records), "--quiet"]
    assert main(args) == 0
    assert len(records.read_text().splitlines()) == 3
    # no facade decoded without the mask: its validity is not measured, not 0 %
    assert "| validity, unconstrained (0 facades) | not measured |" in (tmp_path / "rep" / "report.md").read_text()
    capsys.readouterr()
    assert main([*args, "--seed", "7"]) == 2
    assert "other settings (seed differ)" in capsys.readouterr().err


def _records(path, seed, teds, best=None, noise=None, styles=None):
    from facaid.evaluation.records import RecordLog

    log = RecordLog(path, {"seed": seed, "noise_count": len(noise or []), "model": f"m{len(teds)}{best}"})
    for i, t in enumerate(teds):
        rec = {"i": i, "index": 2 * i, "style": (styles or ["house"] * len(teds))[i], "ted": t}
        if best is not None:
            rec["best"] = {"ted": best[i]}
        if noise and i < len(noise):
            rec["noise"] = [[n, 0.05 * (j + 1), None] for j, n in enumerate(noise[i])]
        log.append(rec)
    return path


def test_compare_pairs_two_runs_facade_by_facade(tmp_path):
    from facaid.evaluation.compare import compare_records, format_comparison

    a = _records(tmp_path / "a.jsonl", 7, [0, 2, 6, 0], best=[0, 0, 4, 0], noise=[[1, 2, 3, 4], [0, 0, 0, 0]],
                 styles=["house", "wings", "wings", "house"])
    b = _records(tmp_path / "b.jsonl", 7, [0, 0, 8, 1, 5], best=[0, 1, 2, 0, 0], noise=[[0, 2, 5, 4], [0, 1, 0, 0]],
                 styles=["house", "wings", "wings", "house", "house"])
    with b.open("a") as f:
        f.write('{"i": 5, "index"')  # cut off by a stopped run: left out, the file left as it is
    before = b.read_bytes()
    result = compare_records(a, b)
    assert b.read_bytes() == before
    assert result["count"] == 4 and result["seed"] == 7 and not result["same_model"]  # facade 5 is B's alone
    g = result["figures"]["greedy"]
    assert (g["better"], g["worse"], g["mean_change"]) == (1, 2, pytest.approx(0.25))
    assert g["a"] == {"exact_structure_rate": 0.5, "ted_le5": 0.75, "ted_mean": 2.0} and g["b"]["ted_mean"] == 2.25
    assert g["interval"][0] <= 0.25 <= g["interval"][1]
    best = result["figures"]["best"]
    assert (best["better"], best["worse"], best["mean_change"]) == (1, 1, pytest.approx(-0.25))
    wings = result["figures"]["best, wings"]
    assert (wings["count"], wings["better"], wings["worse"]) == (2, 1, 1)
    ten = result["figures"]["10 % noise, greedy"]
    assert (ten["count"], ten["better"], ten["worse"], ten["mean_change"]) == (2, 0, 1, pytest.approx(0.5))
    assert "10 % noise, best" not in result["figures"]  # the noise curve had no best of K
    table = format_comparison(result)
    assert "| greedy | 4 | 50.0 % / 75.0 % / 2.00 | 50.0 % / 75.0 % / 2.25 | 1 | 2 | +0.25 (" in table


def test_compare_refuses_runs_of_other_facades(tmp_path, capsys):
    a = _records(tmp_path / "a.jsonl", 7, [0, 1])
    b = _records(tmp_path / "b.jsonl", 8, [0, 1])
    assert main(["compare", str(a), str(b)]) == 2
    assert "different facades (seed 7 and 8)" in capsys.readouterr().err
    notes = tmp_path / "notes.txt"
    notes.write_text("not records\n")
    assert main(["compare", str(a), str(notes)]) == 2
    assert "not an evaluation records file" in capsys.readouterr().err
    assert main(["compare", str(a), str(tmp_path / "missing.jsonl")]) == 2
    assert "no records file" in capsys.readouterr().err
    out = tmp_path / "cmp.json"
    assert main(["compare", str(a), str(_records(tmp_path / "c.jsonl", 7, [1, 1])), "--json", str(out)]) == 0
    assert "| greedy | 2 |" in capsys.readouterr().out
    assert json.loads(out.read_text())["figures"]["greedy"]["worse"] == 1
