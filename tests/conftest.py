import json
import os

import pytest
from hypothesis import settings

from facaid.paths import DEFAULT_CMP

# The property tests draw the same cases on every run, so that the suite passes or fails alike here and in CI;
# HYPOTHESIS_PROFILE=explore draws new ones each run (a case it finds goes into its test as an @example).
settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))

CMP = DEFAULT_CMP  # FACAID_CMP, or ../shared/data/cmp/annotations.jsonl beside the repository


@pytest.fixture(scope="session")
def cmp_records():
    """A few CMP annotations, used only to check that real data passes through the format code."""
    if not CMP.is_file():
        pytest.skip(f"CMP annotations not found at {CMP}")
    with open(CMP) as f:
        return [json.loads(next(f)) for _ in range(25)]


TINY_TOKENIZER = {"max_rects": 1000, "max_out": 200}


@pytest.fixture(scope="session")
def tiny():
    """An untrained model of the smallest size, with its tokenizer: for testing code paths, not quality."""
    import torch

    from facaid.model import FacaidConfig, FacaidModel
    from facaid.tokenizer import Tokenizer, TokenizerConfig

    config = TokenizerConfig(**TINY_TOKENIZER)
    torch.manual_seed(0)
    model = FacaidModel(FacaidConfig(d_model=16, encoder_layers=1, decoder_layers=1, heads=2, ffn=32, node_boxes=True,
                                     tokenizer=config.to_dict())).eval()
    return model, Tokenizer(config)


def pytest_xdist_node_collection_finished(node, ids):
    """With ``-n``, say how many tests run as soon as a worker has collected them (``-q`` hides xdist's count)."""
    config = node.config
    if getattr(config, "_facaid_said_total", False):
        return
    config._facaid_said_total = True
    reporter = config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None:
        reporter.write_line(f"{len(ids)} tests, on {config.getoption('numprocesses')} workers")
