"""The decoding loop: K candidate procedures for a segmentation, greedy or sampled, from a prefix if asked.

It encodes the input once, steps the rows with a `facaid.decoding.backends.Stepper` and masks every step with a
`facaid.decoding.processor.GrammarLogitsProcessor`, so every finished row is a procedure.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

import numpy as np
import torch

from facaid.decoding.backends import Stepper
from facaid.decoding.processor import GrammarLogitsProcessor
from facaid.decoding.step import torch_threads
from facaid.defaults import FLOOR_TOLERANCE
from facaid.grammar.floors import merge_repeated_floors
from facaid.grammar.procedure import Procedure
from facaid.model import MAX_LOCAL, FacaidModel, batch_inputs
from facaid.segmentation import Segmentation
from facaid.tokenizer import BOS, EOS, PAD, TokenError, Tokenizer


@dataclass
class Candidate:
    ids: list[int]  # BOS ... EOS
    logprob: float  # of the generated tokens under the masked distribution
    procedure: Procedure | None  # None only for an invalid unconstrained sequence
    accuracy: float | None = None  # pixel accuracy against the input, when scored
    count_error: int | None = None  # elements too many or too few against the input, when scored
    error: str | None = None  # why an unconstrained sequence is invalid
    swaps: int = 0  # subtrees swapped in from other candidates (`facaid.decoding.composition`), 0 for a decoded one


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
           merge_floors: bool = True, native: bool = True) -> list[Candidate]:
    """K candidate procedures for a segmentation (greedy when ``sample`` is False; then K copies are equal).

    With ``merge_floors`` (and no ``prefix``), neighbouring floors with the same tree and sizes within
    `FLOOR_TOLERANCE` become one repeat, as in the canonical trees (`merge_repeated_floors`); the candidate's
    ids are then those of the merged tree, its log-probability that of the decoded sequence.

    With ``sample``, the first ``greedy`` rows are still decoded greedily, in the same batch as the samples.
    The rows step with the model's decoder blocks and their key/value cache (`facaid.model.decoder.DecoderState`), or
    with ``native`` with the C step of `facaid.native` when it is available (the same logits to about 1e-5);
    K > 1 rows in shards on torch's threads, torch held to one thread meanwhile.

    ``constrained=False`` decodes without the grammar mask, to measure what nullification buys: a sequence
    that breaks the grammar stops there and comes back with ``procedure=None`` and the error."""
    if k < 1:
        raise ValueError(f"k must be at least 1, got {k}")
    if temperature <= 0:
        raise ValueError(f"temperature must be positive, got {temperature}")
    device = next(model.parameters()).device
    max_len = min(max_len or tokenizer.config.max_out, model.decoder.max_len)  # no longer than its positions
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
    stepper = Stepper(model, memory, memory_mask, memory_boxes, max_len, k, native=native)
    vocab = tokenizer.vocab
    last_boxes: list[tuple | None] | None = None  # the rows' node boxes (unquantized) of the newest token
    with torch_threads(1) if stepper.sharded else contextlib.nullcontext():  # torch's workers off the shards' cores
        while not processor.all_finished() and len(seqs[0]) < max_len:
            scores = stepper.logits(ids, local, boxes).float()  # (K, V)
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
                if processor.finished(b):
                    t = PAD
                else:
                    logprob[b] += picked[b]
                try:
                    processor.push(b, t, check=not constrained)  # a masked choice is allowed already
                except TokenError as exc:
                    processor.fail(b, str(exc))
                seqs[b].append(t)
                new_local.append(vocab.next_local(t, prev_local[b]))
                box = processor.node_box(b)
                new_boxes.append(None if box is None else tuple(box))
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
                last_boxes = new_boxes
    out = []
    for b in range(k):
        if processor.error(b) or EOS not in seqs[b]:
            if not constrained:
                error = processor.error(b) or f"no <eos> within {max_len} tokens"
                out.append(Candidate([t for t in seqs[b] if t != PAD], logprob[b], None, error=error))
                continue
            # the length budget guarantees this never happens; kept as a loud check
            raise RuntimeError(f"candidate {b} did not finish within {max_len} tokens")
        seq = seqs[b][: seqs[b].index(EOS) + 1]
        proc = processor.procedure(b)
        if merge_floors and not prefix:
            nodes = sum(1 for _ in proc.root.bfs())
            proc.root = merge_repeated_floors(proc.root, FLOOR_TOLERANCE)
            if sum(1 for _ in proc.root.bfs()) != nodes:
                seq = tokenizer.encode_procedure(proc)[0]
        proc.meta = {"source": "model"}
        out.append(Candidate(seq, logprob[b], proc))
    return out
