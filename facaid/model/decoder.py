"""The decoder, written once, nanoGPT-style: GPT-2 blocks in plain torch for training and for decoding.

Each block is pre-layer-norm: causal self-attention, cross-attention on the encoder's memory, a tanh-GELU MLP,
each added to the residual stream. `Decoder.forward` runs a whole teacher-forced sequence (training, the
validation loss, scoring); `DecoderState` decodes token by token with the same blocks, keeping each block's keys
and values in preallocated buffers and the memory's cross-attention keys and values computed once. Parameter
names and layouts are those of Hugging Face's GPT-2 (``Conv1D`` weights are (in, out)), so the checkpoints trained
with that decoder load unchanged.

Best-of-K decodes K rows against one input: given that input's memory once and ``rows=K``, the rows share its
cross-attention keys and values, and a step attends with the K queries of a head in one matrix product instead
of K vector products over K copies of the memory. With the box bias (`FacaidConfig.box_bias`) each step also
gets each row's node box and adds the same cross-attention bias as `FacaidModel.cross_bias`, computed once per
node rather than once per token. `facaid.native` runs `DecoderState.step` in C, from the same weights and buffers.

Shapes: B rows, T positions, M memory positions, H heads of dh = d / H channels.
"""

from __future__ import annotations

from typing import NamedTuple

import torch
import torch.nn.functional as F
from torch import nn

LAYER_NORM_EPS = 1e-5  # GPT-2's


def padding_mask(mask: torch.Tensor, dtype: torch.dtype) -> torch.Tensor:
    """mask (B, N) bool, True where a position is real -> additive (B, 1, 1, N): the smallest float at padding."""
    return torch.zeros(mask.shape, dtype=dtype, device=mask.device).masked_fill(
        ~mask, torch.finfo(dtype).min)[:, None, None, :]


class Conv1D(nn.Module):
    """GPT-2's linear layer: ``x @ weight + bias`` with weight (in, out)."""

    def __init__(self, n_in: int, n_out: int):
        super().__init__()
        self.weight = nn.Parameter(torch.empty(n_in, n_out))
        self.bias = nn.Parameter(torch.zeros(n_out))

    def forward(self, x: torch.Tensor) -> torch.Tensor:  # (..., in) -> (..., out)
        return torch.addmm(self.bias, x.reshape(-1, x.shape[-1]), self.weight).view(*x.shape[:-1], -1)


class SelfAttention(nn.Module):
    def __init__(self, d: int):
        super().__init__()
        self.c_attn = Conv1D(d, 3 * d)  # queries, keys, values
        self.c_proj = Conv1D(d, d)


class CrossAttention(nn.Module):
    def __init__(self, d: int):
        super().__init__()
        self.q_attn = Conv1D(d, d)  # queries, from the decoder
        self.c_attn = Conv1D(d, 2 * d)  # keys and values, from the memory
        self.c_proj = Conv1D(d, d)


class MLP(nn.Module):
    def __init__(self, d: int, ffn: int):
        super().__init__()
        self.c_fc = Conv1D(d, ffn)
        self.c_proj = Conv1D(ffn, d)


class BlockWeights(NamedTuple):
    """A block's tensors by name: the step reads them from a tuple (an attribute of a module costs more than the
    small products it feeds)."""

    ln_1: tuple[torch.Tensor, torch.Tensor]
    attn_w: torch.Tensor  # (d, 3d): queries, keys, values
    attn_b: torch.Tensor
    attn_proj_w: torch.Tensor  # (d, d)
    attn_proj_b: torch.Tensor
    ln_cross: tuple[torch.Tensor, torch.Tensor]
    cross_q_w: torch.Tensor  # (d, d)
    cross_q_b: torch.Tensor
    cross_kv_w: torch.Tensor  # (d, 2d): the memory's keys and values
    cross_kv_b: torch.Tensor
    cross_proj_w: torch.Tensor  # (d, d)
    cross_proj_b: torch.Tensor
    ln_2: tuple[torch.Tensor, torch.Tensor]
    fc_w: torch.Tensor  # (d, ffn)
    fc_b: torch.Tensor
    mlp_proj_w: torch.Tensor  # (ffn, d)
    mlp_proj_b: torch.Tensor


