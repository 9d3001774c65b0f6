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
