"""Tokens for the transformer: segmentations in, procedures out, and the token grammar of procedures.

Input: each rectangle of the flattened segmentation (footprint layer plus elements) becomes five fields
(label, x, y, w, h), quantized at ``coord_bins`` steps of the image size, with a bottom-left origin and sorted
by y then x; a first row carries the image's aspect ratio. The model embeds a row either as five tokens or as
one token whose five field embeddings are summed (``TokenizerConfig.rect_tokens``). With
``TokenizerConfig.count_features`` a row has four more fields per peer rule (``peer_rule``), its peer counts
(`peer_counts`): how many rectangles of its label share its row and its column, and its rank among them, which
repeat counts follow.

Output: the derivation tree in breadth-first order, each node a group of tokens:

    leaf   := LABEL
    inner  := RULE ROLE [COUNT | CENTER] SIZE+ END

RULE is ``split_x`` ... ``mirror_y``; ROLE is a role or ``role:none``; a repeat has its COUNT, a mirror its
CENTER; each SIZE is one token (mode and quantized value); END closes the node and, for a repeat, carries its
tail (``end:0`` ... ``end:3``). The children of a node follow later, in BFS order, one group each.
`TokenGrammar` knows which tokens may come next in any state: the tokenizer parses with it and the decoder
masks with it, so every decoded sequence is a valid procedure.
"""

from __future__ import annotations

import json
import math
from collections import deque
from dataclasses import asdict, dataclass, field

import numpy as np

from facaid.grammar.execute import fill_counts
from facaid.grammar.layout import layout
from facaid.grammar.procedure import (
    GRAMMAR_VERSION,
    MAX_CHILDREN,
    MAX_DEPTH,
    MAX_LEAVES,
    MAX_NODES,
    ROLES,
    Node,
    Procedure,
    Size,
)
from facaid.labels import LABELS
from facaid.segmentation import Segmentation, flatten_array

PAD, BOS, EOS = 0, 1, 2
RULE_NAMES = ("split_x", "split_y", "repeat_x", "repeat_y", "mirror_x", "mirror_y")


class TokenError(ValueError):
    """A token sequence that is not a procedure (the message gives the position)."""


@dataclass(frozen=True)
class TokenizerConfig:
    coord_bins: int = 128  # input quantization of x, y, w, h
    aspect_bins: int = 64
    size_bins: int = 128  # abs and flt sizes: sqrt-spaced fractions of the image side
    rel_bins: int = 64
    max_count: int = 64
    max_tail: int = 3
    max_rects: int = 512
    max_out: int = 1024
    rect_tokens: int = 1  # 1: one token per rectangle (summed field embeddings); 5: one per field
    count_features: bool = False  # four more input fields per rectangle: `peer_counts`
    peer_rule: str = "overlap"  # who is a peer (`peer_counts`): "overlap", "shape", or both, "overlap+shape"

    def __post_init__(self) -> None:
        if self.count_features and self.rect_tokens != 1:
            raise ValueError("count_features need rect_tokens = 1 (the fields of a rectangle summed in one token)")
        rules = self.peer_rules
        if any(r not in PEER_RULES for r in rules) or len(set(rules)) != len(rules):
            raise ValueError(f"peer_rule must be one or more of {', '.join(PEER_RULES)} joined by '+', "
                             f"got {self.peer_rule!r}")

    @property
    def peer_rules(self) -> tuple[str, ...]:
        """The peer rules whose counts the rows carry, four fields each (with ``count_features``)."""
        return tuple(self.peer_rule.split("+"))

    @property
    def input_fields(self) -> int:
        return 5 + 4 * len(self.peer_rules) if self.count_features else 5

    def to_dict(self) -> dict:
        return asdict(self)


# --- output vocabulary ---------------------------------------------------------------------------------------

