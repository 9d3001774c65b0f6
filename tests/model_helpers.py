"""Helpers the model and training tests share: a tiny model, a batch of generated facades, a training config."""

import torch

from facaid.generator import generate
from facaid.model import FacaidConfig, FacaidModel, batch_inputs, batch_outputs
from facaid.tokenizer import Tokenizer, TokenizerConfig
from facaid.training.config import ARCHITECTURE

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
