"""The encoder-decoder transformer: flattened segmentation rows in, procedure tokens out.

An encoder over the rectangle rows (`facaid.model.encoder`: bidirectional, BERT-style, or causal as in the paper:
``FacaidConfig.encoder``) and a GPT-2-style decoder with cross-attention (`facaid.model.decoder`, written once for
training and decoding), both in plain torch. They take our own embeddings: the five fields of a rectangle are
embedded separately and summed (one token per rectangle) or laid out as five tokens with a field index; output
tokens add the embedding of their local index within their node group and of their node's box. `FacaidModel` is
a Hugging Face `PreTrainedModel`: `save_pretrained` writes config.json and model.safetensors, `from_pretrained`
reads them; the checkpoint also holds the tokenizer and the grammar version.
"""

from __future__ import annotations

from pathlib import Path

import torch
import torch.nn.functional as F
from torch import nn
from transformers import PretrainedConfig, PreTrainedModel

from facaid.grammar.procedure import GRAMMAR_VERSION
from facaid.model.decoder import Conv1D, Decoder, padding_mask
from facaid.model.encoder import BidirectionalEncoder, CausalEncoder
from facaid.tokenizer import PAD, Tokenizer, TokenizerConfig

MAX_LOCAL = 72  # rule, role, count, up to 64 sizes, end


class FacaidConfig(PretrainedConfig):
    model_type = "facaid"

    def __init__(self, d_model: int = 128, encoder_layers: int = 3, decoder_layers: int = 3, heads: int = 4,
                 ffn: int = 512, dropout: float = 0.0, encoder: str = "bidirectional", node_boxes: bool = False,
                 box_bias: bool = False, tokenizer: dict | None = None, grammar: str = GRAMMAR_VERSION, **kwargs):
        super().__init__(**kwargs)
        if encoder not in ("bidirectional", "causal"):
            raise ValueError(f"encoder must be 'bidirectional' (BERT) or 'causal' (GPT-2), got {encoder!r}")
        self.encoder = encoder
        self.node_boxes = node_boxes  # the decoder also sees the box of the node it is writing
        if box_bias and not node_boxes:
            raise ValueError("box_bias needs node_boxes: the bias is the share of each rectangle inside the node box")
        self.box_bias = box_bias  # cross-attention leans, per head, towards the rectangles inside that box
        self.d_model = d_model
        self.encoder_layers = encoder_layers
        self.decoder_layers = decoder_layers
        self.heads = heads
        self.ffn = ffn
        self.dropout = dropout
        self.tokenizer = tokenizer if tokenizer is not None else TokenizerConfig().to_dict()
        self.grammar = grammar

    @property
    def tokenizer_config(self) -> TokenizerConfig:
        return TokenizerConfig(**self.tokenizer)


