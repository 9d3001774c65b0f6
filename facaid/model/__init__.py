"""The transformer: an encoder over a segmentation's rectangle rows (`encoder`), a decoder of procedure tokens with
cross-attention (`decoder`), and the model that joins them, saves and loads a checkpoint (`transformer`)."""

from facaid.model.transformer import (
    MAX_LOCAL,
    FacaidConfig,
    FacaidModel,
    batch_inputs,
    batch_outputs,
    load_model,
    save_model,
)

__all__ = ["MAX_LOCAL", "FacaidConfig", "FacaidModel", "batch_inputs", "batch_outputs", "load_model", "save_model"]
