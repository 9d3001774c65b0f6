"""The decoder step in C (`facaid.decoding.step`): the same logits as the torch decoder, and a clean fallback."""

import pytest
import torch

import facaid.native
from facaid.decoding import decode
from facaid.decoding import step as native
from facaid.generator import generate
from facaid.model import batch_inputs, batch_outputs
from facaid.model.decoder import DecoderState
from facaid.training.surgery import with_box_bias

pytestmark = pytest.mark.skipif(native.library() is None, reason="no C compiler to build the native step")


@pytest.fixture(scope="module")
def models(tiny):
    model, tok = tiny
    biased = with_box_bias(model)
    biased.box_scale.data = torch.tensor([3.0, -2.0])
    return {"plain": model, "biased": biased}, tok


@pytest.mark.parametrize("kind", ["plain", "biased"])
@pytest.mark.parametrize(("k", "threads"), [(1, 1), (3, 1), (9, 2), (16, 3)])
def test_native_step_gives_the_teacher_forced_logits(models, kind, k, threads):
    """Each row its own sequence (other facades' trees), so that rows read from another row's cache or mask
    (the shards' offsets) would show; 9 rows on two threads are shards of 4 and 5, 16 on three 5, 5 and 6."""
    by_kind, tok = models
    model = by_kind[kind]
    sample = generate(4)
    rects, mask = batch_inputs([tok.encode_segmentation(sample.segmentation)])
    ids, local, _, boxes = batch_outputs([tok.encode_target(generate(4 + r).procedure) for r in range(k)])
    ids, local, boxes = ids[:, :50], local[:, :50], boxes[:, :50]
    with torch.no_grad():
        memory, memory_mask = model.encode(rects, mask)
        memory_boxes = model.memory_boxes(rects) if model.box_scale is not None else None
        full = model.decode(ids, local, memory.repeat(k, 1, 1), memory_mask.repeat(k, 1), boxes=boxes,
                               memory_boxes=None if memory_boxes is None else memory_boxes.repeat(k, 1, 1))
        fast = native.NativeDecoder(model, memory, memory_mask, max_len=64, rows=k, memory_boxes=memory_boxes,
                                    threads=threads)
        assert fast.n_shards == {1: 1, 3: 1, 9: 2, 16: 3}[k]
        x = model.embed_outputs(ids, local, boxes)
        steps = torch.stack([fast.step(x[:, i], boxes[:, i]) for i in range(x.shape[1])], 1)
    assert torch.allclose(steps, full, atol=1e-5)
    with pytest.raises(ValueError, match="x must be float32"):
        fast.step(x[:1, 0, :3], boxes[:, 0])


def test_native_step_masks_padded_memory(models):
    """A padding position of the memory (a bool mask from `encode`) must get no attention, as in torch."""
    by_kind, tok = models
    model = by_kind["plain"]
    rects, mask = batch_inputs([tok.encode_segmentation(generate(5).segmentation)])
    with torch.no_grad():
        memory, memory_mask = model.encode(rects, mask)
        memory_mask = memory_mask.clone()
        memory_mask[0, -3:] = False
        memory[0, -3:] = 50.0  # would dominate the attention if it were read
        a = DecoderState(model, memory, memory_mask, max_len=16)
        b = native.NativeDecoder(model, memory, memory_mask, max_len=16)
        x = torch.randn(12, 1, memory.shape[-1], generator=torch.Generator().manual_seed(0))
        for step in x:
            assert torch.allclose(a.step(step), b.step(step), atol=1e-5)
        with pytest.raises(ValueError, match="at most 16 positions"):
            for step in torch.zeros(5, 1, memory.shape[-1]):
                b.step(step)


@pytest.fixture(scope="module")
def shipped():
    from facaid.model import load_model
    from facaid.paths import DEFAULT_CHECKPOINT

    return load_model(DEFAULT_CHECKPOINT)


