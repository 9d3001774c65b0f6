"""Grammar-constrained decoding ("invalid state nullification"): every decoded sequence is a procedure.

`GrammarLogitsProcessor` has the signature of a Hugging Face ``LogitsProcessor``: called with
``(input_ids, scores)`` it returns a copy of the scores with every token the token grammar forbids set to
``-inf``. `decode` runs our own cached loop with it: greedy or sampling, K candidates in one batch, from a
given prefix if asked. `ranked_candidates` executes the candidates and ranks them by how well they reproduce the
input: pixel accuracy in whole points, less a point for every element too many or too few, then likelihood,
and puts first the best candidate composed with the others region by region (`facaid.composition`); `best_of_k`
keeps the first.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

import numpy as np
import torch

from facaid.composition import compose as compose_candidates
from facaid.defaults import DEFAULT_K, FLOOR_TOLERANCE, TEMPERATURE
from facaid.generator.canonical import merge_repeated_floors
from facaid.grammar.execute import execute, to_segmentation
from facaid.grammar.procedure import Procedure
from facaid.incremental import IncrementalDecoder
from facaid.metrics import element_counts, pixel_accuracy, scaled_label_map, scaled_procedure_map
from facaid.model import MAX_LOCAL, FacaidModel, batch_inputs
from facaid.native import native_decoder, torch_threads
from facaid.segmentation import Segmentation
from facaid.tokenizer import BOS, EOS, PAD, TokenError, TokenGrammar, Tokenizer


class GrammarLogitsProcessor:
    """Mask scores (B, V) so that only tokens the grammar allows after ``input_ids`` (B, T) remain.

    Each row follows its own `TokenGrammar`; rows are matched by index across calls, and each call consumes the
    tokens appended since the last one (a leading BOS is skipped). A row that has ended allows only PAD.
    """

    def __init__(self, tokenizer: Tokenizer, sizes: list[tuple[float, float]], max_len: int | None = None):
        if not sizes:
            raise ValueError("sizes must name the (width, height) of every row, got none")
        for w, h in sizes:
            if not (w > 0 and h > 0):
                raise ValueError(f"image sizes must be positive, got {(w, h)!r}")
        self.tokenizer = tokenizer
        self.grammars = [TokenGrammar(tokenizer.vocab, w, h, max_len) for w, h in sizes]
        self.seen = [0] * len(sizes)

    def advance(self, input_ids: torch.Tensor) -> None:
        rows = input_ids.tolist()
        for b, (grammar, row) in enumerate(zip(self.grammars, rows, strict=True)):
            start = self.seen[b]
            if start == 0 and row and row[0] == BOS:
                start = 1
            for t in row[start:]:
                if grammar.done:
                    break
                grammar.step(t)
            self.seen[b] = len(row)

    def mask(self) -> np.ndarray:
        """(B, V) bool: the tokens each row's grammar allows next."""
        masks = []
        for b, g in enumerate(self.grammars):
            if g.done:
                m = np.zeros(len(self.tokenizer.vocab), dtype=bool)
                m[PAD] = True
            else:
                m = g.allowed()
                if not m.any():
                    raise ValueError(f"constraint is unsatisfiable for row {b} after {g.length} tokens")
            masks.append(m)
        return masks[0][None] if len(masks) == 1 else np.stack(masks)  # one row (greedy): no copy

    def __call__(self, input_ids: torch.Tensor, scores: torch.Tensor) -> torch.Tensor:
        if scores.dim() != 2 or scores.shape[1] != len(self.tokenizer.vocab):
            raise ValueError(f"scores must be (batch, {len(self.tokenizer.vocab)}), got {tuple(scores.shape)}")
        if input_ids.shape[0] != len(self.grammars) or scores.shape[0] != len(self.grammars):
            raise ValueError(f"expected {len(self.grammars)} rows, got input_ids {tuple(input_ids.shape)} and "
                             f"scores {tuple(scores.shape)}")
        self.advance(input_ids)
        allowed = torch.from_numpy(self.mask()).to(scores.device)
        return scores.masked_fill(~allowed, float("-inf"))


@dataclass
class Candidate:
    ids: list[int]  # BOS ... EOS
    logprob: float  # of the generated tokens under the masked distribution
    procedure: Procedure | None  # None only for an invalid unconstrained sequence
    accuracy: float | None = None  # pixel accuracy against the input, when scored
    count_error: int | None = None  # elements too many or too few against the input, when scored
    error: str | None = None  # why an unconstrained sequence is invalid
    swaps: int = 0  # subtrees swapped in from other candidates (`facaid.composition`), 0 for a decoded one


