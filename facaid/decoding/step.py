"""The decoder step in C (`facaid/native/step.c`), built on first use with the machine's C compiler.

Greedy decoding takes a few hundred steps of one token, and a step is some 80 torch operations on vectors of
128: their fixed cost, not the arithmetic, sets the time. `NativeDecoder` does the whole step in one call of a
small C function (the same arithmetic as `facaid.model.decoder.DecoderState.step`; the tests check the logits to
1e-5). It takes K rows of one input: greedy decoding steps one row (0.56x the torch step's time), best of K
steps K rows split into `threads` shards, each shard one call on its own thread (ctypes lets go of the GIL for
the call), while torch itself is held to one thread (`torch_threads`), so that its OpenMP workers, which spin
for a while after each parallel region, do not take the cores the shards run on.

The library is built by `facaid.native.load`; without it (no C compiler, or ``FACAID_NATIVE=0``) `native_decoder`
returns None and decoding keeps the torch path.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import torch

from facaid.model import FacaidModel
from facaid.model.decoder import DecoderState
from facaid.native.build import load

_pool: ThreadPoolExecutor | None = None
_pool_size = 0


def _declare(lib: ctypes.CDLL) -> None:
    lib.facaid_step.restype = ctypes.c_int
    lib.facaid_step.argtypes = [  # pointers as plain addresses: ints convert fastest
        ctypes.c_int, ctypes.c_void_p, ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_int,
        ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
        ctypes.c_long, ctypes.c_long, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
        ctypes.c_float, ctypes.c_void_p, ctypes.c_void_p]


def library() -> ctypes.CDLL | None:
    """The loaded step library, built if needed; None (once logged) when it cannot be had or is switched off."""
    return load("step", _declare)


def _array(t: torch.Tensor) -> np.ndarray:
    """A C-contiguous float32 numpy copy or view of a tensor."""
    return np.ascontiguousarray(t.detach().to(torch.float32).cpu().numpy())


def _shared_pool(workers: int) -> ThreadPoolExecutor:
    """The threads the shards beyond the first run on, made once per process (and again for more shards)."""
    global _pool, _pool_size
    if _pool is None or _pool_size < workers:
        _pool, _pool_size = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="facaid-native"), workers
    return _pool


def _forget_pool() -> None:
    global _pool, _pool_size
    _pool, _pool_size = None, 0  # a forked child has none of its parent's threads


os.register_at_fork(after_in_child=_forget_pool)


@contextlib.contextmanager
def torch_threads(n: int):
    """Run the block with torch on ``n`` threads, then restore the setting."""
    before = torch.get_num_threads()
    if n == before:
        yield
        return
    torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(before)


class NativeDecoder(DecoderState):
    """`DecoderState` whose `step` is one call of the C step per shard of rows (``threads`` shards of at
    least four rows, run at once). Only for rows that read one memory row (what `decode` builds); the
    cross-attention keys and values, caches and masks are the parent's, read in place."""

    def __init__(self, model: FacaidModel, memory: torch.Tensor, memory_mask: torch.Tensor, max_len: int,
                 rows: int | None = None, memory_boxes: torch.Tensor | None = None, lib: ctypes.CDLL | None = None,
                 threads: int = 1):
        reason = _unsupported(model, memory)
        if reason:
            raise ValueError(reason)
        self.lib = lib or library()
        if self.lib is None:
            raise RuntimeError("the native step library is unavailable")
        super().__init__(model, memory, memory_mask, max_len, rows=rows, memory_boxes=memory_boxes)
        self.ffn = self.blocks[0].fc_w.shape[1]
        self.m = memory.shape[1]
        self.keep: list[np.ndarray] = []  # every array the pointers point into
        self.n_shards = max(1, min(threads, self.k // 4))
        bounds = [self.k * i // self.n_shards for i in range(self.n_shards + 1)]
        ranges = list(zip(bounds[:-1], bounds[1:], strict=True))  # each shard's rows [first, end)
        pointers: list[list[int]] = [[] for _ in ranges]  # per shard: every block's pointers
        for w, (ck, cv), (kv, _, _) in zip(self.blocks, self.cross, self.cache, strict=True):
            arrays = [w.ln_1[0], w.ln_1[1], w.attn_w, w.attn_b, w.attn_proj_w, w.attn_proj_b,
                      w.ln_cross[0], w.ln_cross[1], w.cross_q_w, w.cross_q_b, w.cross_proj_w, w.cross_proj_b,
                      w.ln_2[0], w.ln_2[1], w.fc_w, w.fc_b, w.mlp_proj_w, w.mlp_proj_b]
            arrays = [_array(t) for t in arrays]
            arrays.append(_array(ck[0].transpose(1, 2)))  # (H, dh, M)
            arrays.append(_array(cv[0]))  # (H, M, dh)
            cache = kv.numpy()  # the parent's buffer, read as keys (K, H, dh, L) and values (K, H, L, dh)
            self.keep += arrays + [cache]
            for shard, (first, _) in zip(pointers, ranges, strict=True):  # the self caches from its first row
                shard += [a.ctypes.data for a in arrays] + [cache[0, first:].ctypes.data, cache[1, first:].ctypes.data]
        wpe = _array(self.wpe)
        ln_f = [_array(a) for a in self.ln_f]
        head_t = _array(self.head[0].t())  # (d, V)
        head_b = None if self.head[1] is None else _array(self.head[1])
        self.vocab = head_t.shape[1]
        # per shard: (first row, rows, block pointers, work buffer of what step.c uses: rows * (6 d + f) + max(L, M))
        self.shards = [(first, end - first, (ctypes.c_void_p * len(ptrs))(*ptrs),
                        np.empty((end - first) * (6 * self.d + self.ffn) + max(self.max_len, self.m), dtype=np.float32))
                       for (first, end), ptrs in zip(ranges, pointers, strict=True)]
        self.keep += [wpe, *ln_f, head_t] + ([] if head_b is None else [head_b])
        self.wpe_at = wpe.ctypes.data
        self.head_args = (ln_f[0].ctypes.data, ln_f[1].ctypes.data, head_t.ctypes.data,
                          None if head_b is None else head_b.ctypes.data, self.eps)
        self.pool = _shared_pool(self.n_shards - 1) if self.n_shards > 1 else None
        self.mask_np: tuple[torch.Tensor | None, np.ndarray | None, int, int] = (None, None, 0, 0)

    def _mask_array(self, mask: torch.Tensor | None) -> tuple[np.ndarray | None, int, int]:
        """The step's mask as a contiguous array with its head and row strides (0 where broadcast); converted
        once while the parent returns the same mask tensor (the tokens of one node)."""
        if mask is None:
            return None, 0, 0
        if self.mask_np[0] is mask:
            return self.mask_np[1:]
        a = _array(mask[0])  # (H or 1, K or 1, M), additive (`DecoderState` builds it so)
        h_stride = 0 if a.shape[0] == 1 else a.shape[1] * self.m
        r_stride = 0 if a.shape[1] == 1 else self.m
        self.mask_np = (mask, a, h_stride, r_stride)
        return a, h_stride, r_stride

    @torch.inference_mode()
    def step(self, x: torch.Tensor, boxes: torch.Tensor | None = None) -> torch.Tensor:
        if self.t >= self.max_len:
            raise ValueError(f"the decoder holds at most {self.max_len} positions")
        if x.shape != (self.k, self.d) or x.dtype != torch.float32 or x.device.type != "cpu":
            raise ValueError(f"x must be float32 ({self.k}, {self.d}) on the CPU, got {x.dtype} {tuple(x.shape)}")
        mask, mask_h, mask_r = self._mask_array(self.cross_mask(boxes))
        x = x.contiguous()
        out = torch.empty((self.k, self.vocab))
        wpe_t = self.wpe_at + 4 * self.d * self.t
        calls = []
        for first, n, pointers, work in self.shards:
            at_mask = None if mask is None else mask.ctypes.data + 4 * first * mask_r
            calls.append((len(self.blocks), pointers, n, self.d, self.heads, self.ffn, self.m, self.max_len, self.t,
                          self.vocab, x.data_ptr() + 4 * first * self.d, wpe_t, at_mask, mask_h, mask_r,
                          *self.head_args, work.ctypes.data, out.data_ptr() + 4 * first * self.vocab))
        others = [self.pool.submit(self.lib.facaid_step, *args) for args in calls[1:]] if self.pool else []
        codes = [self.lib.facaid_step(*calls[0])] + [f.result() for f in others]
        if any(codes):
            raise RuntimeError(f"native step failed with codes {codes}")
        self.t += 1
        return out


def _unsupported(model: FacaidModel, memory: torch.Tensor) -> str | None:
    """Why the C step cannot run this model on this memory, or None when it can."""
    if memory.shape[0] != 1 or memory.dtype != torch.float32:
        return "the native step reads one float32 memory row shared by all decoded rows"
    if memory.device.type != "cpu" or next(model.parameters()).device.type != "cpu":
        return "the native step runs on the CPU"
    return None


def native_decoder(model: FacaidModel, memory: torch.Tensor, memory_mask: torch.Tensor, max_len: int,
                   rows: int | None = None, memory_boxes: torch.Tensor | None = None,
                   threads: int = 1) -> NativeDecoder | None:
    """A `NativeDecoder` when the C step is available and applies (one float32 memory row on the CPU), else
    None."""
    if _unsupported(model, memory):
        return None
    lib = library()
    if lib is None:
        return None
    return NativeDecoder(model, memory, memory_mask, max_len, rows=rows, memory_boxes=memory_boxes, lib=lib,
                         threads=threads)
