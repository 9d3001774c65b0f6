"""The grammar mask ("invalid state nullification") as a Hugging Face ``LogitsProcessor``.

`GrammarLogitsProcessor` follows one `TokenGrammar` per batch row. Inside ``model.generate(...,
logits_processor=[processor])`` it is called with ``(input_ids, scores)`` and returns a copy of the scores with
every token the grammar forbids set to ``-inf``. Our own loop (`facaid.decoding.loop.decode`) drives it through the
same public methods: `push` a row's token (or `fail` it), read the `mask`, a row's `node_box`, and its
`procedure`.
"""

from __future__ import annotations

import numpy as np
import torch
from transformers import LogitsProcessor

from facaid.grammar.procedure import Procedure
from facaid.tokenizer import BOS, PAD, TokenGrammar, Tokenizer


class GrammarLogitsProcessor(LogitsProcessor):
    """Mask scores (B, V) so that only tokens the grammar allows after ``input_ids`` (B, T) remain.

    Each row follows its own `TokenGrammar`; rows are matched by index across calls, and each call consumes the
    tokens appended since the last one (a leading BOS is skipped). A row that has ended (or broken the grammar,
    when tokens are pushed unchecked) allows only PAD.
    """

    def __init__(self, tokenizer: Tokenizer, sizes: list[tuple[float, float]], max_len: int | None = None):
        if not sizes:
            raise ValueError("sizes must name the (width, height) of every row, got none")
        for w, h in sizes:
            if not (w > 0 and h > 0):
                raise ValueError(f"image sizes must be positive, got {(w, h)!r}")
        self.tokenizer = tokenizer
        self._grammars = [TokenGrammar(tokenizer.vocab, w, h, max_len) for w, h in sizes]
        self._seen = [0] * len(sizes)  # tokens of each row consumed, BOS included
        self._errors: list[str | None] = [None] * len(sizes)

    @property
    def rows(self) -> int:
        return len(self._grammars)

    def finished(self, row: int) -> bool:
        """Whether the row has ended (EOS) or broken the grammar."""
        return self._grammars[row].done or self._errors[row] is not None

    def all_finished(self) -> bool:
        return all(self.finished(b) for b in range(self.rows))

    def error(self, row: int) -> str | None:
        """Why the row broke the grammar (`fail`), or None."""
        return self._errors[row]

    def fail(self, row: int, message: str) -> None:
        """End a row that broke the grammar (an unconstrained decode keeps going with the others)."""
        self._errors[row] = message

    def push(self, row: int, token: int, check: bool = True) -> None:
        """Append one token to a row; a finished row takes it as padding. With ``check`` a token the grammar
        forbids raises `TokenError`; ``check=False`` trusts it (a choice the mask allowed already)."""
        self._seen[row] += 1
        if not self.finished(row):
            self._grammars[row].step(token, check=check)

    def advance(self, input_ids: torch.Tensor) -> None:
        """Consume the tokens of ``input_ids`` (B, T) appended since the last call (checked)."""
        for b, row in enumerate(input_ids.tolist()):
            start = self._seen[b]
            if start == 0 and row and row[0] == BOS:
                start = self._seen[b] = 1
            for t in row[start:]:
                self.push(b, t)

    def mask(self) -> np.ndarray:
        """(B, V) bool: the tokens each row's grammar allows next."""
        masks = []
        for b, g in enumerate(self._grammars):
            if self.finished(b):
                m = np.zeros(len(self.tokenizer.vocab), dtype=bool)
                m[PAD] = True
            else:
                m = g.allowed()
                if not m.any():
                    raise ValueError(f"constraint is unsatisfiable for row {b} after {g.length} tokens")
            masks.append(m)
        return masks[0][None] if len(masks) == 1 else np.stack(masks)  # one row (greedy): no copy

    def node_box(self, row: int) -> list | None:
        """The box (x0, y0, x1, y1, in pixels) of the node the row's next token belongs to, or None."""
        return None if self._errors[row] else self._grammars[row].next_box()

    def procedure(self, row: int) -> Procedure:
        """The row's procedure, once it has ended."""
        return self._grammars[row].procedure()

    def __call__(self, input_ids: torch.Tensor, scores: torch.Tensor) -> torch.Tensor:
        if scores.dim() != 2 or scores.shape[1] != len(self.tokenizer.vocab):
            raise ValueError(f"scores must be (batch, {len(self.tokenizer.vocab)}), got {tuple(scores.shape)}")
        if input_ids.shape[0] != self.rows or scores.shape[0] != self.rows:
            raise ValueError(f"expected {self.rows} rows, got input_ids {tuple(input_ids.shape)} and "
                             f"scores {tuple(scores.shape)}")
        self.advance(input_ids)
        allowed = torch.from_numpy(self.mask()).to(scores.device)
        return scores.masked_fill(~allowed, float("-inf"))
