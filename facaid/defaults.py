"""Decoding defaults shared by the library, the command line, the worker and the site, in a module that
imports nothing (the web process and the command-line parser need them without loading torch)."""

# Best-of-K decoding: the greedy candidate and K - 1 samples at TEMPERATURE, ranked by
# `facaid.decoding.rank_key`. On 200 held-out facades (dataset seed 3000) the exact-structure rate was 58.0 %
# greedy, 62-63 % best of 8 and 61.5-64.5 % best of 16 (two draws of samples); decoding 8 costs about 3x the
# greedy latency on 2 CPU cores and 16 about 4x, which would take `facaid.reconstruct` past its 1 s budget.
DEFAULT_K = 8
MAX_K = 32  # the most candidates a job may ask for
TEMPERATURE = 0.7  # exact structure 64.5 % at 0.7 against 61.5 % at 1.0 (same facades, best of 16)
