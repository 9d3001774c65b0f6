import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import torch

from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from facaid.labels import LABELS
from facaid.model import (
    FacaidConfig,
    FacaidModel,
    batch_inputs,
    batch_outputs,
    load_model,
    save_model,
)
from facaid.paths import DEFAULT_CHECKPOINT, ROOT
from facaid.tokenizer import Tokenizer, TokenizerConfig
from facaid.training import load_config, train
from facaid.training.config import ARCHITECTURE
from facaid.training.objective import lr_at, structure_weighted_loss, token_log_probs
from facaid.training.surgery import adapt_to_tokenizer, deepened, encoder_deepened, widen_for_counts, with_box_bias

# what `train.init` may add to a checkpoint's model (`deepened`, `with_box_bias`), and what it must keep (dropout is a
# training setting, not compared)
GROWN = ("decoder_layers", "encoder_layers", "box_bias")
FIXED = tuple(k for k in ARCHITECTURE if k not in (*GROWN, "dropout"))
TINY = {"d_model": 16, "encoder_layers": 1, "decoder_layers": 1, "heads": 2, "ffn": 32, "node_boxes": True}


def tiny(rect_tokens=1, max_out=768, encoder="bidirectional"):
    tc = TokenizerConfig(max_rects=1000, max_out=max_out, rect_tokens=rect_tokens)
    torch.manual_seed(0)
    return FacaidModel(FacaidConfig(tokenizer=tc.to_dict(), encoder=encoder, **TINY)), Tokenizer(tc)


def batch(tok, seeds):
    samples = [generate(s) for s in seeds]
    rects, mask = batch_inputs([tok.encode_segmentation(s.segmentation) for s in samples])
    ids, local, targets, boxes = batch_outputs([tok.encode_target(s.procedure) for s in samples])
    return rects, mask, ids, local, targets, boxes


@pytest.mark.parametrize("rect_tokens, encoder", [(1, "bidirectional"), (5, "bidirectional"), (1, "causal")])
def test_forward_shapes_and_loss(rect_tokens, encoder):
    model, tok = tiny(rect_tokens, encoder=encoder)
    rects, mask, ids, local, targets, boxes = batch(tok, [1, 2, 3])
    logits, loss = model(rects, mask, ids, local, targets, boxes)
    assert logits.shape == (*ids.shape, len(tok.vocab))
    assert loss.item() == pytest.approx(torch.log(torch.tensor(float(len(tok.vocab)))).item(), rel=0.1)
    memory, memory_mask = model.encode(rects, mask)
    assert memory.shape[1] == rects.shape[1] * rect_tokens


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


def test_widening_for_peer_counts_keeps_the_logits_until_trained(tmp_path):
    model, tok = tiny()
    model.eval()
    wide, wide_tok = widen_for_counts(model, tok)
    assert wide_tok.config.count_features and not tok.config.count_features
    narrow_batch, wide_batch = batch(tok, [4, 5]), batch(wide_tok, [4, 5])
    assert wide_batch[0].shape[-1] == 9 and narrow_batch[0].shape[-1] == 5
    with torch.no_grad():
        a, _ = model(*narrow_batch[:4], boxes=narrow_batch[5])
        b, _ = wide(*wide_batch[:4], boxes=wide_batch[5])
    assert torch.equal(a, b)
    # the count embeddings learn: one step moves them and changes the logits
    wide.train()
    _, loss = wide(*wide_batch)
    loss.backward()
    assert all(e.weight.grad.abs().sum() > 0 for e in wide.count_fields)
    save_model(wide, wide_tok, tmp_path / "wide")
    again, again_tok = load_model(tmp_path / "wide")
    assert again_tok.config == wide_tok.config and len(again.count_fields) == 4
    with pytest.raises(ValueError, match="reads 9 fields per rectangle, got 5"):
        again.encode(narrow_batch[0], narrow_batch[1])
    with pytest.raises(ValueError, match="reads the peer counts already"):
        widen_for_counts(again, again_tok)


