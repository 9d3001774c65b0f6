import numpy as np
import pytest
import torch
from hypothesis import example, given, settings
from hypothesis import strategies as st

from facaid.decoding import (
    Candidate,
    GrammarLogitsProcessor,
    best_of_k,
    decode,
    prefix_from_procedure,
    rank_key,
    ranked_candidates,
    score,
)
from facaid.generator import generate
from facaid.grammar import Procedure, execute, validate
from facaid.model import FacaidConfig, FacaidModel
from facaid.tokenizer import BOS, EOS, PAD, TokenGrammar, Tokenizer, TokenizerConfig

CONFIG = TokenizerConfig(max_rects=1000, max_out=160)
TOK = Tokenizer(CONFIG)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(40, 160))
@example(1383, 90)  # once offered a repeat whose smallest expansion overran the leaf budget
@example(612811, 139)  # a split's last child ended 1e-13 before it began (rounding), and laying it out divided by 0
def test_random_logits_always_give_a_valid_procedure(seed, max_len):
    rng = np.random.default_rng(seed)
    proc = GrammarLogitsProcessor(TOK, [(300.0, 200.0)], max_len=max_len)
    ids = [BOS]
    while True:
        scores = torch.from_numpy(rng.normal(0, 3, size=(1, len(TOK.vocab))).astype(np.float32))
        masked = proc(torch.tensor([ids]), scores)
        assert torch.equal(torch.isfinite(masked), torch.from_numpy(proc.mask()))
        if proc.finished(0):
            break
        ids.append(int(masked.argmax()))
    assert ids[-1] == EOS and len(ids) <= max_len
    result = TOK.decode_procedure(ids, 300, 200)
    validate(result)
    assert len(execute(result)) >= 1


def test_the_processor_constrains_hugging_face_generate():
    """`GrammarLogitsProcessor` is a ``transformers.LogitsProcessor``: inside ``generate`` it makes a small random
    decoder-only model (GPT-2 shaped, untrained) write valid procedures, greedy and sampled, and without it the
    same model writes none."""
    from transformers import GPT2Config, GPT2LMHeadModel, LogitsProcessor, LogitsProcessorList

    torch.manual_seed(0)
    lm = GPT2LMHeadModel(GPT2Config(vocab_size=len(TOK.vocab), n_positions=200, n_embd=32, n_layer=1, n_head=2,
                                    bos_token_id=BOS, eos_token_id=EOS, pad_token_id=PAD)).eval()
    sizes = [(300.0, 200.0), (120.0, 400.0), (640.0, 480.0)]
    for sample in (False, True):
        processor = GrammarLogitsProcessor(TOK, sizes, max_len=120)
        assert isinstance(processor, LogitsProcessor)
        out = lm.generate(torch.full((3, 1), BOS), logits_processor=LogitsProcessorList([processor]),
                          max_new_tokens=119, do_sample=sample, top_k=0, eos_token_id=EOS, pad_token_id=PAD,
                          attention_mask=torch.ones(3, 1, dtype=torch.long))
        for row, (w, h) in zip(out.tolist(), sizes, strict=True):
            ids = row[: row.index(EOS) + 1]
            proc = TOK.decode_procedure(ids, w, h)
            validate(proc)
            assert len(execute(proc)) >= 1
    free = lm.generate(torch.full((3, 1), BOS), max_new_tokens=40, do_sample=False, pad_token_id=PAD,
                       attention_mask=torch.ones(3, 1, dtype=torch.long))
    for row in free.tolist():
        with pytest.raises(ValueError):
            TOK.decode_procedure(row[: row.index(EOS) + 1] if EOS in row else row, 300.0, 200.0)


def test_a_rule_is_offered_only_where_its_smallest_expansion_fits_the_leaf_budget():
    v = TOK.vocab
    g = TokenGrammar(v, 300.0, 200.0)
    # three nested repeats: the next slot may be copied 65 * 65 * 9 = 38,025 times (a tail each), and 42,316
    # leaves are spoken for
    for rule, count in (("repeat_x", 64), ("repeat_y", 64), ("repeat_x", 8)):
        for token in (rule, "role:none", f"count:{count}", "abs:10", "end:0"):
            g.step(v.id(token))
    allowed = g.allowed()
    assert g.expanded == 42_316 and g.pending[0][2] == 38_025
    assert allowed[v.id("split_x")] and allowed[v.id("split_y")] and allowed[v.id("label:window")]
    # a repeat (count 1 and a tail) or a mirror would copy its child 76,050 times: over the 100,000 budget
    assert not any(allowed[v.id(r)] for r in ("repeat_x", "repeat_y", "mirror_x", "mirror_y"))
    for token in ("split_x", "role:none", "abs:10", "end:0", "label:window", "<eos>"):
        g.step(v.id(token))
    assert len(execute(g.procedure())) == 64 * 64 * 8  # the budget counts a tail's copy that none of these has


