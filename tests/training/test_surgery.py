"""Model surgery: each change to a trained model starts out computing what the model computed."""

from dataclasses import replace

import numpy as np
import pytest
import torch
from model_helpers import TINY, batch, tiny

from facaid.generator import generate
from facaid.labels import LABELS
from facaid.model import (
    FacaidConfig,
    FacaidModel,
    batch_inputs,
    batch_outputs,
    load_model,
    save_model,
)
from facaid.paths import DEFAULT_CHECKPOINT
from facaid.tokenizer import Tokenizer, TokenizerConfig
from facaid.training.surgery import adapt_to_tokenizer, deepened, encoder_deepened, widen_for_counts, with_box_bias


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
