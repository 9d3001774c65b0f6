"""Training the transformer on freshly generated facades: config, samples, objective, model surgery, the loop."""

from facaid.training.config import TrainConfig, load_config
from facaid.training.loop import train

__all__ = ["TrainConfig", "load_config", "train"]
