"""What computes the next token's logits for the decoding loop: one interface over two backends.

- the C step (`facaid.native`), where it builds: K rows in shards on torch's threads;
- `facaid.model.decoder.DecoderState`: the model's own decoder blocks stepped with their key/value cache.
Both give the logits of the teacher-forced `FacaidModel.decode` (to about 1e-5; tests/decoding/test_native_step.py,
tests/decoding/test_decoding.py).
"""

from __future__ import annotations

import torch

from facaid.decoding.step import native_decoder
from facaid.model import FacaidModel
from facaid.model.decoder import DecoderState


class Stepper:
    """Logits of each row's next token, fed the tokens appended since the last call.

    ``memory`` (1, S, d) is the encoded input the K rows share; ``memory_boxes`` its rectangles' boxes when the
    model biases cross-attention by them."""

    def __init__(self, model: FacaidModel, memory: torch.Tensor, memory_mask: torch.Tensor,
                 memory_boxes: torch.Tensor | None, max_len: int, rows: int, *, native: bool = True):
        self.model = model
        self.fast = None
        if native:
            self.fast = native_decoder(model, memory, memory_mask, max_len, rows=rows, memory_boxes=memory_boxes,
                                       threads=torch.get_num_threads())
        self.fast = self.fast or DecoderState(model, memory, memory_mask, max_len, rows=rows,
                                              memory_boxes=memory_boxes)
        self._boxes: torch.Tensor | None = None  # the boxes whose embedding is kept (the tokens of one node)
        self._box_embedding: torch.Tensor | None = None
        self._row_boxes: torch.Tensor | None = None

    @property
    def sharded(self) -> bool:
        """Whether rows step in shards on several threads (torch should keep to one thread meanwhile)."""
        return getattr(self.fast, "n_shards", 1) > 1

    def logits(self, ids: torch.Tensor, local: torch.Tensor, boxes: torch.Tensor) -> torch.Tensor:
        """(K, V) logits after the new tokens ``ids`` (K, T) with their local indices (K, T) and node boxes
        (K, T, 4). Pass the same ``boxes`` tensor while the rows stay in their nodes: its embedding is kept."""
        if boxes is not self._boxes:
            self._boxes = boxes
            self._box_embedding = self.model.embed_boxes(boxes) if self.model.node_boxes else None
            self._row_boxes = boxes[:, -1]  # one tensor while the boxes stay: the step keeps its attention mask
        x = self.model.embed_outputs(ids, local, boxes, self._box_embedding)
        for i in range(x.shape[1]):  # one new token a step after the first call (BOS and any prefix)
            last = self.fast.step(x[:, i], boxes[:, i] if x.shape[1] > 1 else self._row_boxes)
        return last