class Block(nn.Module):
    """One decoder block. Its arithmetic is `block_forward`'s, on `weights`; the submodules hold the parameters under
    GPT-2's names."""

    def __init__(self, d: int, heads: int, ffn: int, dropout: float, cross: bool = True):
        super().__init__()
        if d % heads:
            raise ValueError(f"d_model {d} is not divisible by {heads} heads")
        self.d, self.heads, self.dropout = d, heads, dropout
        self.ln_1 = nn.LayerNorm(d, eps=LAYER_NORM_EPS)
        self.attn = SelfAttention(d)
        if cross:  # without: a block of the causal encoder (`facaid.model.encoder.CausalEncoder`)
            self.ln_cross_attn = nn.LayerNorm(d, eps=LAYER_NORM_EPS)
            self.crossattention = CrossAttention(d)
        self.ln_2 = nn.LayerNorm(d, eps=LAYER_NORM_EPS)
        self.mlp = MLP(d, ffn)

    def weights(self) -> BlockWeights:
        a, m = self.attn, self.mlp
        c = getattr(self, "crossattention", None)
        cross = (None,) * 7 if c is None else ((self.ln_cross_attn.weight, self.ln_cross_attn.bias), c.q_attn.weight,
                                               c.q_attn.bias, c.c_attn.weight, c.c_attn.bias, c.c_proj.weight,
                                               c.c_proj.bias)
        return BlockWeights((self.ln_1.weight, self.ln_1.bias), a.c_attn.weight, a.c_attn.bias, a.c_proj.weight,
                            a.c_proj.bias, *cross, (self.ln_2.weight, self.ln_2.bias), m.c_fc.weight, m.c_fc.bias,
                            m.c_proj.weight, m.c_proj.bias)

    def forward(self, x: torch.Tensor, memory: torch.Tensor | None, cross_mask: torch.Tensor | None = None
                ) -> torch.Tensor:
        """Teacher forcing: x (B, T, d), memory (B, M, d) or None without cross-attention -> (B, T, d) (see
        `block_forward`)."""
        w = self.weights()
        b, n, d = x.shape
        cross = (None, None) if memory is None else cross_kv(w, memory, self.heads)
        out = block_forward(w, x.reshape(b * n, d), b, *cross, cross_mask, self.heads,
                            dropout=self.dropout if self.training else 0.0)
        return out.view(b, n, d)


