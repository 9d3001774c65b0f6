"""Training: the schedule, the samples and their noise and styles, the loss, runs that resume and fine-tune."""

import json

import pytest
import torch
from model_helpers import batch, tiny, write_config

from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from facaid.model import (
    FacaidConfig,
    load_model,
)
from facaid.tokenizer import Tokenizer, TokenizerConfig
from facaid.training import load_config, train
from facaid.training.objective import lr_at, structure_weighted_loss, token_log_probs


def test_structure_weighted_loss_splits_each_size_into_its_mode_and_value():
    model, tok = tiny()
    rects, mask, ids, local, targets, boxes = batch(tok, [3, 4])
    logits, nll = model(rects, mask, ids, local, targets, boxes)
    assert torch.allclose(structure_weighted_loss(logits, targets, tok.vocab, 1.0), nll, atol=1e-6)
    token_lp, structure_lp = token_log_probs(logits, targets, tok.vocab)
    valid = targets[targets != -100]
    assert len(token_lp) == len(valid) and bool((structure_lp >= token_lp - 1e-6).all())
    # a size's structure is its mode: log P(mode), the probability of all the values of that mode summed
    lp = torch.log_softmax(logits, -1)[targets != -100]
    kinds = [tok.vocab.kind(int(t)) for t in valid]
    i = kinds.index("flt")
    r = tok.vocab.ranges["flt"]
    assert torch.isclose(structure_lp[i], torch.logsumexp(lp[i, r.start:r.stop], -1), atol=1e-5)
    j = kinds.index("rule")  # every other token is structure whole
    assert structure_lp[j] == token_lp[j]
    assert torch.isclose(structure_weighted_loss(logits, targets, tok.vocab, 5.0),
                         -(token_lp + 4.0 * structure_lp).mean(), atol=1e-6)


def test_training_lowers_the_loss_and_resumes_exactly(tmp_path):
    cfg = tmp_path / "c.toml"
    write_config(cfg, tmp_path / "run", steps=9, extra="lr = 3e-3")
    last = train(cfg, until=6, progress=False)
    log = [json.loads(x) for x in (tmp_path / "run" / "log.jsonl").read_text().splitlines()]
    assert [r["step"] for r in log] == [3, 6]
    assert log[-1]["val_loss"] < log[0]["val_loss"]
    assert 0 < log[-1]["val_structure"] < log[-1]["val_loss"]
    state = torch.load(last / "state.pt", weights_only=False)["state"]
    assert state["step"] == 6 and state["sample_index"] > 0
    # stopping at 6 and resuming to 9 == training 9 straight (same batches, same optimizer state)
    train(cfg, resume=True, progress=False)
    write_config(cfg, tmp_path / "straight", steps=9, extra="lr = 3e-3")
    train(cfg, progress=False)
    a, _ = load_model(tmp_path / "run" / "last")
    b, _ = load_model(tmp_path / "straight" / "last")
    for (name, p), (_, q) in zip(a.named_parameters(), b.named_parameters(), strict=True):
        assert torch.allclose(p, q, atol=1e-5), name


def test_config_errors(tmp_path):
    with pytest.raises(ValueError, match="encoder must be"):
        FacaidConfig(encoder="lstm")
    bad = tmp_path / "bad.toml"
    bad.write_text("[train]\nbatch = 3\n")
    with pytest.raises(ValueError, match=r"unknown key\(s\) in \[train\]: batch"):
        load_config(bad)
    bad.write_text("[optimizer]\nlr = 3\n")
    with pytest.raises(ValueError, match="unknown table"):
        load_config(bad)
    for value in ("-1.0", "nan", '"fast"'):
        bad.write_text(f"[train]\nbox_lr_scale = {value}\n")
        with pytest.raises(ValueError, match="box_lr_scale must be a finite number >= 0"):
            load_config(bad)
    for value in ("0", "-2.0", "inf", '"high"'):
        bad.write_text(f"[train]\nstructure_weight = {value}\n")
        with pytest.raises(ValueError, match="structure_weight must be a finite number > 0"):
            load_config(bad)