def prefix_from_procedure(tokenizer: Tokenizer, proc: Procedure, nodes: int) -> list[int]:
    """The tokens of the first ``nodes`` nodes of a procedure in BFS order (BOS included), for partial
    inference: the model keeps them and continues."""
    ids, local = tokenizer.encode_procedure(proc)
    starts = [i for i, k in enumerate(local) if k == 0 and i > 0]  # node groups start at local index 0
    if nodes >= len(starts) - 1:
        return ids[:-1]
    return ids[: starts[nodes]]


@torch.inference_mode()
def decode(model: FacaidModel, tokenizer: Tokenizer, seg: Segmentation, *, k: int = 1, sample: bool = False,
           temperature: float = 1.0, seed: int = 0, prefix: list[int] | None = None,
           max_len: int | None = None, constrained: bool = True, greedy: int = 0,
           incremental: bool = True, merge_floors: bool = True, native: bool = True) -> list[Candidate]:
    """K candidate procedures for a segmentation (greedy when ``sample`` is False; then K copies are equal).

    With ``merge_floors`` (and no ``prefix``), neighbouring floors with the same tree and sizes within
    `FLOOR_TOLERANCE` become one repeat, as in the canonical trees (`merge_repeated_floors`); the candidate's
    ids are then those of the merged tree, its log-probability that of the decoded sequence.

    With ``sample``, the first ``greedy`` rows are still decoded greedily, in the same batch as the samples.
    ``incremental`` (in eval mode) steps with `IncrementalDecoder`; False runs the Hugging Face modules. With
    ``native`` the rows step with the C step of `facaid.native` when it is available (the same logits to
    about 1e-5); K > 1 rows in shards on torch's threads, torch held to one thread meanwhile.

    ``constrained=False`` decodes without the grammar mask, to measure what nullification buys: a sequence
    that breaks the grammar stops there and comes back with ``procedure=None`` and the error."""
    if k < 1:
        raise ValueError(f"k must be at least 1, got {k}")
    if temperature <= 0:
        raise ValueError(f"temperature must be positive, got {temperature}")
    device = next(model.parameters()).device
    max_len = max_len or tokenizer.config.max_out
    rows = tokenizer.encode_segmentation(seg)
    rects, mask = batch_inputs([rows], device)
    memory, memory_mask = model.encode(rects, mask)  # one row: the K candidates read the same input
    memory_boxes = model.memory_boxes(rects) if model.box_scale is not None else None
    start = [BOS] + [t for t in (prefix or []) if t != BOS]
    processor = GrammarLogitsProcessor(tokenizer, [(seg.width, seg.height)] * k, max_len)
    seqs = [list(start) for _ in range(k)]
    processor.advance(torch.tensor(seqs))  # a prefix that breaks the grammar raises TokenError here
    logprob = [0.0] * k  # float64 sums, in Python: a tensor element update per token costs more
    gen = torch.Generator().manual_seed(seed)
    ids = torch.tensor(seqs, device=device)
    start_local = [tokenizer.local_indices(s, tokenizer.vocab) for s in seqs]
    local = torch.tensor(start_local, device=device).clamp(max=MAX_LOCAL - 1)
    prev_local = [row[-1] for row in start_local]  # each row's newest local index, not clamped
    boxes = torch.as_tensor(tokenizer.node_boxes(start, seg.width, seg.height), device=device).expand(k, -1, -1)
    past = None
    fast = None
    if incremental and not model.training:
        if native:  # the C step, where it builds (`facaid.native`): K rows in shards on torch's threads
            fast = native_decoder(model, memory, memory_mask, max_len, rows=k, memory_boxes=memory_boxes,
                                  threads=torch.get_num_threads())
        fast = fast or IncrementalDecoder(model, memory, memory_mask, max_len, rows=k, memory_boxes=memory_boxes)
    else:
        memory, memory_mask = memory.expand(k, -1, -1).contiguous(), memory_mask.expand(k, -1).contiguous()
        if memory_boxes is not None:
            memory_boxes = memory_boxes.expand(k, -1, -1)
    errors: list[str | None] = [None] * k
    vocab = tokenizer.vocab
    last_boxes: list[tuple | None] | None = None  # the rows' node boxes (unquantized) of the newest token
    box_embedding = None  # of ``boxes``, kept while they stay (the tokens of one node)
    row_boxes = boxes[:, -1]
    sharded = getattr(fast, "n_shards", 1) > 1
    with torch_threads(1) if sharded else contextlib.nullcontext():  # torch's spinning workers off the shards' cores
        while not all(g.done or e for g, e in zip(processor.grammars, errors, strict=True)) and len(seqs[0]) < max_len:
            if fast is not None:  # the same logits without the Hugging Face modules' per-call overhead
                if box_embedding is None and model.node_boxes:
                    box_embedding = model.embed_boxes(boxes)
                x = model.embed_outputs(ids, local, boxes, box_embedding)
                for i in range(x.shape[1]):  # one new token a step after the first (BOS and any prefix)
                    last = fast.step(x[:, i], boxes[:, i] if x.shape[1] > 1 else row_boxes)
            else:
                logits, past = model.decode(ids, local, memory, memory_mask, past,
                                            use_cache=True, boxes=boxes, memory_boxes=memory_boxes)
                last = logits[:, -1]
            scores = last.float()  # (K, V)
            if temperature != 1.0:
                scores = scores / temperature
            if constrained:
                scores = scores.masked_fill(torch.from_numpy(~processor.mask()).to(device), float("-inf"))
            logp = torch.log_softmax(scores, dim=-1)
            if sample and greedy < k:  # Gumbel-max: argmax(log p + G) is a draw from p, cheaper than multinomial
                nxt = logp.argmax(-1).cpu()
                u = torch.rand(k - greedy, logp.shape[1], generator=gen)
                nxt[greedy:] = (logp[greedy:].cpu() - torch.log(-torch.log(u))).argmax(-1)
                picked = logp.gather(1, nxt.view(k, 1).to(logp.device)).view(k).tolist()  # log p of each row's token
            else:  # the largest log p and where it is (the first of equal ones, as argmax) in one operation
                top, nxt = logp.max(-1)
                picked, nxt = top.tolist(), nxt.cpu()
            new_local, new_boxes = [], []
            for b, t in enumerate(nxt.tolist()):
                g = processor.grammars[b]
                if g.done or errors[b]:
                    t = PAD
                else:
                    logprob[b] += picked[b]
                    try:
                        g.step(t, check=not constrained)  # a masked choice is allowed already
                    except TokenError as exc:
                        errors[b] = str(exc)
                seqs[b].append(t)
                new_local.append(vocab.next_local(t, prev_local[b]))
                box = None if errors[b] else g.next_box()
                new_boxes.append(None if box is None else tuple(box))
            processor.seen = [len(s) for s in seqs]
            ids = nxt.view(k, 1).to(device)
            prev_local = new_local
            local = torch.tensor([min(i, MAX_LOCAL - 1) for i in new_local], device=device).view(k, 1)
            if new_boxes != last_boxes:  # a new node in some row: its box
                none = [box is None for box in new_boxes]
                full = (0.0, 0.0, seg.width, seg.height)
                q = tokenizer.quantize_boxes(np.array([full if box is None else box for box in new_boxes]),
                                             seg.width, seg.height)
                q[none] = 0
                boxes = torch.as_tensor(q, device=device).view(k, 1, 4)
                row_boxes = boxes[:, 0]  # the same tensor each step while it stays: `fast` keeps its mask
                last_boxes, box_embedding = new_boxes, None
    out = []
    for b, g in enumerate(processor.grammars):
        if not g.done:
            if not constrained:
                error = errors[b] or f"no <eos> within {max_len} tokens"
                out.append(Candidate([t for t in seqs[b] if t != PAD], logprob[b], None, error=error))
                continue
            # the length budget guarantees this never happens; kept as a loud check
            raise RuntimeError(f"candidate {b} did not finish within {max_len} tokens")
        seq = seqs[b][: seqs[b].index(EOS) + 1]
        proc = g.procedure()
        if merge_floors and not prefix:
            nodes = sum(1 for _ in proc.root.bfs())
            proc.root = merge_repeated_floors(proc.root, FLOOR_TOLERANCE)
            if sum(1 for _ in proc.root.bfs()) != nodes:
                seq = tokenizer.encode_procedure(proc)[0]
        proc.meta = {"source": "model"}
        out.append(Candidate(seq, logprob[b], proc))
    return out