def cross_kv(w: BlockWeights, memory: torch.Tensor, heads: int) -> tuple[torch.Tensor, torch.Tensor]:
    """memory (B, M, d) -> its cross-attention keys and values for one block, each (B, H, M, dh)."""
    b, _, d = memory.shape
    k, v = torch.addmm(w.cross_kv_b, memory.reshape(-1, d), w.cross_kv_w).split(d, -1)
    return (k.reshape(b, -1, heads, d // heads).transpose(1, 2),
            v.reshape(b, -1, heads, d // heads).transpose(1, 2))


def _ln(x: torch.Tensor, ln: tuple[torch.Tensor, torch.Tensor]) -> torch.Tensor:
    return torch.layer_norm(x, (x.shape[-1],), ln[0], ln[1], LAYER_NORM_EPS)  # F.layer_norm without its checks


def block_forward(w: BlockWeights, x: torch.Tensor, rows: int, cross_k: torch.Tensor, cross_v: torch.Tensor,
                  cross_mask: torch.Tensor | None, heads: int, cache: tuple | None = None, t: int = 0,
                  dropout: float = 0.0) -> torch.Tensor:
    """One block on the residual stream x (B T, d) of ``rows`` = B rows -> (B T, d).

    ``cross_k``, ``cross_v`` (B or 1, H, M, dh): `cross_kv` of the memory (None: no cross-attention); one memory
    row is shared by B > 1 rows when T is 1. ``cross_mask``: additive, broadcast to the attention's (B, H, T, M)
    (or (1, H, B, M) when shared). Without ``cache`` the self-attention is causal over the T positions; with it
    (one token a row, T = 1, at position ``t``) the new keys and values go into the cache ``(kv, keys, values)``
    (``kv`` (2, B, H, L, dh), the others its halves) and the query reads positions 0..t. ``dropout`` on the
    residual branches and the self-attention (training only). The stream stays two-dimensional: a step is a few
    hundred small operations, and every view costs."""
    d = x.shape[1]
    n, dh = x.shape[0] // rows, d // heads
    qkv = torch.addmm(w.attn_b, _ln(x, w.ln_1), w.attn_w)  # (B T, 3d)
    if cache is None:
        q, k, v = qkv.view(rows, n, 3, heads, dh).permute(2, 0, 3, 1, 4)  # 3 x (B, H, T, dh)
        o = F.scaled_dot_product_attention(q, k, v, is_causal=True, dropout_p=dropout)
        o = o.transpose(1, 2).reshape(rows * n, d)
    else:
        qkv = qkv.view(rows, 3, heads, dh)
        kv, keys, values = cache
        kv[:, :, :, t] = qkv[:, 1:].transpose(0, 1)  # (2, B, H, dh) into position t
        o = F.scaled_dot_product_attention(qkv[:, 0, :, None], keys[:, :, : t + 1], values[:, :, : t + 1])
        o = o.reshape(rows, d)  # (B, H, 1, dh) -> (B, d)
    o = torch.addmm(w.attn_proj_b, o, w.attn_proj_w)
    x = x + (F.dropout(o, dropout) if dropout else o)
    if cross_k is None:  # a block without cross-attention (the causal encoder's)
        return _mlp(w, x, dropout)
    q = torch.addmm(w.cross_q_b, _ln(x, w.ln_cross), w.cross_q_w)  # (B T, d)
    if cross_k.shape[0] == 1 and rows > 1 and n == 1:  # (1, H, B, dh): the B rows are B queries on one memory
        o = F.scaled_dot_product_attention(q.view(rows, heads, dh).transpose(0, 1)[None], cross_k, cross_v,
                                           attn_mask=cross_mask)
        o = o[0].transpose(0, 1).reshape(rows, d)
    elif n == 1:  # (B, H, 1, dh)
        o = F.scaled_dot_product_attention(q.view(rows, heads, 1, dh), cross_k, cross_v, attn_mask=cross_mask)
        o = o.reshape(rows, d)
    else:
        o = F.scaled_dot_product_attention(q.view(rows, n, heads, dh).transpose(1, 2), cross_k, cross_v,
                                           attn_mask=cross_mask)  # (B, H, T, dh)
        o = o.transpose(1, 2).reshape(rows * n, d)
    o = torch.addmm(w.cross_proj_b, o, w.cross_proj_w)
    return _mlp(w, x + (F.dropout(o, dropout) if dropout else o), dropout)


def _mlp(w: BlockWeights, x: torch.Tensor, dropout: float) -> torch.Tensor:
    hidden = F.gelu(torch.addmm(w.fc_b, _ln(x, w.ln_2), w.fc_w), approximate="tanh")  # (B T, ffn)
    o = torch.addmm(w.mlp_proj_b, hidden, w.mlp_proj_w)
    return x + (F.dropout(o, dropout) if dropout else o)


class Decoder(nn.Module):
    """Learned positions, the blocks, a final layer norm: embedded tokens (B, T, d) -> hidden states (B, T, d)."""

    def __init__(self, d: int, layers: int, heads: int, ffn: int, max_len: int, dropout: float = 0.0,
                 cross: bool = True):
        super().__init__()
        self.d, self.heads, self.max_len, self.dropout = d, heads, max_len, dropout
        self.wpe = nn.Embedding(max_len, d)
        self.h = nn.ModuleList(Block(d, heads, ffn, dropout, cross) for _ in range(layers))
        self.ln_f = nn.LayerNorm(d, eps=LAYER_NORM_EPS)

    def forward(self, x: torch.Tensor, memory: torch.Tensor | None, cross_mask: torch.Tensor | None = None
                ) -> torch.Tensor:
        """Teacher forcing: x (B, T, d) embedded tokens, memory (B, M, d) (None for blocks without
        cross-attention), cross_mask additive (B, 1 or H, T or 1, M) -> (B, T, d)."""
        if x.shape[1] > self.max_len:
            raise ValueError(f"the decoder holds at most {self.max_len} positions, got {x.shape[1]}")
        x = x + self.wpe.weight[: x.shape[1]]
        if self.dropout and self.training:
            x = F.dropout(x, self.dropout)
        for block in self.h:
            x = block(x, memory, cross_mask)
        return torch.layer_norm(x, (self.d,), self.ln_f.weight, self.ln_f.bias, LAYER_NORM_EPS)


class DecoderState:
    """Token-by-token decoding with a model's decoder: the key/value cache of K rows and the memory they read."""

    def __init__(self, model: nn.Module, memory: torch.Tensor, memory_mask: torch.Tensor, max_len: int,
                 rows: int | None = None, memory_boxes: torch.Tensor | None = None):
        """``model``: a `facaid.model.FacaidModel`. memory (B, M, d) and memory_mask (B, M) bool from
        `model.encode`: one memory row per decoded row, or one memory row shared by ``rows`` decoded rows; with
        ``config.box_bias``, memory_boxes (B, M, 5) (`FacaidModel.memory_boxes`), and `step` takes each row's node
        box."""
        dec = model.decoder
        self.k = rows or memory.shape[0]
        if memory.shape[0] not in (1, self.k):
            raise ValueError(f"memory has {memory.shape[0]} rows; expected 1 or {self.k}")
        self.shared = memory.shape[0] == 1 and self.k > 1  # K rows reading one memory row
        self.heads, self.d = dec.heads, dec.d
        self.dh = self.d // self.heads
        self.eps = LAYER_NORM_EPS
        self.t = 0
        self.max_len = min(max_len, dec.max_len)
        self.mask = None  # (B, 1, 1, M) additive: the smallest float where a memory position is padding
        if not bool(memory_mask.all()):
            self.mask = padding_mask(memory_mask, memory.dtype)
        self.box_scale = model.box_scale
        if self.box_scale is not None:
            if memory_boxes is None:
                raise ValueError("this model biases cross-attention by the node box: pass memory_boxes")
            # `FacaidModel.cross_bias` split into what the memory fixes once and what each step's boxes add
            self.box_terms = model.box_terms(memory_boxes)
            self.scale = self.box_scale.detach().view(1, -1, 1, 1)
            self.last_boxes = self.last_mask = None
        self.box_share = model.box_share
        self.wpe = dec.wpe.weight
        self.ln_f = (dec.ln_f.weight, dec.ln_f.bias)
        self.head = (model.lm_head.weight, model.lm_head.bias)
        self.blocks = [block.weights() for block in dec.h]
        self.cross, self.cache = [], []
        with torch.inference_mode():
            for w in self.blocks:
                self.cross.append(cross_kv(w, memory, self.heads))
                # keys and values in one buffer, so that a step writes both with one copy; and views of each
                kv = memory.new_empty((2, self.k, self.heads, self.max_len, self.dh))
                self.cache.append((kv, kv[0], kv[1]))

    def cross_mask(self, boxes: torch.Tensor | None) -> torch.Tensor | None:
        """The cross-attention mask of this step: the padding, and with the box bias each row's node box (the
        same as `FacaidModel.cross_bias`; kept while the boxes stay, as they do for the tokens of one node)."""
        if self.box_scale is None:
            return self.mask
        if boxes is None:
            raise ValueError("this model biases cross-attention by the node box: pass each row's box")
        if self.last_boxes is not None and (boxes is self.last_boxes or torch.equal(boxes, self.last_boxes)):
            return self.last_mask
        if self.shared:  # (1, H, K, M): the K rows' boxes as K positions of the one memory row
            mask = self.scale * self.box_share(self.box_terms, boxes[None])[:, None]
        else:  # (K, H, 1, M): one position per row
            mask = self.scale * self.box_share(self.box_terms, boxes[:, None])[:, None]
        if self.mask is not None:
            mask = mask + self.mask
        self.last_boxes, self.last_mask = boxes, mask
        return mask

    @torch.inference_mode()
    def step(self, x: torch.Tensor, boxes: torch.Tensor | None = None) -> torch.Tensor:
        """x (K, d): the embedded newest token of each row -> logits (K, V) for the token after it. ``boxes``
        (K, 4): the quantized node box each row's next token belongs to (what `FacaidModel.embed_outputs` got)."""
        if self.t >= self.max_len:
            raise ValueError(f"the decoder holds at most {self.max_len} positions")
        t = self.t
        mask = self.cross_mask(boxes)
        x = x + self.wpe[t]  # (K, d)
        for w, (ck, cv), cache in zip(self.blocks, self.cross, self.cache, strict=True):
            x = block_forward(w, x, self.k, ck, cv, mask, self.heads, cache, t)
        self.t += 1
        return F.linear(torch.layer_norm(x, (self.d,), *self.ln_f, self.eps), *self.head)