def test_learning_rate_schedule():
    from facaid.training import TrainConfig

    cfg = TrainConfig(lr=1e-3, min_lr=1e-4, warmup=10, steps=110)
    assert lr_at(0, cfg) == pytest.approx(1e-4)
    assert lr_at(9, cfg) == pytest.approx(1e-3)
    assert lr_at(110, cfg) == pytest.approx(1e-4)
    assert lr_at(60, cfg) == pytest.approx(5.5e-4)


def test_sample_processes_give_the_same_examples_in_the_same_order():
    from facaid.training.samples import SampleStream

    tok = Tokenizer(TokenizerConfig(max_rects=1000, max_out=160))  # short: some facades are skipped
    shares = {"annotate": 0.5, "partial": 0.3, "irregular": 0.3, "outline": 0.3}
    one = SampleStream(tok, seed=5, noise=(0.5, 0.006), **shares)
    many = SampleStream(tok, seed=5, workers=2, noise=(0.5, 0.006), **shares)
    try:
        for n in (7, 13):
            a, b = one.take(n), many.take(n)
            assert len(b) == n and repr(a) == repr(b)
            assert (one.index, one.skipped) == (many.index, many.skipped)
        assert one.skipped > 0
    finally:
        many.close()


def test_noisy_inputs_keep_the_clean_target_and_are_seeded():
    from facaid.training.samples import make_example

    tok = Tokenizer(TokenizerConfig(max_rects=1000, max_out=768))
    for index in range(4):
        clean = make_example(tok, 3, index)
        noisy = make_example(tok, 3, index, noise=(1.0, 0.006))
        again = make_example(tok, 3, index, noise=(1.0, 0.006))
        if clean is None:
            continue
        assert repr(noisy) == repr(again)
        assert repr(noisy[1]) == repr(clean[1])  # the target: the clean procedure
        assert repr(noisy[0]) != repr(clean[0])  # the input: edges moved
        assert repr(make_example(tok, 3, index, noise=(0.0, 0.006))) == repr(clean)


@pytest.mark.parametrize("name", ["annotate", "partial", "irregular", "outline"])
def test_inputs_drawn_as_people_draw_keep_the_clean_target(name):
    """Each share changes the input, seeded by the sample, never the target; a share of 0 leaves the example as it
    was. ``annotate``: edges moved as on CMP, elements left out, boxes added; ``partial``: fewer elements (10-80 %
    left out); ``irregular``: whole floors and bays moved, no window cut in pieces; ``outline``: the facade
    rectangle left out or cut."""
    from facaid.training.samples import make_example

    tok = Tokenizer(TokenizerConfig(max_rects=1000, max_out=768))
    changed = fewer = 0
    for index in range(6):
        clean = make_example(tok, 4, index)
        if clean is None:
            continue
        drawn = make_example(tok, 4, index, **{name: 1.0})
        assert repr(drawn) == repr(make_example(tok, 4, index, **{name: 1.0}))
        assert repr(drawn[1]) == repr(clean[1])
        assert repr(make_example(tok, 4, index, **{name: 0.0})) == repr(clean)
        changed += repr(drawn[0]) != repr(clean[0])
        windows, clean_windows = (drawn[0][:, 0] == 2).sum(), (clean[0][:, 0] == 2).sum()  # window rows
        fewer += windows < clean_windows
        if name == "irregular":
            assert windows == clean_windows
    assert changed >= 4
    if name == "partial":
        assert fewer >= 4


def test_an_unknown_input_share_is_refused():
    from facaid.training.samples import SampleStream

    with pytest.raises(TypeError, match="unknown input share"):
        SampleStream(Tokenizer(TokenizerConfig()), seed=1, drawn=0.5)


@pytest.mark.parametrize("field", ["noise", "annotate", "partial", "irregular", "outline"])
def test_shares_of_noisy_inputs_must_be_shares(field):
    from facaid.training.config import TrainConfig

    for bad in (-0.1, 1.5, float("nan")):
        with pytest.raises(ValueError, match=f"{field} must be a share between 0 and 1"):
            TrainConfig(**{field: bad})