def test_mask_matches_an_explicit_boolean_matrix():
    v = TOK.vocab
    proc = GrammarLogitsProcessor(TOK, [(100.0, 100.0), (100.0, 100.0)])
    ids = torch.tensor([[BOS, v.id("split_y")], [BOS, v.id("label:window")]])
    scores = torch.zeros(2, len(v))
    out = proc(ids, scores)
    expected = np.zeros((2, len(v)), dtype=bool)
    expected[0, list(v.ranges["role"])] = True  # after a rule: its role
    expected[1, EOS] = True  # a lone leaf is a whole procedure
    assert np.array_equal(torch.isfinite(out).numpy(), expected)
    assert torch.equal(scores, torch.zeros(2, len(v)))  # a masked copy, never in place
    ids = torch.cat([ids, torch.tensor([[v.id("role:none")], [EOS]])], 1)
    out = proc(ids, torch.zeros(2, len(v)))
    assert torch.isfinite(out[1]).nonzero().flatten().tolist() == [PAD]


def test_processor_validates_its_arguments():
    with pytest.raises(ValueError, match="positive"):
        GrammarLogitsProcessor(TOK, [(0.0, 10.0)])
    proc = GrammarLogitsProcessor(TOK, [(10.0, 10.0)])
    with pytest.raises(ValueError, match=r"scores must be \(batch, "):
        proc(torch.tensor([[BOS]]), torch.zeros(1, 5))
    with pytest.raises(ValueError, match="expected 1 rows"):
        proc(torch.tensor([[BOS], [BOS]]), torch.zeros(2, len(TOK.vocab)))


def test_length_budget_closes_deep_trees():
    v = TOK.vocab
    g = TokenGrammar(v, 100, 100, max_len=12)
    g.step(v.id("split_x"))
    g.step(v.id("role:none"))
    for _ in range(3):
        g.step(v.id("flt:5"))
    allowed = g.allowed()
    assert allowed[v.id("end:0")]
    assert not allowed[v.id("flt:5")]  # a fourth child would not fit
    g.step(v.id("end:0"))
    assert not g.allowed()[v.id("split_y")]  # nor a new inner node


@pytest.fixture(scope="module")
def tiny_model():
    torch.manual_seed(0)
    return FacaidModel(FacaidConfig(d_model=16, encoder_layers=1, decoder_layers=1, heads=2, ffn=32, node_boxes=True,
                                    tokenizer=CONFIG.to_dict())).eval()


def test_decode_greedy_sampling_and_prefix(tiny_model):
    seg = generate(4).segmentation
    greedy = decode(tiny_model, TOK, seg, k=2)
    assert greedy[0].ids == greedy[1].ids
    samples = decode(tiny_model, TOK, seg, k=3, sample=True, seed=1)
    for c in greedy + samples:
        validate(c.procedure)
        assert c.ids[0] == BOS and c.ids[-1] == EOS and len(c.ids) <= CONFIG.max_out
        assert c.logprob <= 0
    assert decode(tiny_model, TOK, seg, k=3, sample=True, seed=1)[0].ids == samples[0].ids
    mixed = decode(tiny_model, TOK, seg, k=3, sample=True, seed=1, greedy=1)  # row 0 greedy, in the same batch
    assert mixed[0].ids == greedy[0].ids and mixed[0].logprob == pytest.approx(greedy[0].logprob)
    target = generate(4).procedure
    prefix = prefix_from_procedure(TOK, target, nodes=2)
    cont = decode(tiny_model, TOK, seg, prefix=prefix, max_len=400)[0]
    assert cont.ids[: len(prefix)] == prefix
    best = best_of_k(tiny_model, TOK, seg, k=3)
    assert 0.0 <= best.accuracy <= 1.0


@pytest.mark.parametrize("k, padded, shared", [(1, False, False), (3, False, False), (2, True, False),
                                               (3, False, True)])
