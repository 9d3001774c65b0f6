"""The transformer: shapes and loss, padding, the cached step against teacher forcing, save and load."""

import json

import pytest
import torch
from model_helpers import batch, tiny

from facaid.model import (
    load_model,
    save_model,
)


@pytest.mark.parametrize("rect_tokens, encoder", [(1, "bidirectional"), (5, "bidirectional"), (1, "causal")])
def test_forward_shapes_and_loss(rect_tokens, encoder):
    model, tok = tiny(rect_tokens, encoder=encoder)
    rects, mask, ids, local, targets, boxes = batch(tok, [1, 2, 3])
    logits, loss = model(rects, mask, ids, local, targets, boxes)
    assert logits.shape == (*ids.shape, len(tok.vocab))
    assert loss.item() == pytest.approx(torch.log(torch.tensor(float(len(tok.vocab)))).item(), rel=0.1)
    memory, memory_mask = model.encode(rects, mask)
    assert memory.shape[1] == rects.shape[1] * rect_tokens


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
    from facaid.model.decoder import DecoderState

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
