"""The tokenizer: segmentations to input rows, procedures to token ids and back, saved as ``tokenizer.json``."""

from __future__ import annotations

import json
import math
from collections import deque

import numpy as np

from facaid.grammar.execute import fill_counts
from facaid.grammar.nodes import Node
from facaid.grammar.procedure import GRAMMAR_VERSION, Procedure
from facaid.labels import LABELS
from facaid.segmentation import Segmentation, flatten_array
from facaid.tokenizer.features import MAX_PEERS, peer_counts, quantize_rel, quantize_size
from facaid.tokenizer.token_grammar import TokenGrammar
from facaid.tokenizer.vocabulary import BOS, EOS, PAD, TokenizerConfig, Vocabulary


class Tokenizer:
    def __init__(self, config: TokenizerConfig | None = None):
        self.config = config or TokenizerConfig()
        self.vocab = Vocabulary(self.config)

    # input
    @property
    def input_vocab_sizes(self) -> tuple[int, ...]:
        """Sizes of the field embeddings: label (incl. the <image> row), x, y, w, h, and with
        ``count_features`` the four `peer_counts` of each peer rule."""
        c = self.config
        sizes = (len(LABELS) + 1, max(c.coord_bins, c.aspect_bins), c.coord_bins, c.coord_bins + 1,
                 c.coord_bins + 1)
        return sizes + (MAX_PEERS + 1, MAX_PEERS) * 2 * len(c.peer_rules) if c.count_features else sizes

    def encode_segmentation(self, seg: Segmentation) -> np.ndarray:
        """(N + 1, F) int64 rows (label, x, y, w, h[, peer counts]); row 0 is the <image> row with the aspect
        ratio (and zero counts)."""
        c = self.config
        arr = flatten_array(seg.width, seg.height, seg.to_array(), wall="footprint")
        if len(arr) > c.max_rects:
            raise ValueError(f"too many rectangles for the model: {len(arr)} after flattening "
                             f"(at most {c.max_rects})")
        return self.encode_rect_array(seg.width, seg.height, arr)

    def encode_rect_array(self, width: int, height: int, arr: np.ndarray) -> np.ndarray:
        c = self.config
        rows = np.concatenate([arr[:, :1].astype(np.int64), self.quantize_boxes(arr[:, 1:], width, height)], 1)
        if c.count_features:
            rows = np.concatenate([rows, *(peer_counts(arr, rule) for rule in c.peer_rules)], 1)
        rows = rows[np.lexsort((rows[:, 1], rows[:, 2]))]
        aspect = math.log(width / height)  # in [-log 16, log 16] for sane images
        qa = min(c.aspect_bins - 1, max(0, round((aspect / math.log(16) + 1) / 2 * (c.aspect_bins - 1))))
        meta = np.zeros((1, c.input_fields), dtype=np.int64)
        meta[0, :2] = len(LABELS), qa
        return np.concatenate([meta, rows])

    def quantize_boxes(self, boxes: np.ndarray, width: float, height: float) -> np.ndarray:
        """(N, 4) boxes x0, y0, x1, y1 (y down) -> (N, 4) int64 x, y, w, h at ``coord_bins``, bottom-left origin."""
        r = self.config.coord_bins
        b = np.asarray(boxes, dtype=np.float64)
        x = np.clip(np.floor(b[:, 0] * r / width), 0, r - 1)
        y = np.clip(np.floor((height - b[:, 3]) * r / height), 0, r - 1)
        w = np.clip(np.rint((b[:, 2] - b[:, 0]) * r / width), 1, r)
        h = np.clip(np.rint((b[:, 3] - b[:, 1]) * r / height), 1, r)
        return np.stack([x, y, w, h], axis=1).astype(np.int64)

    # output
    def node_boxes(self, ids: list[int], width: float, height: float) -> np.ndarray:
        """(len(ids), 4) int64: at each position, the quantized box of the node the *next* token belongs to
        (all zeros where the next token is EOS or nothing). The decoder sees it with the token, so it knows
        which region of the input it is describing. ``ids`` start with BOS and follow the grammar."""
        grammar = TokenGrammar(self.vocab, width, height, max_len=max(self.config.max_out, len(ids) + 1))
        boxes, known = np.zeros((len(ids), 4)), np.zeros(len(ids), dtype=bool)
        for t, token in enumerate(ids):
            if t > 0 or token != BOS:
                if token == PAD or grammar.done:
                    break
                grammar.step(int(token), check=False)
            box = grammar.next_box()
            if box is not None:
                boxes[t], known[t] = box, True
        out = np.zeros((len(ids), 4), dtype=np.int64)
        if known.any():
            out[known] = self.quantize_boxes(boxes[known], width, height)
        return out

    def encode_procedure(self, proc: Procedure) -> tuple[list[int], list[int]]:
        """(token ids with BOS and EOS, local index of each token within its node group). A repeat's exceptions are
        not in the model's grammar (the structure reader writes them): such a tree raises ValueError."""
        v, c = self.vocab, self.config
        if any(n.exceptions for _, n in proc.nodes()):
            raise ValueError("the model's grammar has no exceptions of repeats; this procedure has some")
        ids, local = [BOS], [0]
        fills = fill_counts(proc) if any(n.count == "fill" for _, n in proc.nodes()) else {}
        queue: deque[Node] = deque([proc.root])
        while queue:
            node = queue.popleft()
            group: list[int] = []
            if node.rule == "leaf":
                group.append(v.id(f"label:{node.label}"))
            else:
                group.append(v.id(f"{node.rule}_{node.axis}"))
                group.append(v.id(f"role:{node.role or 'none'}"))
                if node.rule == "repeat":
                    count = fills[id(node)] if node.count == "fill" else node.count
                    group.append(v.id(f"count:{min(count, c.max_count)}"))
                elif node.rule == "mirror":
                    group.append(v.id(f"center:{int(node.center)}"))
                side = proc.width if node.axis == "x" else proc.height
                for s in node.sizes:
                    if s.mode == "rel":
                        group.append(v.id(f"rel:{quantize_rel(s.value, c.rel_bins)}"))
                    else:
                        group.append(v.id(f"{s.mode}:{quantize_size(s.value, side, c.size_bins)}"))
                group.append(v.id(f"end:{min(node.tail, c.max_tail)}"))
                queue.extend(node.children)
            ids.extend(group)
            local.extend(range(len(group)))
        ids.append(EOS)
        local.append(0)
        return ids, local

    def encode_target(self, proc: Procedure) -> tuple[list[int], list[int], np.ndarray]:
        """What the decoder is trained on: (ids, local indices, node boxes) of a procedure."""
        ids, local = self.encode_procedure(proc)
        return ids, local, self.node_boxes(ids, proc.width, proc.height)

    def decode_procedure(self, ids: list[int], width: float, height: float) -> Procedure:
        """Parse output tokens (with or without BOS) back into a procedure; raise `TokenError` if invalid."""
        grammar = TokenGrammar(self.vocab, width, height, max_len=max(self.config.max_out, len(ids) + 1))
        for t in ids[1:] if ids and ids[0] == BOS else ids:
            if t == PAD:
                break
            grammar.step(int(t))
            if grammar.done:
                break
        proc = grammar.procedure()
        proc.meta = {"source": "model"}
        return proc

    @staticmethod
    def local_indices(ids: list[int], vocab: Vocabulary) -> list[int]:
        """Local index of each token within its node group, from the ids alone (used while decoding)."""
        out, k = [], 0
        for t in ids:
            k = vocab.next_local(t, k)
            out.append(k)
        return out

    # persistence
    def save(self, path) -> None:
        payload = {"grammar": GRAMMAR_VERSION, "config": self.config.to_dict(), "output_tokens": self.vocab.tokens}
        with open(path, "w", encoding="utf-8") as f:
            json.dump(payload, f, indent=1)

    @classmethod
    def load(cls, path) -> Tokenizer:
        with open(path, encoding="utf-8") as f:
            payload = json.load(f)
        if payload.get("grammar") != GRAMMAR_VERSION:
            raise ValueError(f"tokenizer made for grammar {payload.get('grammar')!r}; this build runs "
                             f"{GRAMMAR_VERSION!r}")
        tok = cls(TokenizerConfig(**payload["config"]))
        if tok.vocab.tokens != payload["output_tokens"]:
            raise ValueError("the saved vocabulary does not match this build's vocabulary")
        return tok
