"""The encoder over the rectangle rows, written here as the decoder is (`facaid.model.decoder`), in plain torch.

Two kinds (`FacaidConfig.encoder`): ``"bidirectional"``, a BERT-style stack (learned positions and a type
embedding summed with the input and normalized; each layer post-layer-norm self-attention over all positions
and an exact-GELU MLP), which the shipped model uses; and ``"causal"``, as in the paper, GPT-2-style: the
decoder's blocks without cross-attention, each position reading those before it. Parameter names are those of
Hugging Face's ``BertModel`` and ``GPT2Model``, so the checkpoints trained with them load unchanged.

Shapes: B rows, N positions (rectangle tokens), d channels, H heads of dh = d / H.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import nn

from facaid.model.decoder import Decoder, padding_mask

BERT_LAYER_NORM_EPS = 1e-12  # BERT's


class BertEmbeddings(nn.Module):
    def __init__(self, d: int, max_len: int, dropout: float):
        super().__init__()
        self.position_embeddings = nn.Embedding(max_len, d)
        self.token_type_embeddings = nn.Embedding(1, d)
        self.LayerNorm = nn.LayerNorm(d, eps=BERT_LAYER_NORM_EPS)
        self.dropout = dropout

    def forward(self, x: torch.Tensor) -> torch.Tensor:  # (B, N, d) -> (B, N, d)
        x = x + self.token_type_embeddings.weight[0] + self.position_embeddings.weight[: x.shape[1]]
        return F.dropout(self.LayerNorm(x), self.dropout, self.training)


class _Projections(nn.Module):
    def __init__(self, d: int):
        super().__init__()
        self.query, self.key, self.value = nn.Linear(d, d), nn.Linear(d, d), nn.Linear(d, d)


class _Sum(nn.Module):
    """A projection added to the residual and normalized: ``LayerNorm(x + dense(h))``."""

    def __init__(self, n_in: int, d: int):
        super().__init__()
        self.dense = nn.Linear(n_in, d)
        self.LayerNorm = nn.LayerNorm(d, eps=BERT_LAYER_NORM_EPS)


class _Attention(nn.Module):
    def __init__(self, d: int):
        super().__init__()
        self.self = _Projections(d)  # BERT's name for them
        self.output = _Sum(d, d)


class _Intermediate(nn.Module):
    def __init__(self, d: int, ffn: int):
        super().__init__()
        self.dense = nn.Linear(d, ffn)


class BertLayer(nn.Module):
    def __init__(self, d: int, heads: int, ffn: int, dropout: float):
        super().__init__()
        self.heads, self.dropout = heads, dropout
        self.attention = _Attention(d)
        self.intermediate = _Intermediate(d, ffn)
        self.output = _Sum(ffn, d)

    def forward(self, x: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """x (B, N, d), mask additive (B, 1, 1, N) -> (B, N, d)."""
        b, n, d = x.shape
        p, dh, drop = self.attention.self, d // self.heads, self.dropout if self.training else 0.0

        def heads(t: torch.Tensor) -> torch.Tensor:  # (B, N, d) -> (B, H, N, dh)
            return t.view(b, n, self.heads, dh).transpose(1, 2)

        o = F.scaled_dot_product_attention(heads(p.query(x)), heads(p.key(x)), heads(p.value(x)), attn_mask=mask,
                                           dropout_p=drop)
        o = o.transpose(1, 2).reshape(b, n, d)
        a = self.attention.output
        x = a.LayerNorm(x + F.dropout(a.dense(o), drop, self.training))
        h = F.gelu(self.intermediate.dense(x))  # exact (erf) GELU, as BERT
        return self.output.LayerNorm(x + F.dropout(self.output.dense(h), drop, self.training))


class _Layers(nn.Module):
    def __init__(self, layers: list[BertLayer]):
        super().__init__()
        self.layer = nn.ModuleList(layers)


class BidirectionalEncoder(nn.Module):
    """BERT-style: every position reads every other real one."""

    def __init__(self, d: int, layers: int, heads: int, ffn: int, max_len: int, dropout: float = 0.0):
        super().__init__()
        self.embeddings = BertEmbeddings(d, max_len, dropout)
        self.encoder = _Layers([BertLayer(d, heads, ffn, dropout) for _ in range(layers)])

    def forward(self, x: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """x (B, N, d) embedded rows, mask (B, N) bool -> (B, N, d)."""
        x = self.embeddings(x)
        additive = padding_mask(mask, x.dtype)
        for layer in self.encoder.layer:
            x = layer(x, additive)
        return x


class CausalEncoder(Decoder):
    """GPT-2-style, as in the paper: the decoder's blocks without cross-attention, each position reading itself and
    those before it (padding comes last, so no real position reads it)."""

    def __init__(self, d: int, layers: int, heads: int, ffn: int, max_len: int, dropout: float = 0.0):
        super().__init__(d, layers, heads, ffn, max_len, dropout, cross=False)

    def forward(self, x: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """x (B, N, d) embedded rows, mask (B, N) bool (unused: see the class) -> (B, N, d)."""
        return super().forward(x, None)