def test_style_weights_draw_the_styles_of_the_samples(tmp_path):
    import random

    from facaid.generator import STYLE_NAMES, TRAINING_STYLES
    from facaid.training import TrainConfig
    from facaid.training.samples import make_example, sample_style

    cfg = TrainConfig(style_weights={"wings": 3.0, "house": 0.0})
    assert (*STYLE_NAMES, "wing") == TRAINING_STYLES
    assert cfg.styles == (*({"wings": 3.0, "house": 0.0}.get(n, 1.0) for n in STYLE_NAMES), 0.0)
    assert TrainConfig().styles is None and sample_style(1, 0, None) is None
    drawn = [sample_style(1, i, cfg.styles) for i in range(1600)]
    assert drawn == [sample_style(1, i, cfg.styles) for i in range(1600)]  # seeded by the sample
    assert "house" not in drawn and "wing" not in drawn and 0.30 < drawn.count("wings") / len(drawn) < 0.45
    # "wing" unnamed weighs nothing and changes no draw: the configs from before it draw what they drew
    before = [random.Random(f"facaid-style:1:{i}").choices(STYLE_NAMES, weights=cfg.styles[:-1])[0]
              for i in range(1600)]
    assert drawn == before
    # the examples follow the drawn styles
    tok = Tokenizer(TokenizerConfig(max_rects=1000, max_out=768))
    for style in ("wings", "wing"):
        only = tuple(1.0 if n == style else 0.0 for n in TRAINING_STYLES)
        index = next(i for i in range(8) if make_example(tok, 3, i, styles=only) is not None)
        example = make_example(tok, 3, index, styles=only)
        assert repr(example[1]) == repr(tok.encode_target(generate(sample_seed(3, index), style).procedure))
    for weights, message in (({"gothic": 1.0}, "unknown style"), ({"wings": -1.0}, "finite numbers >= 0"),
                             ({"wings": float("nan")}, "finite numbers >= 0"),
                             ({n: 0.0 for n in TRAINING_STYLES}, "at least one style")):
        with pytest.raises(ValueError, match=message):
            TrainConfig(style_weights=weights)
    toml = tmp_path / "w.toml"
    toml.write_text('[train]\nstyle_weights = { wings = 2.5 }\n')
    assert load_config(toml)[2].style_weights == {"wings": 2.5}
    toml.write_text('[train]\nstyle_weights = { wings = "many" }\n')
    with pytest.raises(ValueError, match="finite numbers >= 0"):
        load_config(toml)


def test_structure_weight_steers_training_to_the_structure(tmp_path):
    """The same steps on the same batches lower the structure's validation NLL more when it weighs more."""
    cfg = tmp_path / "c.toml"
    write_config(cfg, tmp_path / "base", steps=3, extra="lr = 3e-3")
    base = train(cfg, progress=False)
    structure = {}
    for weight in (1.0, 20.0):
        write_config(cfg, tmp_path / f"w{weight}", steps=9,
                     extra=f'lr = 1e-2\ninit = "{base}"\nstructure_weight = {weight}')
        train(cfg, progress=False)
        log = [json.loads(x) for x in (tmp_path / f"w{weight}" / "log.jsonl").read_text().splitlines()]
        structure[weight] = log[-1]["val_structure"]
    assert structure[20.0] < structure[1.0]


