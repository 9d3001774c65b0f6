"""Token-by-token decoding with the decoder's own weights and plain torch operations.

Decoding a facade is a few hundred steps of one token each; at that size the Hugging Face modules' Python
overhead costs more than the arithmetic. `IncrementalDecoder` runs the same GPT-2 blocks (pre-layer-norm
self-attention, cross-attention on the encoder's memory, tanh-GELU MLP, final layer norm) on preallocated
key/value buffers, with the cross-attention keys and values computed once. It gives the logits of
`FacaidModel.decode` with a cache (tested to 1e-5), for inference only.

Best-of-K decodes K rows against one input: given that input's memory once and ``rows=K``, the rows share its
cross-attention keys and values, and a step attends with the K queries of a head in one matrix product
instead of K vector products over K copies of the memory.

With the box bias (`FacaidConfig.box_bias`) each step also gets each row's node box and adds the same
cross-attention bias as `FacaidModel.cross_bias`, computed once per node rather than once per token.
"""

from __future__ import annotations

from typing import NamedTuple

import torch
import torch.nn.functional as F

from facaid.model import FacaidModel


class _Block(NamedTuple):
    """One GPT-2 block's weights as plain tensors (a module attribute lookup per step costs more than the small
    matrices); Conv1D weights are (in, out), for ``torch.addmm(bias, x, weight)``."""

    ln_1: tuple[torch.Tensor, torch.Tensor]
    attn_w: torch.Tensor
    attn_b: torch.Tensor
    attn_proj_w: torch.Tensor
    attn_proj_b: torch.Tensor
    ln_cross: tuple[torch.Tensor, torch.Tensor]
    cross_q_w: torch.Tensor
    cross_q_b: torch.Tensor
    cross_proj_w: torch.Tensor
    cross_proj_b: torch.Tensor
    ln_2: tuple[torch.Tensor, torch.Tensor]
    fc_w: torch.Tensor
    fc_b: torch.Tensor
    mlp_proj_w: torch.Tensor
    mlp_proj_b: torch.Tensor

    @classmethod
    def of(cls, block) -> _Block:
        a, c, m = block.attn, block.crossattention, block.mlp
        return cls(ln_1=(block.ln_1.weight, block.ln_1.bias), attn_w=a.c_attn.weight, attn_b=a.c_attn.bias,
                   attn_proj_w=a.c_proj.weight, attn_proj_b=a.c_proj.bias,
                   ln_cross=(block.ln_cross_attn.weight, block.ln_cross_attn.bias), cross_q_w=c.q_attn.weight,
                   cross_q_b=c.q_attn.bias, cross_proj_w=c.c_proj.weight, cross_proj_b=c.c_proj.bias,
                   ln_2=(block.ln_2.weight, block.ln_2.bias), fc_w=m.c_fc.weight, fc_b=m.c_fc.bias,
                   mlp_proj_w=m.c_proj.weight, mlp_proj_b=m.c_proj.bias)