@dataclass
class Vocabulary:
    """Output token strings and the id ranges of each kind."""

    config: TokenizerConfig
    tokens: list[str] = field(default_factory=list)
    ranges: dict[str, range] = field(default_factory=dict)

    def __post_init__(self) -> None:
        c = self.config
        groups = {
            "special": ["<pad>", "<bos>", "<eos>"],
            "rule": list(RULE_NAMES),
            "label": [f"label:{name}" for name in LABELS],
            "role": ["role:none", *(f"role:{r}" for r in ROLES)],
            "count": [f"count:{n}" for n in range(1, c.max_count + 1)],
            "center": ["center:0", "center:1"],
            "abs": [f"abs:{q}" for q in range(c.size_bins)],
            "flt": [f"flt:{q}" for q in range(c.size_bins)],
            "rel": [f"rel:{q}" for q in range(c.rel_bins)],
            "end": [f"end:{t}" for t in range(c.max_tail + 1)],
        }
        for name, items in groups.items():
            self.ranges[name] = range(len(self.tokens), len(self.tokens) + len(items))
            self.tokens.extend(items)
        self.index = {t: i for i, t in enumerate(self.tokens)}
        self.kinds = [name for name, r in self.ranges.items() for _ in r]  # kind of each token id

    def __len__(self) -> int:
        return len(self.tokens)

    def id(self, token: str) -> int:
        return self.index[token]

    def kind(self, token_id: int) -> str:
        if not 0 <= token_id < len(self.kinds):
            raise TokenError(f"token id {token_id} is outside the vocabulary of {len(self)}")
        return self.kinds[token_id]

    def next_local(self, token_id: int, prev_local: int) -> int:
        """Local index of a token within its node group: a rule, a label or a special token starts a group."""
        return 0 if self.kinds[token_id] in ("rule", "label", "special") else prev_local + 1


# --- quantization -------------------------------------------------------------------------------------------------

MAX_PEERS = 64  # peer counts and ranks are clipped here
PEER_RULES = ("overlap", "shape")
SHAPE_TOLERANCE = 0.25  # "shape" peers: edges and sizes agree within this share of the larger extent