def test_fine_tuning_starts_from_a_checkpoint(tmp_path):
    cfg = tmp_path / "c.toml"
    write_config(cfg, tmp_path / "base", steps=3, extra="lr = 3e-3")
    base = train(cfg, progress=False)
    # zero steps from init: the weights are the checkpoint's, exactly
    write_config(cfg, tmp_path / "tuned", steps=0, extra=f'noise = 0.5\ninit = "{base}"')
    tuned = train(cfg, progress=False)
    a, _ = load_model(base)
    b, _ = load_model(tuned)
    for (name, p), (_, q) in zip(a.named_parameters(), b.named_parameters(), strict=True):
        assert torch.equal(p, q), name
    state = torch.load(tuned / "state.pt", weights_only=False)["state"]
    assert state["step"] == 0
    # a config that adds the peer counts starts from the same weights, the count embeddings at zero
    write_config(cfg, tmp_path / "counts", steps=0, extra=f'init = "{base}"')
    cfg.write_text(cfg.read_text().replace("[tokenizer]", "[tokenizer]\ncount_features = true"))
    counts, counts_tok = load_model(train(cfg, progress=False))
    assert counts_tok.config.count_features
    assert all(torch.equal(p, a.state_dict()[n]) for n, p in counts.state_dict().items() if n in a.state_dict())
    assert all((e.weight == 0).all() for e in counts.count_fields)
    # they may learn faster than the rest (train.count_lr_scale): Adam's first steps move them by about lr each
    moved = {}
    for scale in (1.0, 10.0):
        write_config(cfg, tmp_path / f"counts-{scale}", steps=2, extra=f'init = "{base}"\ncount_lr_scale = {scale}')
        cfg.write_text(cfg.read_text().replace("[tokenizer]", "[tokenizer]\ncount_features = true"))
        tuned_counts, _ = load_model(train(cfg, progress=False))
        moved[scale] = max(e.weight.abs().max().item() for e in tuned_counts.count_fields)
    assert 5 < moved[10.0] / moved[1.0] < 15
    # a config that adds the box bias starts from the same weights, its scales at zero; they learn at
    # train.box_lr_scale, and 0 freezes them while the rest learns
    box = {}
    for scale in ("start", 0.0, 1.0, 10.0):
        steps = 0 if scale == "start" else 2
        lr_scale = 1.0 if scale == "start" else scale
        write_config(cfg, tmp_path / f"box-{scale}", steps=steps,
                     extra=f'init = "{base}"\nbox_lr_scale = {lr_scale}')
        cfg.write_text(cfg.read_text().replace("[model]", "[model]\nbox_bias = true"))
        biased, _ = load_model(train(cfg, progress=False))
        box[scale] = biased.box_scale.abs().max().item()
        same = [torch.equal(p, a.state_dict()[n]) for n, p in biased.state_dict().items() if n != "box_scale"]
        assert all(same) if scale == "start" else not all(same)
    assert box["start"] == box[0.0] == 0.0 and 5 < box[10.0] / box[1.0] < 15
    # a config that appends decoder blocks starts from the same logits; the new blocks learn at
    # train.grown_lr_scale, and a resumed run keeps them in their own optimizer groups
    grown = {}
    for scale in (1.0, 10.0):
        write_config(cfg, tmp_path / f"deep-{scale}", steps=2, extra=f'init = "{base}"\ngrown_lr_scale = {scale}')
        cfg.write_text(cfg.read_text().replace("decoder_layers = 1", "decoder_layers = 2"))
        deep, _ = load_model(train(cfg, progress=False))
        grown[scale] = deep.decoder.h[1].mlp.c_proj.weight.abs().max().item()
    assert 5 < grown[10.0] / grown[1.0] < 15
    write_config(cfg, tmp_path / "deep-resumed", steps=2, extra=f'init = "{base}"\ngrown_lr_scale = 10.0')
    cfg.write_text(cfg.read_text().replace("decoder_layers = 1", "decoder_layers = 2"))
    train(cfg, until=1, progress=False)
    resumed, _ = load_model(train(cfg, resume=True, progress=False))
    assert torch.allclose(resumed.decoder.h[1].mlp.c_proj.weight, deep.decoder.h[1].mlp.c_proj.weight, atol=1e-6)
    # the same for encoder layers
    grown = {}
    for scale in (1.0, 10.0):
        write_config(cfg, tmp_path / f"enc-{scale}", steps=2, extra=f'init = "{base}"\ngrown_lr_scale = {scale}')
        cfg.write_text(cfg.read_text().replace("encoder_layers = 1", "encoder_layers = 2"))
        wide, _ = load_model(train(cfg, progress=False))
        grown[scale] = wide.encoder.encoder.layer[1].output.dense.weight.abs().max().item()
    assert 5 < grown[10.0] / grown[1.0] < 15
    write_config(cfg, tmp_path / "tuned", steps=0, extra=f'noise = 0.5\ninit = "{base}"')
    text = cfg.read_text()
    cfg.write_text(text.replace("d_model = 16", "d_model = 8"))
    with pytest.raises(ValueError, match="another architecture .d_model"):
        train(cfg, progress=False)