class IncrementalDecoder:
    def __init__(self, model: FacaidModel, memory: torch.Tensor, memory_mask: torch.Tensor, max_len: int,
                 rows: int | None = None, memory_boxes: torch.Tensor | None = None):
        """memory (B, M, d) and memory_mask (B, M) bool from `model.encode`: one memory row per decoded row, or
        one memory row shared by ``rows`` decoded rows; with ``config.box_bias``, memory_boxes (B, M, 5)
        (`FacaidModel.memory_boxes`), and `step` takes each row's node box."""
        dec = model.decoder
        cfg = dec.config
        if cfg.activation_function not in ("gelu_new", "gelu_pytorch_tanh"):
            raise ValueError(f"unsupported activation {cfg.activation_function}")
        self.k = rows or memory.shape[0]
        if memory.shape[0] not in (1, self.k):
            raise ValueError(f"memory has {memory.shape[0]} rows; expected 1 or {self.k}")
        self.shared = memory.shape[0] == 1 and self.k > 1
        self.heads, self.d = cfg.n_head, cfg.n_embd
        self.dh = self.d // self.heads
        self.eps = cfg.layer_norm_epsilon
        self.t = 0
        self.max_len = min(max_len, cfg.n_positions)
        self.mask = None  # (B, 1, 1, M) additive: the smallest float where a memory position is padding
        if not bool(memory_mask.all()):
            self.mask = memory.new_zeros(memory_mask.shape).masked_fill(
                ~memory_mask, torch.finfo(memory.dtype).min)[:, None, None, :]
        self.box_scale = model.box_scale
        if self.box_scale is not None:
            if memory_boxes is None:
                raise ValueError("this model biases cross-attention by the node box: pass memory_boxes")
            # `FacaidModel.cross_bias` split into what the memory fixes once and what each step's boxes add
            self.box_terms = model.box_terms(memory_boxes)
            self.scale = self.box_scale.detach().view(1, -1, 1, 1)
            self.last_boxes = self.last_mask = None
        self.wpe = dec.wpe.weight
        self.ln_f = (dec.ln_f.weight, dec.ln_f.bias)
        self.head = (model.lm_head.weight, model.lm_head.bias)
        self.blocks, self.cross, self.cache = [], [], []
        b = memory.shape[0]
        with torch.inference_mode():
            for block in dec.h:
                self.blocks.append(_Block.of(block))
                c = block.crossattention
                ck, cv = torch.addmm(c.c_attn.bias, memory.reshape(-1, self.d), c.c_attn.weight).split(self.d, -1)
                self.cross.append((self._heads(ck.reshape(b, -1, self.d)), self._heads(cv.reshape(b, -1, self.d))))
                # keys and values in one buffer, so that a step writes both with one copy; and views of each
                kv = memory.new_empty((2, self.k, self.heads, self.max_len, self.dh))
                self.cache.append((kv, kv[0], kv[1]))

    def _heads(self, x: torch.Tensor) -> torch.Tensor:  # (B, T, d) -> (B, H, T, dh)
        return x.view(x.shape[0], -1, self.heads, self.dh).transpose(1, 2)

    def _ln(self, x: torch.Tensor, ln: tuple[torch.Tensor, torch.Tensor]) -> torch.Tensor:
        return torch.layer_norm(x, (self.d,), ln[0], ln[1], self.eps)  # F.layer_norm's kernel, without its checks

    def _cross(self, q: torch.Tensor, ck: torch.Tensor, cv: torch.Tensor, mask: torch.Tensor | None) -> torch.Tensor:
        """q (K, d) -> the cross-attention output (K, d)."""
        k, heads, dh = self.k, self.heads, self.dh
        if self.shared:  # (1, H, K, dh): the K rows are K queries on the one memory
            o = F.scaled_dot_product_attention(q.view(k, heads, dh).transpose(0, 1)[None], ck, cv, attn_mask=mask)
            return o[0].transpose(0, 1).reshape(k, self.d)
        o = F.scaled_dot_product_attention(q.view(k, heads, 1, dh), ck, cv, attn_mask=mask)
        return o.reshape(k, self.d)

    def _cross_mask(self, boxes: torch.Tensor | None) -> torch.Tensor | None:
        """The cross-attention mask of this step: the padding, and with the box bias each row's node box (the
        same as `FacaidModel.cross_bias`; kept while the boxes stay, as they do for the tokens of one node)."""
        if self.box_scale is None:
            return self.mask
        if boxes is None:
            raise ValueError("this model biases cross-attention by the node box: pass each row's box")
        if self.last_boxes is not None and (boxes is self.last_boxes or torch.equal(boxes, self.last_boxes)):
            return self.last_mask
        if self.shared:  # (1, H, K, M): the K rows' boxes as K positions of the one memory row
            mask = self.scale * FacaidModel.box_share(self.box_terms, boxes[None])[:, None]
        else:  # (K, H, 1, M): one position per row
            mask = self.scale * FacaidModel.box_share(self.box_terms, boxes[:, None])[:, None]
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
        k, heads, dh = self.k, self.heads, self.dh
        mask = self._cross_mask(boxes)
        x = x + self.wpe[t]
        for w, (ck, cv), (kv, kc, vc) in zip(self.blocks, self.cross, self.cache, strict=True):
            qkv = torch.addmm(w.attn_b, self._ln(x, w.ln_1), w.attn_w).view(k, 3, heads, dh)
            kv[:, :, :, t] = qkv[:, 1:].transpose(0, 1)
            o = F.scaled_dot_product_attention(qkv[:, 0, :, None], kc[:, :, : t + 1], vc[:, :, : t + 1])
            x = x + torch.addmm(w.attn_proj_b, o.reshape(k, self.d), w.attn_proj_w)
            q = torch.addmm(w.cross_q_b, self._ln(x, w.ln_cross), w.cross_q_w)
            x = x + torch.addmm(w.cross_proj_b, self._cross(q, ck, cv, mask), w.cross_proj_w)
            hidden = F.gelu(torch.addmm(w.fc_b, self._ln(x, w.ln_2), w.fc_w), approximate="tanh")
            x = x + torch.addmm(w.mlp_proj_b, hidden, w.mlp_proj_w)
        self.t += 1
        return F.linear(self._ln(x, self.ln_f), *self.head)