def score(candidate: Candidate, seg: Segmentation, target: np.ndarray | None = None, scale: float = 0.25,
          counts: np.ndarray | None = None) -> float:
    """Score a candidate against the segmentation it should reproduce: its pixel accuracy at reduced
    resolution (returned, and set as ``candidate.accuracy``) and how many elements it has too many or too few,
    class by class (``candidate.count_error``). ``target`` and ``counts`` are the segmentation's
    `scaled_label_map` and `element_counts`, when already computed."""
    if target is None:
        target = scaled_label_map(seg, scale)
    if counts is None:
        counts = element_counts(seg)
    leaves = execute(candidate.procedure)  # once, for both figures
    candidate.accuracy = pixel_accuracy(scaled_procedure_map(candidate.procedure, scale, leaves), target)
    shown = element_counts(to_segmentation(candidate.procedure, leaves))
    candidate.count_error = int(np.abs(shown - counts).sum())
    return candidate.accuracy


def rank_key(candidate: Candidate) -> tuple[int, float]:
    """Higher is better: pixel accuracy in whole points less one point per element too many or too few, then
    likelihood. Decoded sizes are rough, so a candidate that misses a point of accuracy can still be the right
    structure, while a wrong repeat count shows in the element counts; among near ties the model's likelihood
    decides. (On 200 held-out facades, best of 16: exact structure 64.5 % against 62.0 % by accuracy alone.)"""
    return round(100 * candidate.accuracy) - candidate.count_error, candidate.logprob