def test_decoder_state_steps_give_the_teacher_forced_logits(tiny_model, k, padded, shared):
    """`facaid.model.decoder`: the blocks stepped with their key/value cache (one token a row, K rows on one memory row
    or their own) compute what the teacher-forced pass over the whole sequence computes."""
    from facaid.model import batch_inputs, batch_outputs
    from facaid.model.decoder import DecoderState

    samples = [generate(s) for s in (4, 5)[: 2 if padded else 1]]
    rows = [TOK.encode_segmentation(s.segmentation) for s in samples]
    rects, mask = batch_inputs(rows * (1 if padded else k))
    ids, local, _, boxes = batch_outputs([TOK.encode_target(s.procedure) for s in samples] * (1 if padded else k))
    ids, local, boxes = ids[:, :40], local[:, :40], boxes[:, :40]
    with torch.no_grad():
        memory, memory_mask = tiny_model.encode(rects, mask)
        assert bool(memory_mask.all()) != padded
        full = tiny_model.decode(ids, local, memory, memory_mask, boxes=boxes)
        if shared:  # K rows on one memory row: the K queries of a head attend in one product
            fast = DecoderState(tiny_model, memory[:1], memory_mask[:1], max_len=64, rows=k)
            assert fast.shared
        else:
            fast = DecoderState(tiny_model, memory, memory_mask, max_len=64)
        x = tiny_model.embed_outputs(ids, local, boxes)
        steps = torch.stack([fast.step(x[:, i]) for i in range(x.shape[1])], 1)
    assert torch.allclose(steps, full, atol=1e-5)
    with pytest.raises(ValueError, match="memory has 2 rows"):
        DecoderState(tiny_model, torch.zeros(2, 5, memory.shape[-1]), torch.ones(2, 5, dtype=torch.bool),
                           max_len=8, rows=3)


@pytest.fixture(scope="module")
def biased_model(tiny_model):
    from facaid.training.surgery import with_box_bias

    model = with_box_bias(tiny_model)
    model.box_scale.data = torch.tensor([3.0, -2.0])
    return model


@pytest.mark.parametrize("k, shared, padded", [(1, False, False), (3, True, False), (2, False, True)])
def test_decoder_state_applies_the_box_bias(tiny_model, biased_model, k, shared, padded):
    from facaid.model import batch_inputs, batch_outputs
    from facaid.model.decoder import DecoderState

    samples = [generate(4), generate(5)] if padded else [generate(4)] * k
    rects, mask = batch_inputs([TOK.encode_segmentation(s.segmentation) for s in samples])
    ids, local, _, boxes = batch_outputs([TOK.encode_target(s.procedure) for s in samples])
    ids, local, boxes = ids[:, :40], local[:, :40], boxes[:, :40]
    with torch.no_grad():
        memory, memory_mask = biased_model.encode(rects, mask)
        assert bool(memory_mask.all()) != padded
        memory_boxes = biased_model.memory_boxes(rects)
        full = biased_model.decode(ids, local, memory, memory_mask, boxes=boxes, memory_boxes=memory_boxes)
        plain = tiny_model.decode(ids, local, memory, memory_mask, boxes=boxes)
        assert not torch.allclose(full, plain, atol=1e-3)  # the same weights but the bias
        rows = 1 if shared else k
        fast = DecoderState(biased_model, memory[:rows], memory_mask[:rows], max_len=64, rows=k,
                                  memory_boxes=memory_boxes[:rows])
        x = biased_model.embed_outputs(ids, local, boxes)
        steps = torch.stack([fast.step(x[:, i], boxes[:, i]) for i in range(x.shape[1])], 1)
    with pytest.raises(ValueError, match="pass each row's box"):
        fast.step(x[:, 0])
    assert torch.allclose(steps, full, atol=1e-5)
    with pytest.raises(ValueError, match="pass memory_boxes"):
        DecoderState(biased_model, memory, memory_mask, max_len=8)