def test_shipped_model_logits_match_the_torch_step(shipped):
    """The shipped weights have the activations the C step must get right (softmax and GELU over real ranges):
    its logits along a real facade's sequence against the torch step's."""
    model, tok = shipped
    sample = generate(3)
    rects, mask = batch_inputs([tok.encode_segmentation(sample.segmentation)])
    ids, local, _, boxes = batch_outputs([tok.encode_target(sample.procedure)])
    with torch.no_grad():
        memory, memory_mask = model.encode(rects, mask)
        memory_boxes = model.memory_boxes(rects)
        a = DecoderState(model, memory, memory_mask, max_len=ids.shape[1], memory_boxes=memory_boxes)
        b = native.NativeDecoder(model, memory, memory_mask, max_len=ids.shape[1], memory_boxes=memory_boxes)
        x = model.embed_outputs(ids, local, boxes)
        worst = max(float((a.step(x[:, i], boxes[:, i]) - b.step(x[:, i], boxes[:, i])).abs().max())
                    for i in range(x.shape[1]))
    assert worst < 1e-4


def test_shipped_model_decodes_the_same_with_the_native_step(shipped):
    model, tok = shipped
    for seed in (0, 1, 2):
        seg = generate(seed).segmentation
        a = decode(model, tok, seg, native=False)[0]
        b = decode(model, tok, seg)[0]
        assert a.ids == b.ids and b.logprob == pytest.approx(a.logprob, abs=1e-3)


def test_best_of_k_samples_the_same_on_sharded_native_steps(shipped):
    """Best of K steps its rows in shards on torch's threads, with torch held to one thread meanwhile: the same
    samples as the torch step, and torch's setting back afterwards."""
    model, tok = shipped
    seg = generate(1).segmentation
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        a = decode(model, tok, seg, k=8, sample=True, greedy=1, temperature=0.7, seed=3, native=False)
        b = decode(model, tok, seg, k=8, sample=True, greedy=1, temperature=0.7, seed=3)
        assert torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)
    assert len({tuple(c.ids) for c in a}) > 2  # the rows differ, so a row read from another would show
    assert [c.ids for c in a] == [c.ids for c in b]
    assert [c.logprob for c in b] == pytest.approx([c.logprob for c in a], abs=1e-3)


def test_torch_threads_restores_the_setting():
    before = torch.get_num_threads()
    with native.torch_threads(1):
        assert torch.get_num_threads() == 1
    assert torch.get_num_threads() == before
    with pytest.raises(KeyError), native.torch_threads(1):
        raise KeyError("inside")
    assert torch.get_num_threads() == before


def test_without_the_library_decoding_keeps_torch(models, monkeypatch):
    by_kind, tok = models
    seg = generate(4).segmentation
    expected = decode(by_kind["biased"], tok, seg)[0].ids
    monkeypatch.setenv("FACAID_NATIVE", "0")
    assert native.library() is None
    rects, mask = batch_inputs([tok.encode_segmentation(seg)])
    memory, memory_mask = by_kind["plain"].encode(rects, mask)
    assert native.native_decoder(by_kind["plain"], memory, memory_mask, 16) is None
    monkeypatch.delenv("FACAID_NATIVE")
    assert native.native_decoder(by_kind["plain"], memory.double(), memory_mask, 16) is None  # float32 only
    assert native.native_decoder(by_kind["plain"], memory.repeat(2, 1, 1), memory_mask.repeat(2, 1), 16) is None
    assert native.native_decoder(by_kind["plain"], memory, memory_mask, 16) is not None
    assert decode(by_kind["biased"], tok, seg)[0].ids == expected


def test_build_is_cached_and_reports_a_failing_compiler(tmp_path, monkeypatch):
    monkeypatch.setenv("FACAID_CACHE", str(tmp_path))
    path = facaid.native.build("step")
    assert path.parent == tmp_path / "native" and path.is_file()
    assert facaid.native.build("step") == path  # built once per source, flags and machine
    path.unlink()
    with pytest.raises(RuntimeError, match="failed"):
        facaid.native.build("step", compiler="false")  # exits 1, as a broken compiler would
    assert not list((tmp_path / "native").iterdir())  # nothing half-written is left


def test_a_forked_child_makes_its_own_shard_threads():
    """A pool's threads do not survive a fork (a prefork worker, a forking server): the child starts a new one."""
    import os

    pool = native._shared_pool(1)
    assert pool.submit(lambda: 41 + 1).result() == 42
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: report whether it inherited the pool and whether a new one runs, then leave
        ok = native._pool is None and native._shared_pool(1).submit(lambda: 7).result(timeout=10) == 7
        os.write(write, b"1" if ok else b"0")
        os._exit(0)
    os.close(write)
    got = os.read(read, 1)
    os.waitpid(pid, 0)
    assert got == b"1"
    assert native._pool is pool
