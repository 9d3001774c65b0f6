"""Grammar-constrained decoding ("invalid state nullification"): every decoded sequence is a procedure.

- `processor`: `GrammarLogitsProcessor`, a Hugging Face ``LogitsProcessor`` that masks every token the token
  grammar forbids (it works inside ``model.generate`` too);
- `backends`: `Stepper`, the next token's logits from the C step (`step`) or the decoder's own cached torch step;
- `loop`: `decode`, K candidates (greedy or sampled) in one batch, from a prefix if asked;
- `ranking`: `ranked_candidates` and `best_of_k`, the candidates executed and ranked by how well they
  reproduce the input, composed region by region (`composition`).
"""

from facaid.decoding.loop import Candidate, decode, prefix_from_procedure
from facaid.decoding.processor import GrammarLogitsProcessor
from facaid.decoding.ranking import best_of_k, fits, rank_key, ranked_candidates, score

__all__ = ["Candidate", "GrammarLogitsProcessor", "best_of_k", "decode", "fits", "prefix_from_procedure",
           "rank_key", "ranked_candidates", "score"]