@pytest.mark.parametrize("native, sample", [(True, True), (False, True), (False, False)])
def test_decoded_log_probability_is_the_teacher_forced_one(biased_model, native, sample):
    """`decode` keeps a node's box, its embedding and its cross-attention bias while the node's tokens last;
    teacher forcing the decoded sequence recomputes all of them at every position and must give the same
    masked log-probability (greedy alone takes each token and its log-probability from one ``max``)."""
    from facaid.model import MAX_LOCAL, batch_inputs

    seg = generate(6).segmentation
    rects, mask = batch_inputs([TOK.encode_segmentation(seg)])
    candidates = decode(biased_model, TOK, seg, k=3 if sample else 1, sample=sample, seed=2, greedy=1,
                        merge_floors=False, native=native)
    for c in candidates:
        inputs = c.ids[:-1]
        local = torch.tensor([TOK.local_indices(inputs, TOK.vocab)]).clamp(max=MAX_LOCAL - 1)
        boxes = torch.as_tensor(TOK.node_boxes(inputs, seg.width, seg.height))[None]
        with torch.no_grad():
            memory, memory_mask = biased_model.encode(rects, mask)
            logits = biased_model.decode(torch.tensor([inputs]), local, memory, memory_mask, boxes=boxes,
                                            memory_boxes=biased_model.memory_boxes(rects))
        grammar = TokenGrammar(TOK.vocab, seg.width, seg.height, CONFIG.max_out)
        total = 0.0
        for t, token in enumerate(c.ids[1:]):
            allowed = torch.from_numpy(grammar.allowed())
            total += float(torch.log_softmax(logits[0, t].masked_fill(~allowed, float("-inf")), -1)[token])
            grammar.step(token)
        assert grammar.done
        assert total == pytest.approx(c.logprob, abs=1e-4)
    if sample:
        assert len({tuple(c.ids) for c in candidates}) > 1  # the samples differ: more than one path was checked


def _candidate(accuracy: float, count_error: int, logprob: float) -> Candidate:
    return Candidate([BOS, EOS], logprob, None, accuracy=accuracy, count_error=count_error)


def test_rank_key_weighs_element_counts_against_accuracy_then_likelihood():
    key = rank_key
    assert key(_candidate(0.95, 0, -30.0)) > key(_candidate(0.97, 4, -10.0))  # a wrong count costs more
    assert key(_candidate(0.951, 0, -10.0)) > key(_candidate(0.954, 0, -20.0))  # a near tie: the likelier
    assert key(_candidate(0.96, 0, -30.0)) > key(_candidate(0.94, 0, -10.0))  # two points are not a tie
    assert key(_candidate(0.96, 1, -10.0)) > key(_candidate(0.94, 0, -30.0))  # one element for two points


def test_score_counts_the_elements_a_wrong_repeat_count_adds():
    sample = next(s for s in map(generate, range(100)) if any(map(_fewer_possible, s.procedure.nodes())))
    exact = Candidate([BOS, EOS], 0.0, sample.procedure)
    assert score(exact, sample.segmentation) > 0.95 and exact.count_error == 0  # 1/4 scale: edges round
    wrong = Procedure.from_dict(sample.procedure.to_dict())
    _, node = next(filter(_fewer_possible, wrong.nodes()))
    node.count -= 1
    off = Candidate([BOS, EOS], 0.0, wrong)
    score(off, sample.segmentation)
    assert off.count_error > 0 and off.accuracy < exact.accuracy


def _fewer_possible(item) -> bool:
    """A repeat with a count above 1 whose pattern holds an element: one copy fewer shows fewer elements."""
    _, node = item
    return (node.rule == "repeat" and node.count != "fill" and node.count > 1
            and any(n.rule == "leaf" and n.label not in ("facade", "background") for _, n in node.walk()))


def test_ranked_candidates_are_sorted_by_rank_key(tiny_model):
    seg = generate(4).segmentation
    ranked = ranked_candidates(tiny_model, TOK, seg, k=5, seed=2, compose=False)
    assert len(ranked) == 5 and all(c.count_error is not None and c.swaps == 0 for c in ranked)
    keys = [rank_key(c) for c in ranked]
    assert keys == sorted(keys, reverse=True)


def test_ranked_candidates_put_a_valid_composition_first(tiny_model):
    # (the untrained model's candidates rarely share a region; tests/test_shipped_model.py composes for sure)
    for s in range(6):
        seg = generate(s).segmentation
        plain = ranked_candidates(tiny_model, TOK, seg, k=6, seed=s, compose=False)
        ranked = ranked_candidates(tiny_model, TOK, seg, k=6, seed=s)
        first = ranked[0]
        if first.swaps:  # the composition, then the candidates as ranked without it
            assert [c.ids for c in ranked[1:]] == [c.ids for c in plain]
            assert first.procedure.meta["composed"] == first.swaps and first.logprob == plain[0].logprob
            validate(first.procedure)
            g = TokenGrammar(TOK.vocab, seg.width, seg.height)
            for t in first.ids[1:]:
                g.step(t)  # raises if the model could not have decoded it
            assert g.done and first.accuracy is not None
        else:
            assert [c.ids for c in ranked] == [c.ids for c in plain]
    prefix = prefix_from_procedure(TOK, generate(0).procedure, nodes=2)
    assert ranked_candidates(tiny_model, TOK, generate(0).segmentation, k=6, prefix=prefix)[0].swaps == 0
