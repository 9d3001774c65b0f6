"""The output vocabulary: special tokens, rules, labels, roles, counts, sizes and ends, with the id range of each
kind, and the tokenizer's settings (`TokenizerConfig`)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from facaid.grammar.procedure import ROLES
from facaid.labels import LABELS
from facaid.tokenizer.features import PEER_RULES

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