class FacaidModel(PreTrainedModel):
    config_class = FacaidConfig
    base_model_prefix = "facaid"
    main_input_name = "rects"
    # the token embeddings of the Hugging Face modules the shipped weights were trained with, never read (our own
    # embeddings go in as ``inputs_embeds``)
    _keys_to_ignore_on_load_unexpected = [r"^decoder\.wte\.weight$", r"^encoder\.wte\.weight$",
                                          r"^encoder\.embeddings\.word_embeddings\.weight$"]

    def __init__(self, config: FacaidConfig):
        super().__init__(config)
        tok = Tokenizer(config.tokenizer_config)
        tc = config.tokenizer_config
        d = config.d_model
        self.rect_tokens = tc.rect_tokens
        self.node_boxes = config.node_boxes  # read per decoded token: an attribute costs less than the config's
        sizes = tok.input_vocab_sizes
        self.fields = nn.ModuleList(nn.Embedding(n, d) for n in sizes[:5])  # label, x, y, w, h (and node boxes)
        # the peer counts of `facaid.tokenizer.peer_counts`, zero at first: a model widened with them
        # (`widen_for_counts`) starts out computing what it computed without them
        self.count_fields = nn.ModuleList(nn.Embedding(n, d) for n in sizes[5:])
        self.field_index = nn.Embedding(5, d)
        max_input = (tc.max_rects + 1) * tc.rect_tokens
        kind = BidirectionalEncoder if config.encoder == "bidirectional" else CausalEncoder  # causal: the paper's
        self.encoder = kind(d, config.encoder_layers, config.heads, config.ffn, max_input, config.dropout)
        self.token_embedding = nn.Embedding(len(tok.vocab), d)
        self.local_embedding = nn.Embedding(MAX_LOCAL, d)
        self.decoder = Decoder(d, config.decoder_layers, config.heads, config.ffn, tc.max_out, config.dropout)
        self.lm_head = nn.Linear(d, len(tok.vocab), bias=False)
        # per head, the cross-attention logit added per unit of a rectangle's share inside the node box; zero at
        # first, so that a model given it (`with_box_bias`) computes what it computed without it
        self.box_scale = nn.Parameter(torch.zeros(config.heads)) if config.box_bias else None
        self.post_init()
        for emb in self.count_fields:
            nn.init.zeros_(emb.weight)
        if self.box_scale is not None:
            nn.init.zeros_(self.box_scale)

    def _init_weights(self, module: nn.Module) -> None:
        if isinstance(module, Conv1D):
            nn.init.normal_(module.weight, std=0.02)
            nn.init.zeros_(module.bias)
        elif isinstance(module, nn.Linear):
            nn.init.normal_(module.weight, std=0.02)
            if module.bias is not None:
                nn.init.zeros_(module.bias)
        elif isinstance(module, nn.Embedding):
            nn.init.normal_(module.weight, std=0.02)
        elif isinstance(module, nn.LayerNorm):
            nn.init.ones_(module.weight)
            nn.init.zeros_(module.bias)

    def encode(self, rects: torch.Tensor, rect_mask: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """rects (B, N, F) int, rect_mask (B, N) bool -> memory (B, M, d) and its mask (B, M)."""
        if rects.shape[-1] != 5 + len(self.count_fields):
            raise ValueError(f"this model reads {5 + len(self.count_fields)} fields per rectangle, got "
                             f"{rects.shape[-1]}: encode the input with the checkpoint's tokenizer")
        embs = [emb(rects[..., f]) for f, emb in enumerate(self.fields)]  # 5 x (B, N, d)
        if self.rect_tokens == 1:
            embs += [emb(rects[..., 5 + f]) for f, emb in enumerate(self.count_fields)]
            x = torch.stack(embs, 0).sum(0)  # (B, N, d)
            mask = rect_mask
        else:
            b, n = rects.shape[:2]
            x = torch.stack(embs, 2) + self.field_index.weight  # (B, N, 5, d)
            x = x.reshape(b, n * 5, -1)  # (B, 5N, d)
            mask = rect_mask.repeat_interleave(5, dim=1)  # (B, 5N)
        h = self.encoder(x, mask)  # (B, M, d)
        return h, mask

    def embed_outputs(self, ids: torch.Tensor, local: torch.Tensor, boxes: torch.Tensor | None = None,
                      box_embedding: torch.Tensor | None = None) -> torch.Tensor:
        """The decoder's input embeddings (B, T, d) of output tokens, their local indices and node boxes
        (``box_embedding``: `embed_boxes` of the boxes, when already computed)."""
        # the tables through F.embedding rather than the modules: decoding embeds one token at a time, where a
        # module call's overhead costs more than the lookup
        x = F.embedding(ids, self.token_embedding.weight) + F.embedding(local, self.local_embedding.weight)
        if self.node_boxes:
            if box_embedding is None:
                if boxes is None:
                    raise ValueError("this model reads node boxes: pass boxes (B, T, 4) to decode")
                box_embedding = self.embed_boxes(boxes)
            x = x + box_embedding
        return x

    def embed_boxes(self, boxes: torch.Tensor) -> torch.Tensor:
        """The node boxes' part of `embed_outputs`: (..., 4) quantized x, y, w, h -> (..., d), embedded with the
        input rectangles' tables. Decoding reuses it for all the tokens of a node."""
        f = self.fields  # by index: a slice of a ModuleList builds a new ModuleList
        x, y, w, h = f[1].weight, f[2].weight, f[3].weight, f[4].weight
        return (F.embedding(boxes[..., 0], x) + F.embedding(boxes[..., 1], y) + F.embedding(boxes[..., 2], w)
                + F.embedding(boxes[..., 3], h))

    def memory_boxes(self, rects: torch.Tensor) -> torch.Tensor:
        """(B, N, F) encoded rectangles -> (B, M, 5) float (x0, y0, x1, y1, is a rectangle) per memory position, in
        the quantized coordinates of the node boxes; the image row is not a rectangle."""
        q = rects[..., 1:5].float()
        real = (rects[..., 0] < self.fields[0].num_embeddings - 1).float()  # the image row has label len(LABELS)
        out = torch.stack([q[..., 0], q[..., 1], q[..., 0] + q[..., 2], q[..., 1] + q[..., 3], real], -1)
        return out if self.rect_tokens == 1 else out.repeat_interleave(5, dim=1)

    @staticmethod
    def box_terms(memory_boxes: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """What `box_share` needs of the memory, fixed for a whole decode: (lo, hi) corners (B, M, 2) and the
        weight (B, M) that turns an overlap area into a share (zero for the image row)."""
        mb = memory_boxes.float()
        lo, hi = mb[..., 0:2], mb[..., 2:4]
        return lo, hi, mb[..., 4] / (hi - lo).prod(-1).clamp(min=1)

    @staticmethod
    def box_share(terms: tuple[torch.Tensor, torch.Tensor, torch.Tensor], boxes: torch.Tensor) -> torch.Tensor:
        """Each memory rectangle's share of area inside each node box: boxes (B, T, 4) quantized x, y, w, h
        (all zero where there is no node) and `box_terms` of (B or 1, M) -> (B, T, M)."""
        lo, hi, weight = (t[:, None] for t in terms)  # (B, 1, M, ...)
        b = boxes.float()[:, :, None]  # (B, T, 1, 4)
        inter = (torch.minimum(hi, b[..., 0:2] + b[..., 2:4]) - torch.maximum(lo, b[..., 0:2])).clamp(min=0)
        return inter[..., 0] * inter[..., 1] * weight

    def cross_bias(self, memory_boxes: torch.Tensor, memory_mask: torch.Tensor, boxes: torch.Tensor) -> torch.Tensor:
        """The additive cross-attention mask (B, H, T, M): per head, ``box_scale`` times `box_share` at each
        position, and the padding masked out. A row of zero boxes gets the same bias everywhere, which changes
        nothing."""
        share = self.box_share(self.box_terms(memory_boxes), boxes)  # (B, T, M)
        bias = self.box_scale.view(1, -1, 1, 1) * share[:, None]  # (B, H, T, M)
        masked = torch.finfo(bias.dtype).min
        return bias.masked_fill(~memory_mask[:, None, None, :], masked)

    def decode(self, ids: torch.Tensor, local: torch.Tensor, memory: torch.Tensor, memory_mask: torch.Tensor,
               boxes: torch.Tensor | None = None, memory_boxes: torch.Tensor | None = None) -> torch.Tensor:
        """Teacher forcing: ids, local (B, T) and, with ``config.node_boxes``, boxes (B, T, 4) -> logits (B, T, V).

        ``boxes`` hold at each position the quantized (x, y, w, h) of the node the next token belongs to
        (`Tokenizer.node_boxes`); they are embedded with the same tables as the input rectangles. With
        ``config.box_bias`` the cross-attention also leans towards the rectangles inside them: pass
        ``memory_boxes`` (`memory_boxes` of the encoded rectangles). Token-by-token decoding runs the same blocks
        through `facaid.model.decoder.DecoderState`."""
        x = self.embed_outputs(ids, local, boxes)  # (B, T, d)
        if self.box_scale is not None:
            if memory_boxes is None:
                raise ValueError("this model biases cross-attention by the node box: pass memory_boxes")
            mask = self.cross_bias(memory_boxes, memory_mask, boxes).to(x.dtype)  # (B, H, T, M)
        else:
            mask = padding_mask(memory_mask, x.dtype)  # (B, 1, 1, M)
        return self.lm_head(self.decoder(x, memory, mask))  # (B, T, V)

    def forward(self, rects: torch.Tensor, rect_mask: torch.Tensor, ids: torch.Tensor, local: torch.Tensor,
                targets: torch.Tensor | None = None, boxes: torch.Tensor | None = None
                ) -> tuple[torch.Tensor, torch.Tensor | None]:
        """Teacher-forced logits (B, T, V) and, given targets (B, T) with -100 for ignored, the mean loss."""
        memory, memory_mask = self.encode(rects, rect_mask)
        memory_boxes = self.memory_boxes(rects) if self.box_scale is not None else None
        logits = self.decode(ids, local, memory, memory_mask, boxes=boxes, memory_boxes=memory_boxes)
        loss = None
        if targets is not None:
            loss = F.cross_entropy(logits.reshape(-1, logits.shape[-1]), targets.reshape(-1), ignore_index=-100)
        return logits, loss


def load_model(path: str | Path, device: str | torch.device = "cpu") -> tuple[FacaidModel, Tokenizer]:
    """Load a checkpoint directory; fail clearly if it was made for another grammar version."""
    path = Path(path)
    if not (path / "config.json").is_file():
        raise FileNotFoundError(f"no checkpoint at {path} (config.json missing)")
    config = FacaidConfig.from_pretrained(path)
    if config.grammar != GRAMMAR_VERSION:
        raise ValueError(f"checkpoint {path} was trained for grammar {config.grammar!r}; this build runs "
                         f"{GRAMMAR_VERSION!r}")
    tokenizer = Tokenizer.load(path / "tokenizer.json")
    if tokenizer.config != config.tokenizer_config:
        raise ValueError(f"checkpoint {path}: tokenizer.json does not match config.json")
    model = FacaidModel.from_pretrained(path, config=config).to(device)
    model.eval()
    return model, tokenizer


def save_model(model: FacaidModel, tokenizer: Tokenizer, path: str | Path) -> None:
    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    model.save_pretrained(path, safe_serialization=True)
    tokenizer.save(path / "tokenizer.json")


def batch_inputs(rows: list, device: str | torch.device = "cpu") -> tuple[torch.Tensor, torch.Tensor]:
    """Pad encoded segmentations (each (N_i, F)) into rects (B, N, F) and rect_mask (B, N)."""
    n = max(len(r) for r in rows)
    rects = torch.zeros(len(rows), n, len(rows[0][0]), dtype=torch.long)
    mask = torch.zeros(len(rows), n, dtype=torch.bool)
    for i, r in enumerate(rows):
        rects[i, : len(r)] = torch.as_tensor(r)
        mask[i, : len(r)] = True
    return rects.to(device), mask.to(device)


def batch_outputs(seqs: list[tuple], device: str | torch.device = "cpu"
                  ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    """Teacher forcing: (ids, local, targets) each (B, T) and boxes (B, T, 4) from (ids, local[, boxes])
    tuples with BOS ... EOS; boxes (`Tokenizer.node_boxes`) are zeros where a tuple has none."""
    t = max(len(s[0]) for s in seqs) - 1
    ids = torch.full((len(seqs), t), PAD, dtype=torch.long)
    local = torch.zeros(len(seqs), t, dtype=torch.long)
    targets = torch.full((len(seqs), t), -100, dtype=torch.long)
    boxes = torch.zeros(len(seqs), t, 4, dtype=torch.long)
    for i, (seq, loc, *rest) in enumerate(seqs):
        n = len(seq) - 1
        ids[i, :n] = torch.as_tensor(seq[:-1])
        local[i, :n] = torch.as_tensor(loc[:-1]).clamp(max=MAX_LOCAL - 1)
        targets[i, :n] = torch.as_tensor(seq[1:])
        if rest:
            boxes[i, :n] = torch.as_tensor(rest[0][:-1])
    return ids.to(device), local.to(device), targets.to(device), boxes.to(device)
