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

from facaid.tokenizer.codec import Tokenizer
from facaid.tokenizer.features import (
    MAX_PEERS,
    PEER_RULES,
    SHAPE_TOLERANCE,
    dequantize_size,
    peer_counts,
    quantize_rel,
    quantize_size,
)
from facaid.tokenizer.token_grammar import TokenGrammar
from facaid.tokenizer.vocabulary import BOS, EOS, PAD, RULE_NAMES, TokenError, TokenizerConfig, Vocabulary

__all__ = ["BOS", "EOS", "MAX_PEERS", "PAD", "PEER_RULES", "RULE_NAMES", "SHAPE_TOLERANCE", "TokenError",
           "TokenGrammar", "Tokenizer", "TokenizerConfig", "Vocabulary", "dequantize_size", "peer_counts",
           "quantize_rel", "quantize_size"]
