from collections import deque

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from facaid.generator import STYLE_NAMES, generate
from facaid.grammar import Node, Procedure, Size, execute, validate
from facaid.grammar.execute import first_boxes
from facaid.tokenizer import BOS, EOS, TokenError, TokenGrammar, Tokenizer, TokenizerConfig, peer_counts

TOK = Tokenizer(TokenizerConfig(max_rects=2000, max_out=2000))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**63), st.sampled_from(STYLE_NAMES))
def test_procedure_tokens_round_trip(seed, style):
    proc = generate(seed, style).procedure
    ids, local = TOK.encode_procedure(proc)
    assert ids[0] == BOS and ids[-1] == EOS
    assert Tokenizer.local_indices(ids, TOK.vocab) == local
    back = TOK.decode_procedure(ids, proc.width, proc.height)
    validate(back)
    assert TOK.encode_procedure(back)[0] == ids  # tokens are a fixed point
    # same structure, sizes within quantization: the executions agree to a few pixels
    a, b = execute(proc), execute(back)
    assert [x[0] for x in a] == [x[0] for x in b]
    err = np.abs(np.array([x[1:] for x in a]) - np.array([x[1:] for x in b])).max()
    assert err < 0.05 * max(proc.width, proc.height)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**63), st.sampled_from(STYLE_NAMES))
def test_node_boxes_are_the_executed_first_instances(seed, style):
    proc = generate(seed, style).procedure
    ids, local, boxes = TOK.encode_target(proc)
    assert boxes.shape == (len(ids), 4)
    back = TOK.decode_procedure(ids, proc.width, proc.height)  # what the decoder has read: quantized sizes
    first = first_boxes(back)
    order, queue = [], deque([back.root])
    while queue:
        node = queue.popleft()
        order.append(node)
        queue.extend(node.children)
    starts = [i for i, k in enumerate(local) if k == 0 and 0 < i < len(ids) - 1]  # node groups
    expected = TOK.quantize_boxes(np.array([first[id(n)] for n in order]), proc.width, proc.height)
    # the box rides on the token *before* each group (it tells the decoder which node comes next) and on
    # every token of the group but its last
    assert (boxes[np.array(starts) - 1] == expected).all()
    assert (boxes[-2] == 0).all() and boxes[0].tolist() == [0, 0, 128, 128]


def test_segmentation_rows_sorted_bottom_up():
    seg = generate(5).segmentation
    rows = TOK.encode_segmentation(seg)
    assert rows[0, 0] == 12  # the <image> row
    keys = [(y, x) for _, x, y, _, _ in rows[1:].tolist()]
    assert keys == sorted(keys)
    assert rows[:, 1:].min() >= 0 and rows[1:, 1:3].max() < 128 and rows[1:, 3:].max() <= 128


def test_peer_counts_of_a_window_grid():
    # 3 floors of 4 windows (y down) and one door, on a wall
    windows = [[2, 20 + 100 * c, 20 + 100 * f, 80 + 100 * c, 80 + 100 * f] for f in range(3) for c in range(4)]
    rows = [[1, 0, 0, 400, 300], *windows, [3, 170, 240, 230, 300]]
    counts = peer_counts(np.array(rows))
    assert counts[0].tolist() == [1, 0, 1, 0]  # the wall, alone
    assert counts[-1].tolist() == [1, 0, 1, 0]  # the door: not a peer of the windows
    for i, (f, c) in enumerate((f, c) for f in range(3) for c in range(4)):
        # 4 in its floor, c-th from the left; 3 in its column, floor 0 is the top so it ranks 2 from the bottom
        assert counts[1 + i].tolist() == [4, c, 3, 2 - f]
    # edges moved by up to 12 px (a fifth of a window): peers by overlap, so the same counts
    moved = np.array(rows) + np.random.default_rng(0).integers(-12, 13, (len(rows), 5)) * [0, 1, 1, 1, 1]
    assert (peer_counts(moved) == counts).all()