def test_box_bias_starts_at_zero_and_leans_on_the_rectangles_in_the_node_box(tmp_path):
    model, tok = tiny()
    model.eval()
    biased = with_box_bias(model)
    assert biased.config.box_bias and biased.box_scale.shape == (2,) and not biased.box_scale.any()
    rects, mask, ids, local, targets, boxes = batch(tok, [4, 5])
    with torch.no_grad():
        a, _ = model(rects, mask, ids, local, boxes=boxes)
        b, _ = biased(rects, mask, ids, local, boxes=boxes)
    assert torch.equal(a, b)
    # the bias per head is the scale times the share of each rectangle's area inside the node box
    image, label = len(LABELS), 2  # the image row's label is len(LABELS)
    geometry = torch.tensor([[[image, 3, 0, 9, 9], [label, 10, 10, 4, 4], [label, 11, 10, 2, 2], [label, 40, 40, 2, 2],
                              [label, 10, 10, 4, 4]]])
    padding = torch.tensor([[True, True, True, True, False]])
    node = torch.tensor([[[10, 10, 4, 2], [0, 0, 0, 0]]])  # a box, then no node (EOS)
    biased.box_scale.data = torch.tensor([2.0, -1.0])
    bias = biased.cross_bias(biased.memory_boxes(geometry), padding, node)
    assert bias.shape == (1, 2, 2, 5)
    assert bias[0, 0, 0, :4].tolist() == [0.0, 1.0, 2.0, 0.0]  # half of rectangle 1 is inside, all of rectangle 2
    assert bias[0, 1, 0, :4].tolist() == [0.0, -0.5, -1.0, 0.0]
    assert bias[0, :, 1, :4].eq(0).all()  # no node: the same bias everywhere, no change
    assert bias[0, :, :, 4].eq(torch.finfo(bias.dtype).min).all()  # padding stays masked
    # with scales, the logits move and the scales get gradients; they survive save and load
    biased.train()
    changed, loss = biased(rects, mask, ids, local, targets, boxes)
    assert not torch.allclose(changed, a)
    loss.backward()
    assert biased.box_scale.grad.abs().sum() > 0
    save_model(biased, tok, tmp_path / "biased")
    again, _ = load_model(tmp_path / "biased")
    assert torch.equal(again.box_scale, biased.box_scale)
    with pytest.raises(ValueError, match="has the box bias already"):
        with_box_bias(again)
    with pytest.raises(ValueError, match="pass memory_boxes"):
        memory, memory_mask = again.encode(rects, mask)
        again.decode(ids, local, memory, memory_mask, boxes=boxes)
    with pytest.raises(ValueError, match="box_bias needs node_boxes"):
        FacaidConfig(box_bias=True, node_boxes=False)
    five, five_tok = tiny(rect_tokens=5)
    rects5 = batch(five_tok, [4])[0]
    assert with_box_bias(five).memory_boxes(rects5).shape == (1, rects5.shape[1] * 5, 5)


def test_a_deepened_decoder_keeps_the_logits_until_trained(tmp_path):
    base, tok = tiny()
    model = with_box_bias(base)
    model.eval()
    deep = deepened(model, 3)
    assert deep.config.decoder_layers == 3 and len(deep.decoder.h) == 3
    rects, mask, ids, local, targets, boxes = batch(tok, [4, 5])
    with torch.no_grad():
        a, _ = model(rects, mask, ids, local, boxes=boxes)
        b, _ = deep(rects, mask, ids, local, boxes=boxes)
    assert torch.equal(a, b)
    # the new blocks copy the last one but write nothing: their output projections are zero, the rest is a copy
    last, new = dict(deep.decoder.h[0].named_parameters()), dict(deep.decoder.h[2].named_parameters())
    for name, p in new.items():
        if name.startswith(("attn.c_proj.", "crossattention.c_proj.", "mlp.c_proj.")):
            assert not p.any(), name
        else:
            assert torch.equal(p, last[name]) and p.data_ptr() != last[name].data_ptr(), name
    # they learn: the zero projections get gradients, and one step changes the logits
    deep.train()
    _, loss = deep(rects, mask, ids, local, targets, boxes)
    loss.backward()
    assert deep.decoder.h[2].mlp.c_proj.weight.grad.abs().sum() > 0
    with torch.no_grad():
        deep.decoder.h[2].mlp.c_proj.weight -= 0.5 * deep.decoder.h[2].mlp.c_proj.weight.grad.sign()
    deep.eval()
    with torch.no_grad():
        assert not torch.allclose(deep(rects, mask, ids, local, boxes=boxes)[0], a)
    # token-by-token decoding runs every block, in torch and in C
    from facaid.decoding import decode
    s = generate(5)
    fast, slow = (decode(deep, tok, s.segmentation, max_len=80, native=flag)[0] for flag in (True, False))
    assert fast.ids == slow.ids
    save_model(deep, tok, tmp_path / "deep")
    again, _ = load_model(tmp_path / "deep")
    assert again.config.decoder_layers == 3
    with pytest.raises(ValueError, match="more than the 3 decoder layers it has, got 3"):
        deepened(again, 3)