def _near(v: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """(N, N): pairs whose values ``v`` differ by at most `SHAPE_TOLERANCE` of the larger of their ``scale``."""
    return np.abs(v[:, None] - v[None, :]) <= SHAPE_TOLERANCE * np.maximum(scale[:, None], scale[None, :])


def peer_counts(arr: np.ndarray, rule: str = "overlap") -> np.ndarray:
    """(N, 4) int64 for int rows (label, x0, y0, x1, y1), y down: the number of rectangles of the same label
    in the row's row, itself included, and its rank in it from the left, then the same for its column (rank
    from the bottom). A window in a grid of 5 floors by 6 bays gets (6, bay, 5, floor): the counts a repeat
    needs, which the model would otherwise have to count by attention.

    ``rule`` says who is in a row (a column likewise, the axes swapped):
    - "overlap": vertical overlap >= half the lower height. Peers by overlap rather than equal edges, so that
      edges moved a little keep the counts (a rectangle that noise breaks into pieces changes them).
    - "shape": a translate along the row, within `SHAPE_TOLERANCE`: top and bottom edges and width agree to a
      quarter of the larger height or width. The copies of one repeat are peers, the windows of the next
      building in the same row (another floor height, another window size) are not, nor a floor's windows
      and the taller ones of the floor below, which a repeat of floors does not count either."""
    if len(arr) == 0:
        return np.zeros((0, 4), dtype=np.int64)
    if rule not in PEER_RULES:
        raise ValueError(f"peer rule must be one of {', '.join(PEER_RULES)}, got {rule!r}")
    a = np.asarray(arr, dtype=np.float64)
    same = a[:, 0][:, None] == a[:, 0][None, :]
    order = np.arange(len(a))  # ties in position rank by row order
    out = []
    for lo, hi, rank_lo, rank_hi, sign in ((2, 4, 1, 3, 1.0), (1, 3, 2, 4, -1.0)):
        # peers share the (lo, hi) axis's span; rank on the other axis (x from the left, y from the bottom)
        extent = a[:, hi] - a[:, lo]
        if rule == "overlap":
            overlap = (np.minimum(a[:, hi][:, None], a[:, hi][None, :])
                       - np.maximum(a[:, lo][:, None], a[:, lo][None, :]))
            peers = same & (overlap >= 0.5 * np.minimum(extent[:, None], extent[None, :])) & (overlap > 0)
        else:
            length = a[:, rank_hi] - a[:, rank_lo]  # the size along the row
            peers = same & _near(a[:, lo], extent) & _near(a[:, hi], extent) & _near(length, length)
        centre = sign * (a[:, rank_lo] + a[:, rank_hi])
        before = peers & ((centre[None, :] < centre[:, None])
                          | ((centre[None, :] == centre[:, None]) & (order[None, :] < order[:, None])))
        out += [np.minimum(peers.sum(1), MAX_PEERS), np.minimum(before.sum(1), MAX_PEERS - 1)]
    return np.stack(out, axis=1).astype(np.int64)


def quantize_size(value: float, side: float, bins: int) -> int:
    """abs/flt sizes: the fraction of the image side, sqrt-spaced so small parts keep precision."""
    frac = min(max(value / side, 0.0), 1.0)
    return min(bins - 1, round(math.sqrt(frac) * (bins - 1)))


def dequantize_size(q: int, side: float, bins: int) -> float:
    return (q / (bins - 1)) ** 2 * side


def quantize_rel(value: float, bins: int) -> int:
    return min(bins - 1, max(0, round(value * (bins - 1))))


# --- the token grammar ----------------------------------------------------------------------------------------------

@dataclass
class _Open:
    """The node whose tokens are being read."""

    node: Node
    depth: int
    mult: int  # copies of this node after expansion
    phase: str  # "role", "extra", "sizes"
    box: list  # [x0, y0, x1, y1] of the node's first instance, in image coordinates
    child_boxes: list = field(default_factory=list)  # one list per child, filled in at the node's end


class TokenGrammar:
    """The automaton of procedure token sequences: what may come next, and the tree read so far.

    One instance follows one sequence (after BOS). `allowed()` is a boolean mask over the vocabulary;
    `step(token)` consumes a token and raises `TokenError` when it is not allowed. The constraints keep every
    completion valid: depth, node and expansion limits, and a length budget (``max_out``) that always leaves
    room to close every open node with leaves.
    """

    def __init__(self, vocab: Vocabulary, width: float, height: float, max_len: int | None = None):
        self.vocab = vocab
        self.width, self.height = float(width), float(height)
        self.max_len = max_len or vocab.config.max_out
        self.length = 1  # BOS
        self.nodes = 0
        self.expanded = 1  # leaves the expansion may have: sum of copies over every created slot
        # (parent, depth, copies, box): the slots whose nodes come next; a box is filled in when its parent ends
        self.pending: deque[tuple[Node | None, int, int, list]] = deque([(None, 0, 1, [0.0, 0.0, self.width,
                                                                                         self.height])])
        self.root: Node | None = None
        self.open: _Open | None = None
        self.done = False
        r = vocab.ranges
        self._masks = {name: self._mask(r[name]) for name in r}
        self._eos = self._mask(range(EOS, EOS + 1))
        # a split's first size copies its child as often as the split is copied; a repeat (count 1, and room
        # for a tail) or a mirror twice as often
        self._splits = np.zeros(len(vocab), dtype=bool)
        self._splits[[i for i in r["rule"] if vocab.tokens[i].startswith("split")]] = True
        self._doubling = self._masks["rule"] & ~self._splits

    def _mask(self, ids: range) -> np.ndarray:
        m = np.zeros(len(self.vocab), dtype=bool)
        m[ids.start : ids.stop] = True
        return m

    # Length budget. The state is kept feasible: the tokens so far plus the fewest that can finish the
    # sequence (one leaf per open slot, the rest of the open node, EOS) never exceed max_len. Leaves and the
    # mandatory tokens of a node keep it so; a new inner node or an extra size is allowed only if it does.
    _INNER_MIN = 5  # role, count or center, one size, its leaf child, end

    def allowed(self) -> np.ndarray:
        m = self._masks
        if self.done:
            return np.zeros(len(self.vocab), dtype=bool)
        room = self.max_len - self.length - 1  # tokens left before the final EOS
        if self.open is None:
            if not self.pending:
                return self._eos.copy()
            _, depth, copies, _ = self.pending[0]
            out = m["label"].copy()
            if (depth + 1 < MAX_DEPTH and self.nodes + 2 <= MAX_NODES
                    and 1 + self._INNER_MIN + len(self.pending) - 1 <= room):
                if self.expanded + copies <= MAX_LEAVES:  # the leaf budget: the smallest expansion must fit
                    out |= self._splits
                if self.expanded + 2 * copies <= MAX_LEAVES:
                    out |= self._doubling
            return out
        o = self.open
        if o.phase == "role":
            return m["role"].copy()
        if o.phase == "extra":
            if o.node.rule == "mirror":
                return m["center"].copy()
            out = m["count"].copy()
            counts = self.vocab.ranges["count"]
            for n in range(1, len(counts) + 1):  # copies of the children: count, plus one for a tail
                if self.expanded + o.mult * (n + 1) > MAX_LEAVES:
                    out[counts.start + n - 1 :] = False
                    break
            return out
        k = len(o.node.sizes)
        out = np.zeros(len(self.vocab), dtype=bool)
        more = (k == 0 or (k < MAX_CHILDREN and self.nodes + len(self.pending) + 1 <= MAX_NODES
                           and 1 + len(self.pending) + 1 + 1 <= room))  # size, open slots, new child, end
        if more and self.expanded + self._child_copies(o) <= MAX_LEAVES:
            out |= m["abs"] | m["flt"] | m["rel"]
        if k > 0:
            ends = self.vocab.ranges["end"]
            tails = min(k, len(ends)) if o.node.rule == "repeat" else 1  # a tail is shorter than the pattern
            out[ends.start : ends.start + tails] = True
        return out

    def _child_copies(self, o: _Open) -> int:
        if o.node.rule == "repeat":
            return o.mult * (o.node.count + 1)
        if o.node.rule == "mirror":
            return o.mult * 2
        return o.mult

    def next_box(self) -> list | None:
        """The box (x0, y0, x1, y1) of the node the next token belongs to (its first instance), or None when
        the next token can only be EOS or the sequence is over."""
        if self.done:
            return None
        if self.open is not None:
            return self.open.box
        return self.pending[0][3] if self.pending else None

    def step(self, token: int, check: bool = True) -> None:
        """Consume a token; ``check=False`` skips the mask for sequences known to be valid (training data)."""
        if check and (not 0 <= token < len(self.vocab) or not self.allowed()[token]):
            name = self.vocab.tokens[token] if 0 <= token < len(self.vocab) else str(token)
            raise TokenError(f"token {self.length} ({name}) is not allowed here")
        self.length += 1
        v = self.vocab
        kind = v.kind(token)
        text = v.tokens[token]
        if kind == "special":  # EOS
            self.done = True
            return
        if self.open is None:
            parent, depth, copies, box = self.pending.popleft()
            if kind == "label":
                node = Node.leaf(text.split(":", 1)[1])
            else:
                rule, axis = text.split("_")
                node = Node(rule, axis=axis)
                if rule == "repeat":
                    node.count = 1
                self.open = _Open(node, depth, copies, "role", box)
            self.nodes += 1
            if parent is None:
                self.root = node
            else:
                parent.children.append(node)
            return
        o = self.open
        if kind == "role":
            role = text.split(":", 1)[1]
            o.node.role = None if role == "none" else role
            o.phase = "sizes" if o.node.rule == "split" else "extra"
        elif kind == "count":
            o.node.count = int(text.split(":")[1])
            o.phase = "sizes"
        elif kind == "center":
            o.node.center = text.endswith("1")
            o.phase = "sizes"
        elif kind in ("abs", "flt", "rel"):
            q = int(text.split(":")[1])
            side = self.width if o.node.axis == "x" else self.height
            if kind == "rel":
                value = q / (v.config.rel_bins - 1)
            else:
                value = dequantize_size(q, side, v.config.size_bins)
            o.node.sizes.append(Size(kind, value))
            copies = self._child_copies(o)
            self.expanded += copies
            o.child_boxes.append([0.0, 0.0, 0.0, 0.0])
            self.pending.append((o.node, o.depth + 1, copies, o.child_boxes[-1]))
        elif kind == "end":
            o.node.tail = int(text.split(":")[1])
            self._lay_out_children(o)
            self.open = None
        else:
            raise TokenError(f"token {self.length - 1} ({text}) is not allowed here")

    @staticmethod
    def _lay_out_children(o: _Open) -> None:
        """Fill in the first-instance boxes of the children of a node whose sizes are all read."""
        node = o.node
        x0, y0, x1, y1 = o.box
        lo, hi = (x0, x1) if node.axis == "x" else (y0, y1)
        sizes = node.sizes
        if node.rule == "repeat":
            sizes = sizes * node.count + sizes[: node.tail]
        elif node.rule == "mirror":
            sizes = sizes + sizes[::-1][(1 if node.center else 0):]
        lengths = layout(sizes, hi - lo)
        pos, last = lo, len(sizes) - 1
        for i, box in enumerate(o.child_boxes):  # the first copy: the executor's layout from the near end
            end = hi if i == last else pos + lengths[i]
            box[:] = [pos, y0, end, y1] if node.axis == "x" else [x0, pos, x1, end]
            pos = end

    def procedure(self) -> Procedure:
        if not self.done:
            raise TokenError("the sequence ended before <eos>")
        return Procedure(self.width, self.height, self.root)


# --- the tokenizer ---------------------------------------------------------------------------------------------------

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
        """(token ids with BOS and EOS, local index of each token within its node group)."""
        v, c = self.vocab, self.config
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