def test_shape_peers_leave_out_the_next_building_in_the_row():
    # one row across two buildings: 4 windows 60 px wide from y 100 to 180, then 3 windows 40 px wide from 110
    # to 170 (another floor height): by overlap all 7 are peers, by shape 4 and 3; an odd window among the 4
    # (twice as wide) is a peer of none by shape
    left = [[2, 20 + 100 * c, 100, 80 + 100 * c, 180] for c in range(4)]
    right = [[2, 420 + 70 * c, 110, 460 + 70 * c, 170] for c in range(3)]
    rows = np.array([*left, *right])
    overlap, shape = peer_counts(rows, "overlap"), peer_counts(rows, "shape")
    assert overlap[:, 0].tolist() == [7] * 7 and overlap[:, 1].tolist() == list(range(7))
    assert shape[:, 0].tolist() == [4] * 4 + [3] * 3 and shape[:, 1].tolist() == [0, 1, 2, 3, 0, 1, 2]
    assert shape[:, 2].tolist() == [1] * 7  # one per column
    wide = rows.copy()
    wide[1, 3] += 60
    assert peer_counts(wide, "shape")[:, 0].tolist() == [3, 1, 3, 3, 3, 3, 3]
    # edges moved by up to 8 px (a tenth of a window's height): the same counts
    moved = rows + np.random.default_rng(1).integers(-4, 5, rows.shape) * [0, 1, 1, 1, 1]
    assert (peer_counts(moved, "shape") == shape).all()
    with pytest.raises(ValueError, match="peer rule must be one of overlap, shape"):
        peer_counts(rows, "size")


def test_two_peer_rules_give_eight_count_fields():
    seg = generate(5).segmentation
    both = Tokenizer(TokenizerConfig(max_rects=2000, count_features=True, peer_rule="overlap+shape"))
    one = Tokenizer(TokenizerConfig(max_rects=2000, count_features=True))
    rows = both.encode_segmentation(seg)
    assert both.config.input_fields == rows.shape[1] == 13 and len(both.input_vocab_sizes) == 13
    assert (rows[:, :9] == one.encode_segmentation(seg)).all()
    for bad in ("shape+shape", "overlap+", "size"):
        with pytest.raises(ValueError, match="peer_rule must be one or more of overlap, shape"):
            TokenizerConfig(peer_rule=bad)


def test_peer_counts_ride_on_the_rows():
    seg = generate(5).segmentation
    counting = Tokenizer(TokenizerConfig(max_rects=2000, max_out=2000, count_features=True))
    rows = counting.encode_segmentation(seg)
    assert rows.shape[1] == 9 and (rows[:, :5] == TOK.encode_segmentation(seg)).all()
    assert rows[0, 5:].tolist() == [0, 0, 0, 0]
    assert (rows[1:, 5] >= 1).all() and (rows[1:, 6] < rows[1:, 5]).all() and (rows[1:, 8] < rows[1:, 7]).all()
    with pytest.raises(ValueError, match="count_features need rect_tokens = 1"):
        TokenizerConfig(rect_tokens=5, count_features=True)


def test_too_many_rectangles_is_a_clear_error():
    small = Tokenizer(TokenizerConfig(max_rects=3))
    with pytest.raises(ValueError, match="too many rectangles for the model"):
        small.encode_segmentation(generate(1).segmentation)


def test_fill_repeats_are_encoded_with_their_resolved_count():
    root = Node.repeat("x", "fill", [(Size("flt", 40), Node.leaf("window"))])
    ids, _ = TOK.encode_procedure(Procedure(400, 50, root))
    assert "count:10" in [TOK.vocab.tokens[i] for i in ids]


def test_grammar_rejects_bad_sequences_with_position():
    v = TOK.vocab
    g = TokenGrammar(v, 100, 100)
    with pytest.raises(TokenError, match=r"token 1 \(role:tile\) is not allowed here"):
        g.step(v.id("role:tile"))
    g = TokenGrammar(v, 100, 100)
    g.step(v.id("repeat_x"))
    g.step(v.id("role:none"))
    g.step(v.id("count:3"))
    g.step(v.id("abs:10"))
    with pytest.raises(TokenError, match="end:1"):
        g.step(v.id("end:1"))  # a tail must be shorter than the pattern
    with pytest.raises(TokenError, match="ended before <eos>"):
        TOK.decode_procedure([BOS, v.id("split_x")], 10, 10)


def test_save_and_load(tmp_path):
    TOK.save(tmp_path / "tokenizer.json")
    assert Tokenizer.load(tmp_path / "tokenizer.json").vocab.tokens == TOK.vocab.tokens
    text = (tmp_path / "tokenizer.json").read_text().replace("facaid-split-1", "facaid-split-0")
    (tmp_path / "old.json").write_text(text)
    with pytest.raises(ValueError, match="made for grammar 'facaid-split-0'"):
        Tokenizer.load(tmp_path / "old.json")