@pytest.mark.parametrize("encoder", ["bidirectional", "causal"])
def test_a_deepened_encoder_keeps_the_memory_until_trained(tmp_path, encoder):
    model, tok = tiny(encoder=encoder)
    with torch.no_grad():  # a trained layer's closing norm has a gain and a bias, which the new layers must keep
        for p in model.encoder.parameters():
            p.add_(0.3 * torch.randn_like(p))
    model.eval()
    deep = encoder_deepened(model, 3)
    deep.eval()
    assert deep.config.encoder_layers == 3 and deep.config.decoder_layers == model.config.decoder_layers
    rects, mask, ids, local, targets, boxes = batch(tok, [4, 5])
    with torch.no_grad():
        a, _ = model(rects, mask, ids, local, boxes=boxes)
        b, _ = deep(rects, mask, ids, local, boxes=boxes)
        assert torch.allclose(model.encode(rects, mask)[0], deep.encode(rects, mask)[0], atol=1e-5)
    assert torch.allclose(a, b, atol=1e-5)
    layers = deep.encoder.encoder.layer if encoder == "bidirectional" else deep.encoder.h
    assert len(layers) == 3
    # the new layers write nothing at first, and learn: one step on their zero projections changes the memory
    outputs = ("attention.output.dense.", "output.dense.") if encoder == "bidirectional" else ("attn.c_proj.",
                                                                                                "mlp.c_proj.")
    for name, p in layers[2].named_parameters():
        if name.startswith(outputs):
            assert not p.any(), name
    deep.train()
    _, loss = deep(rects, mask, ids, local, targets, boxes)
    loss.backward()
    out = layers[2].output.dense if encoder == "bidirectional" else layers[2].mlp.c_proj
    assert out.weight.grad.abs().sum() > 0
    with torch.no_grad():
        out.weight -= 0.5 * out.weight.grad.sign()
        assert not torch.allclose(deep.encode(rects, mask)[0], model.encode(rects, mask)[0], atol=1e-3)
    save_model(deep, tok, tmp_path / "deep")
    again, _ = load_model(tmp_path / "deep")
    assert again.config.encoder_layers == 3
    with pytest.raises(ValueError, match="more than the 3 encoder layers it has, got 2"):
        encoder_deepened(again, 2)


