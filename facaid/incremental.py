"""Token-by-token decoding with the decoder's own weights and plain torch operations.

Decoding a facade is a few hundred steps of one token each; at that size the Hugging Face modules' Python
overhead costs more than the arithmetic. `IncrementalDecoder` runs the same GPT-2 blocks (pre-layer-norm
self-attention, cross-attention on the encoder's memory, tanh-GELU MLP, final layer norm) on preallocated
key/value buffers, with the cross-attention keys and values computed once. It gives the logits of
`FacaidModel.decode` with a cache (tested to 1e-5), for inference only.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F

from facaid.model import FacaidModel


class IncrementalDecoder:
    def __init__(self, model: FacaidModel, memory: torch.Tensor, memory_mask: torch.Tensor, max_len: int):
        """memory (K, M, d) and memory_mask (K, M) bool from `model.encode` (rows may repeat one input)."""
        dec = model.decoder
        cfg = dec.config
        if cfg.activation_function not in ("gelu_new", "gelu_pytorch_tanh"):
            raise ValueError(f"unsupported activation {cfg.activation_function}")
        self.model = model
        self.dec = dec
        self.k = memory.shape[0]
        self.heads, self.d = cfg.n_head, cfg.n_embd
        self.dh = self.d // self.heads
        self.eps = cfg.layer_norm_epsilon
        self.t = 0
        self.max_len = min(max_len, cfg.n_positions)
        self.mask = None if bool(memory_mask.all()) else memory_mask[:, None, None, :]
        self.cross, self.cache = [], []
        with torch.no_grad():
            for block in dec.h:
                ca = block.crossattention
                ck, cv = torch.addmm(ca.c_attn.bias, memory.reshape(-1, self.d), ca.c_attn.weight).split(self.d, -1)
                self.cross.append((self._heads(ck.reshape(self.k, -1, self.d)),
                                   self._heads(cv.reshape(self.k, -1, self.d))))
                shape = (self.k, self.heads, self.max_len, self.dh)
                self.cache.append((memory.new_empty(shape), memory.new_empty(shape)))

    def _heads(self, x: torch.Tensor) -> torch.Tensor:  # (K, T, d) -> (K, H, T, dh)
        return x.view(self.k, -1, self.heads, self.dh).transpose(1, 2)

    def _ln(self, x: torch.Tensor, ln) -> torch.Tensor:
        return F.layer_norm(x, (self.d,), ln.weight, ln.bias, self.eps)

    @torch.no_grad()
    def step(self, x: torch.Tensor) -> torch.Tensor:
        """x (K, d): the embedded newest token of each row -> logits (K, V) for the token after it."""
        if self.t >= self.max_len:
            raise ValueError(f"the decoder holds at most {self.max_len} positions")
        t = self.t
        k, heads, dh = self.k, self.heads, self.dh
        x = x + self.dec.wpe.weight[t]
        for block, (ck, cv), (kc, vc) in zip(self.dec.h, self.cross, self.cache, strict=True):
            a = block.attn
            q, key, value = torch.addmm(a.c_attn.bias, self._ln(x, block.ln_1), a.c_attn.weight).split(self.d, -1)
            kc[:, :, t] = key.view(k, heads, dh)
            vc[:, :, t] = value.view(k, heads, dh)
            o = F.scaled_dot_product_attention(q.view(k, heads, 1, dh), kc[:, :, : t + 1], vc[:, :, : t + 1])
            x = x + torch.addmm(a.c_proj.bias, o.reshape(k, self.d), a.c_proj.weight)
            c = block.crossattention
            q = torch.addmm(c.q_attn.bias, self._ln(x, block.ln_cross_attn), c.q_attn.weight)
            o = F.scaled_dot_product_attention(q.view(k, heads, 1, dh), ck, cv, attn_mask=self.mask)
            x = x + torch.addmm(c.c_proj.bias, o.reshape(k, self.d), c.c_proj.weight)
            m = block.mlp
            hidden = F.gelu(torch.addmm(m.c_fc.bias, self._ln(x, block.ln_2), m.c_fc.weight), approximate="tanh")
            x = x + torch.addmm(m.c_proj.bias, hidden, m.c_proj.weight)
        self.t += 1
        return self.model.lm_head(self._ln(x, self.dec.ln_f))
