"""Decoding defaults shared by the library, the command line, the worker and the site, in a module that
imports nothing (the web process and the command-line parser need them without loading torch)."""

# Best-of-K decoding: the greedy candidate and K - 1 samples at TEMPERATURE, ranked by
# `facaid.decoding.rank_key`. On 200 held-out facades (dataset seed 3000) the exact-structure rate was 58.0 %
# greedy, 62-63 % best of 8 and 61.5-64.5 % best of 16 (two draws of samples). The K rows share the input's
# cross-attention (`facaid.model.decoder.DecoderState`), so decoding 16 costs about 2.8x the greedy latency on
# 2 CPU cores and 8 about 1.9x; `facaid.reconstruct` takes as long with 16 as with 8 (bench/bench_reconstruct.py).
DEFAULT_K = 16
MAX_K = 32  # the most candidates a job may ask for
TEMPERATURE = 0.7  # exact structure 64.5 % at 0.7 against 61.5 % at 1.0 (same facades, best of 16)
# Decoded floors: neighbouring floors with the same tree whose sizes agree within this fraction are written as one
# repeat, as the canonical trees write them (`facaid.grammar.floors.merge_repeated_floors`). On 150 facades
# of dataset seed 7777, best of 16: TED <= 5 84.7 % at 0.2-0.3 and with no size check, 84.0 % at 0.05-0.1,
# 82.7 % unmerged. Floors further apart than this stay apart, so a real facade's taller floor keeps its height.
FLOOR_TOLERANCE = 0.25

# completion (facaid.completion): proposals scored lower are not returned; chosen on the CMP dev half with
# bench/bench_assist.py (a simulated annotator)
DEFAULT_MIN_SCORE = 0.85
DEFAULT_MIN_COPY = 0.6  # the copies of a unit (`completion.copies`) scored below this are not returned unless asked for
# the two procedures of a real reconstruction (`facaid.pipeline.reconstruct`): floors of tiles with exceptions, what
# the named parameters edit (the default), and the annotation as drawn
STRUCTURES = ("editable", "exact")
