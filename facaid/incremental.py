"""Token-by-token decoding with the decoder's own weights and plain torch operations.

Decoding a facade is a few hundred steps of one token each; at that size the Hugging Face modules' Python
overhead costs more than the arithmetic. `IncrementalDecoder` runs the same GPT-2 blocks (pre-layer-norm
self-attention, cross-attention on the encoder's memory, tanh-GELU MLP, final layer norm) on preallocated
key/value buffers, with the cross-attention keys and values computed once. It gives the logits of
`FacaidModel.decode` with a cache (tested to 1e-5), for inference only.

Best-of-K decodes K rows against one input: given that input's memory once and ``rows=K``, the rows share its
cross-attention keys and values, and a step attends with the K queries of a head in one matrix product
instead of K vector products over K copies of the memory.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F

from facaid.model import FacaidModel


class IncrementalDecoder:
    def __init__(self, model: FacaidModel, memory: torch.Tensor, memory_mask: torch.Tensor, max_len: int,
                 rows: int | None = None):
        """memory (B, M, d) and memory_mask (B, M) bool from `model.encode`: one memory row per decoded row, or
        one memory row shared by ``rows`` decoded rows."""
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
        self.mask = None if bool(memory_mask.all()) else memory_mask[:, None, None, :]
        # the weights as plain tensors: a module attribute lookup per step costs more than the small matrices
        self.wpe = dec.wpe.weight
        self.ln_f = (dec.ln_f.weight, dec.ln_f.bias)
        self.head = (model.lm_head.weight, model.lm_head.bias)
        self.blocks, self.cross, self.cache = [], [], []
        b = memory.shape[0]
        with torch.no_grad():
            for block in dec.h:
                a, c, m = block.attn, block.crossattention, block.mlp
                self.blocks.append((
                    (block.ln_1.weight, block.ln_1.bias), a.c_attn.weight, a.c_attn.bias, a.c_proj.weight,
                    a.c_proj.bias, (block.ln_cross_attn.weight, block.ln_cross_attn.bias), c.q_attn.weight,
                    c.q_attn.bias, c.c_proj.weight, c.c_proj.bias, (block.ln_2.weight, block.ln_2.bias),
                    m.c_fc.weight, m.c_fc.bias, m.c_proj.weight, m.c_proj.bias))
                ck, cv = torch.addmm(c.c_attn.bias, memory.reshape(-1, self.d), c.c_attn.weight).split(self.d, -1)
                self.cross.append((self._heads(ck.reshape(b, -1, self.d)), self._heads(cv.reshape(b, -1, self.d))))
                shape = (self.k, self.heads, self.max_len, self.dh)
                self.cache.append((memory.new_empty(shape), memory.new_empty(shape)))

    def _heads(self, x: torch.Tensor) -> torch.Tensor:  # (B, T, d) -> (B, H, T, dh)
        return x.view(x.shape[0], -1, self.heads, self.dh).transpose(1, 2)

    def _ln(self, x: torch.Tensor, ln: tuple[torch.Tensor, torch.Tensor]) -> torch.Tensor:
        return F.layer_norm(x, (self.d,), ln[0], ln[1], self.eps)

    def _cross(self, q: torch.Tensor, ck: torch.Tensor, cv: torch.Tensor) -> torch.Tensor:
        """q (K, d) -> the cross-attention output (K, d)."""
        k, heads, dh = self.k, self.heads, self.dh
        if self.shared:  # (1, H, K, dh): the K rows are K queries on the one memory
            o = F.scaled_dot_product_attention(q.view(k, heads, dh).transpose(0, 1)[None], ck, cv,
                                               attn_mask=self.mask)
            return o[0].transpose(0, 1).reshape(k, self.d)
        o = F.scaled_dot_product_attention(q.view(k, heads, 1, dh), ck, cv, attn_mask=self.mask)
        return o.reshape(k, self.d)

    @torch.no_grad()
    def step(self, x: torch.Tensor) -> torch.Tensor:
        """x (K, d): the embedded newest token of each row -> logits (K, V) for the token after it."""
        if self.t >= self.max_len:
            raise ValueError(f"the decoder holds at most {self.max_len} positions")
        t = self.t
        k, heads, dh = self.k, self.heads, self.dh
        x = x + self.wpe[t]
        for (ln1, aw, ab, pw, pb, lnc, qw, qb, cw, cb, ln2, fw, fb, mw, mb), (ck, cv), (kc, vc) in zip(
                self.blocks, self.cross, self.cache, strict=True):
            q, key, value = torch.addmm(ab, self._ln(x, ln1), aw).split(self.d, -1)
            kc[:, :, t] = key.view(k, heads, dh)
            vc[:, :, t] = value.view(k, heads, dh)
            o = F.scaled_dot_product_attention(q.view(k, heads, 1, dh), kc[:, :, : t + 1], vc[:, :, : t + 1])
            x = x + torch.addmm(pb, o.reshape(k, self.d), pw)
            q = torch.addmm(qb, self._ln(x, lnc), qw)
            x = x + torch.addmm(cb, self._cross(q, ck, cv), cw)
            hidden = F.gelu(torch.addmm(fb, self._ln(x, ln2), fw), approximate="tanh")
            x = x + torch.addmm(mb, hidden, mw)
        self.t += 1
        return F.linear(self._ln(x, self.ln_f), *self.head)