def ranked_candidates(model: FacaidModel, tokenizer: Tokenizer, seg: Segmentation, k: int = DEFAULT_K, *,
                      temperature: float = TEMPERATURE, seed: int = 0, prefix: list[int] | None = None,
                      reference: Segmentation | None = None, compose: bool = True) -> list[Candidate]:
    """The greedy candidate and K-1 samples, executed, scored against ``reference`` (default: ``seg``, what
    the model read) and ranked by `rank_key`, best first.

    With ``compose`` (and K > 1, no ``prefix``), the first candidate becomes its composition with the others
    (`facaid.composition.compose`: each region's best subtree) when that differs from it; the composition
    carries the log-probability of the candidate it started from and ``swaps`` > 0. The candidates follow."""
    candidates = decode(model, tokenizer, seg, k=k, sample=k > 1, greedy=1, temperature=temperature, seed=seed,
                        prefix=prefix)  # one batch, sharing the cross-attention
    if reference is None:
        reference = seg
    target, counts = scaled_label_map(reference, 0.25), element_counts(reference)
    for c in candidates:
        score(c, reference, target, counts=counts)
    ranked = sorted(candidates, key=rank_key, reverse=True)
    if compose and k > 1 and not prefix:
        seen: set[tuple[int, ...]] = set()
        distinct = [c for c in ranked if not (tuple(c.ids) in seen or seen.add(tuple(c.ids)))]  # each once
        proc, swaps = compose_candidates([c.procedure for c in distinct], [c.logprob for c in distinct],
                                         reference.to_array(), target, valid=lambda p: _fits(tokenizer, p))
        if swaps:
            proc.meta = {"source": "model", "composed": swaps}
            composed = Candidate(tokenizer.encode_procedure(proc)[0], ranked[0].logprob, proc, swaps=swaps)
            score(composed, reference, target, counts=counts)
            ranked.insert(0, composed)
    return ranked


def _fits(tokenizer: Tokenizer, proc: Procedure) -> bool:
    """Whether the model could have decoded ``proc``: its tokens pass the token grammar (length, node, depth
    and leaf limits)."""
    ids = tokenizer.encode_procedure(proc)[0]
    grammar = TokenGrammar(tokenizer.vocab, proc.width, proc.height)
    try:
        for t in ids[1:]:
            grammar.step(t)
    except TokenError:
        return False
    return grammar.done


def best_of_k(model: FacaidModel, tokenizer: Tokenizer, seg: Segmentation, k: int = DEFAULT_K, *,
              temperature: float = TEMPERATURE, seed: int = 0, prefix: list[int] | None = None,
              compose: bool = True) -> Candidate:
    """The first of `ranked_candidates`: the candidate that reproduces the input best, composed with the others
    region by region."""
    return ranked_candidates(model, tokenizer, seg, k, temperature=temperature, seed=seed, prefix=prefix,
                             compose=compose)[0]