def test_finer_coordinates_read_positions_as_before_and_sizes_between_two_steps_as_their_mean():
    model, tok = tiny()
    model.eval()
    fine_cfg = replace(tok.config, coord_bins=256, aspect_bins=128)
    fine, fine_tok = adapt_to_tokenizer(model, tok, fine_cfg)
    assert fine_tok.config == fine_cfg and fine.config.tokenizer_config == fine_cfg
    x, fx = model.fields[1].weight, fine.fields[1].weight
    assert fx.shape[0] == 256 and all(torch.equal(fx[j], x[j // 2]) for j in range(256))
    w, fw = model.fields[3].weight, fine.fields[3].weight
    assert fw.shape[0] == 257 and torch.equal(fw[0], w[0]) and torch.equal(fw[1], w[1])
    assert all(torch.equal(fw[2 * n], w[n]) for n in range(1, 129))
    assert all(torch.allclose(fw[2 * n + 1], (w[n] + w[n + 1]) / 2) for n in range(1, 128))
    # with the size tables blanked, a square image's rectangles give the same memory at 128 and 256 steps
    for m in (model, fine):
        for f in (3, 4):
            torch.nn.init.zeros_(m.fields[f].weight)
    arr = np.array([[1, 0, 0, 300, 300], [2, 37, 41, 95, 120], [2, 151, 41, 209, 120], [3, 120, 200, 180, 300]])
    coarse_rows, fine_rows = tok.encode_rect_array(300, 300, arr), fine_tok.encode_rect_array(300, 300, arr)
    assert not (coarse_rows[1:, 1:3] == fine_rows[1:, 1:3]).all()
    with torch.no_grad():
        a, _ = model.encode(*batch_inputs([coarse_rows]))
        b, _ = fine.encode(*batch_inputs([fine_rows]))
    assert torch.allclose(a, b, atol=1e-6)


def test_added_peer_rules_start_at_zero_and_what_cannot_be_adapted_is_refused():
    tc = TokenizerConfig(max_rects=1000, count_features=True)
    torch.manual_seed(0)
    model, tok = FacaidModel(FacaidConfig(tokenizer=tc.to_dict(), **TINY)).eval(), Tokenizer(tc)
    both, both_tok = adapt_to_tokenizer(model, tok, replace(tc, peer_rule="overlap+shape"))
    rows, both_rows = batch(tok, [4, 5]), batch(both_tok, [4, 5])
    assert rows[0].shape[-1] == 9 and both_rows[0].shape[-1] == 13
    assert torch.equal(rows[0], both_rows[0][..., :9])
    with torch.no_grad():
        assert torch.equal(model(*rows[:4], boxes=rows[5])[0], both(*both_rows[:4], boxes=both_rows[5])[0])
    assert len(both.count_fields) == 8 and not any(e.weight.any() for e in both.count_fields[4:])
    for target, message in ((replace(tc, coord_bins=192, aspect_bins=96), "integer factor finer"),
                            (replace(tc, coord_bins=256), "coord_bins and aspect_bins alike"),
                            (replace(tc, peer_rule="shape"), "added after the ones read now"),
                            (replace(tc, size_bins=64), "another size_bins")):
        with pytest.raises(ValueError, match=message):
            adapt_to_tokenizer(model, tok, target)
    with pytest.raises(ValueError, match="added after the ones read now: overlap\\+shape -> overlap"):
        adapt_to_tokenizer(both, both_tok, tc)


def test_the_shipped_weights_adapted_to_finer_coordinates_keep_their_loss():
    from facaid.training.samples import SampleStream

    model, tok = load_model(DEFAULT_CHECKPOINT)
    c = tok.config
    fine, fine_tok = adapt_to_tokenizer(model, tok, replace(c, coord_bins=2 * c.coord_bins,
                                                            aspect_bins=2 * c.aspect_bins))

    def loss(m, t):
        examples = SampleStream(t, seed=2).take(16)
        rects, mask = batch_inputs([e[0] for e in examples])
        ids, local, targets, boxes = batch_outputs([e[1] for e in examples])
        with torch.no_grad():
            return m(rects, mask, ids, local, targets, boxes)[1].item()

    before, after = loss(model, tok), loss(fine, fine_tok)
    assert after < 1.15 * before, (before, after)


def test_padding_does_not_change_a_sequence():
    model, tok = tiny()
    model.eval()
    rects, mask, ids, local, _, boxes = batch(tok, [7, 8])
    alone = batch(tok, [7])
    with torch.no_grad():
        both = model(rects, mask, ids, local, boxes=boxes)[0][0]
        one = model(*alone[:4], boxes=alone[5])[0][0]
    n = alone[2].shape[1]
    assert torch.allclose(both[:n], one, atol=1e-5)


def test_cached_and_uncached_decoding_agree():
    from facaid.decoder import DecoderState

    model, tok = tiny()
    model.eval()
    rects, mask, ids, local, _, boxes = batch(tok, [9])
    with torch.no_grad():
        memory, mmask = model.encode(rects, mask)
        full = model.decode(ids, local, memory, mmask, boxes=boxes)
        state = DecoderState(model, memory, mmask, max_len=ids.shape[1])
        x = model.embed_outputs(ids, local, boxes)
        steps = [state.step(x[:, i]) for i in range(11)]
    assert torch.allclose(full[:, 10], steps[10], atol=1e-5)
    assert torch.allclose(full[:, 0], steps[0], atol=1e-5)


def test_save_load_round_trip_and_grammar_check(tmp_path):
    model, tok = tiny()
    save_model(model, tok, tmp_path / "ckpt")
    loaded, tok2 = load_model(tmp_path / "ckpt")
    assert tok2.vocab.tokens == tok.vocab.tokens
    rects, mask, ids, local, _, boxes = batch(tok, [3])
    model.eval()
    with torch.no_grad():
        assert torch.equal(model(rects, mask, ids, local, boxes=boxes)[0],
                           loaded(rects, mask, ids, local, boxes=boxes)[0])
        with pytest.raises(ValueError, match="reads node boxes"):
            model(rects, mask, ids, local)
    assert (tmp_path / "ckpt" / "model.safetensors").is_file()
    cfg = json.loads((tmp_path / "ckpt" / "config.json").read_text())
    cfg["grammar"] = "facaid-split-0"
    (tmp_path / "ckpt" / "config.json").write_text(json.dumps(cfg))
    with pytest.raises(ValueError, match="trained for grammar 'facaid-split-0'"):
        load_model(tmp_path / "ckpt")
    with pytest.raises(FileNotFoundError, match="no checkpoint"):
        load_model(tmp_path / "nothing")


def write_config(path, out, steps=6, extra=""):
    path.write_text(f"""
[model]
d_model = 16
encoder_layers = 1
decoder_layers = 1
heads = 2
ffn = 32
node_boxes = true
[tokenizer]
max_rects = 400
max_out = 400
[train]
out = "{out}"
batch_size = 4
pool_batches = 2
steps = {steps}
warmup = 2
eval_every = 3
save_every = 3
val_count = 4
{extra}
""")


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


EXPERIMENTS = ROOT / "experiments"


def _shipped() -> tuple[dict, TokenizerConfig]:
    shipped = json.loads((DEFAULT_CHECKPOINT / "config.json").read_text())
    return shipped, TokenizerConfig(**shipped.pop("tokenizer"))


@pytest.mark.parametrize("name", sorted(path.stem for path in (ROOT / "configs").glob("*.toml")))
def test_user_configs_parse_and_shipped_toml_states_the_shipped_model(name):
    """configs/ holds what a user runs: each parses into a schedule; shipped.toml is the shipped model and tokenizer
    exactly, the others share its fixed architecture (width, heads, feed-forward)."""
    model_config, tok_config, train_config = load_config(ROOT / "configs" / f"{name}.toml")
    assert train_config.steps > 0 and train_config.lr > train_config.min_lr and not train_config.init
    shipped, shipped_tok = _shipped()
    for key in FIXED:
        assert getattr(model_config, key) == shipped[key], key
    if name == "shipped":
        assert tok_config == shipped_tok
        for key in GROWN:
            assert getattr(model_config, key) == shipped[key], key


def _runs() -> dict[Path, Path]:
    """The experiments' configs by the weights their runs leave (``train.out``/last, resolved)."""
    return {(ROOT / load_config(p)[2].out / "last").resolve(): p for p in EXPERIMENTS.glob("*/config.toml")}


def test_every_experiment_has_its_config_and_notes():
    folders = [p for p in EXPERIMENTS.iterdir() if p.is_dir()]
    assert len(folders) >= 15
    for folder in folders:
        assert (folder / "config.toml").is_file() and (folder / "notes.md").is_file(), folder.name
        date, name = folder.name[:10], folder.name[11:]
        assert date.count("-") == 2 and name, f"{folder.name}: expected YYYY-MM-DD-name"
        assert (folder / "notes.md").read_text().startswith(f"# {name} ({date})")


def test_the_shipped_checkpoint_is_the_last_link_of_the_experiments_chain():
    """Following ``train.init`` from run to run, the experiments marked as links of the shipped chain lead to one
    last run whose model and tokenizer are the shipped checkpoint's; each link trains its parent's model or adds
    what `train.init` may add (decoder blocks, the box bias). Runs tried and not shipped start from the shipped
    checkpoint or another experiment's run."""
    runs = _runs()
    configs = {path.parent.name: load_config(path) for path in runs.values()}
    chain = {path.parent.name for path in runs.values()
             if "in the chain that made the shipped checkpoint" in (path.parent / "notes.md").read_text()}
    assert len(chain) == 15
    parents = {}
    for name, (_, _, cfg) in configs.items():
        init = (ROOT / cfg.init).resolve()
        if init in runs:
            parents[name] = runs[init].parent.name
        elif name in chain:
            assert cfg.init == "runs/gpu/last" or not cfg.init, f"{name}: init {cfg.init} is no run of the chain"
        else:
            assert init == DEFAULT_CHECKPOINT.resolve(), f"{name}: init {cfg.init} is neither shipped nor a run"
    for name, parent in parents.items():
        model_config, parent_model = configs[name][0], configs[parent][0]  # the tokenizer may read more
        for key in FIXED:
            assert getattr(parent_model, key) == getattr(model_config, key), (name, key)
        for key in GROWN:
            assert getattr(parent_model, key) <= getattr(model_config, key), (name, key)
    last = [name for name in chain if name not in {parents[n] for n in chain if n in parents}]
    assert len(last) == 1, last
    model_config, tok_config, _ = configs[last[0]]
    shipped, shipped_tok = _shipped()
    assert shipped_tok == tok_config
    for key in (*FIXED, *GROWN):
        assert shipped[key] == getattr(model_config, key), key


def test_the_shipped_checkpoint_holds_weights_config_tokenizer_and_a_model_card():
    """No optimizer state and no logs: --resume state lives in a run's directory, logs in experiments/."""
    assert {p.name for p in DEFAULT_CHECKPOINT.iterdir()} == {"config.json", "model.safetensors", "tokenizer.json",
                                                             "README.md"}
    card = (DEFAULT_CHECKPOINT / "README.md").read_text()
    header, _, body = card.removeprefix("---\n").partition("\n---\n")
    assert card.startswith("---\n") and "license:" in header and "pipeline_tag:" in header
    for section in ("## Training data", "## Figures", "## Limits", "## How it was made"):
        assert section in body, section


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
    one = SampleStream(tok, seed=5, noise=(0.5, 0.006))
    many = SampleStream(tok, seed=5, workers=2, noise=(0.5, 0.006))
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
