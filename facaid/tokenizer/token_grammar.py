"""The token grammar: the automaton of procedure token sequences. It knows which tokens may come next in any state
(the decoder masks with it) and builds the tree read so far (the tokenizer parses with it)."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np

from facaid.grammar.layout import layout
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import MAX_CHILDREN, MAX_DEPTH, MAX_LEAVES, MAX_NODES, Procedure
from facaid.tokenizer.features import dequantize_size
from facaid.tokenizer.vocabulary import EOS, TokenError, Vocabulary


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
