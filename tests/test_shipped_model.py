import pytest

from facaid.generator import generate
from facaid.grammar import validate
from facaid.paths import DEFAULT_CHECKPOINT
from facaid.pipeline import default_model, reconstruct


@pytest.mark.skipif(not (DEFAULT_CHECKPOINT / "model.safetensors").is_file(), reason="no shipped checkpoint")
def test_shipped_model_loads_by_default_and_reconstructs():
    model, tokenizer = default_model()
    assert model.config.grammar == "facaid-split-1"
    seg = generate(21, "tenement").segmentation
    result = reconstruct(seg, k=2)  # the default model
    validate(result.procedure)
    assert result.accuracy >= result.accuracy_decoded
    assert result.accuracy > 0.8
    assert not result.shortcut  # a decoded structure near the input is sized, not passed over


@pytest.mark.skipif(not (DEFAULT_CHECKPOINT / "model.safetensors").is_file(), reason="no shipped checkpoint")
def test_a_real_annotation_takes_the_shortcut_to_the_induced_structure(cmp_records):
    from facaid.metrics import procedure_accuracy
    from facaid.pipeline import FAR_OFF
    from facaid.segmentation import Segmentation, flatten

    seg = Segmentation.from_dict(cmp_records[0], clip=True)
    result = reconstruct(seg, k=2)
    assert result.shortcut and result.source == "induced"
    assert result.procedure.meta["structure"] == "induced" and result.accuracy > 0.9
    assert result.accuracy == procedure_accuracy(result.procedure, flatten(seg))
    longer = reconstruct(seg, k=2, induce=False)  # the model's own structure, sized: far below
    assert not longer.shortcut and longer.accuracy_decoded < FAR_OFF
    assert longer.accuracy < result.accuracy  # sizing it would not have closed the gap
