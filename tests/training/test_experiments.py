"""configs/ and experiments/: what a user runs, and the chain of runs that made the shipped checkpoint."""

import json
from pathlib import Path

import pytest
from model_helpers import FIXED, GROWN

from facaid.paths import DEFAULT_CHECKPOINT, ROOT
from facaid.tokenizer import TokenizerConfig
from facaid.training import load_config

EXPERIMENTS = ROOT / "experiments"


def _shipped() -> tuple[dict, TokenizerConfig]:
    shipped = json.loads((DEFAULT_CHECKPOINT / "config.json").read_text())
    return shipped, TokenizerConfig(**shipped.pop("tokenizer"))


@pytest.mark.parametrize("name", sorted(path.stem for path in (ROOT / "configs").glob("*.toml")))
def test_user_configs_parse_and_shipped_toml_states_the_shipped_model(name):
    """configs/ holds what a user runs: each parses into a schedule; shipped.toml is the shipped model and tokenizer
    exactly, the others share its fixed architecture (width, heads, feed-forward)."""
    model_config, tok_config, train_config = load_config(ROOT / "configs" / f"{name}.toml")
    assert train_config.steps > 0 and train_config.lr > train_config.min_lr and not train_config.init
    shipped, shipped_tok = _shipped()
    for key in FIXED:
        assert getattr(model_config, key) == shipped[key], key
    if name == "shipped":
        assert tok_config == shipped_tok
        for key in GROWN:
            assert getattr(model_config, key) == shipped[key], key


def _runs() -> dict[Path, Path]:
    """The experiments' configs by the weights their runs leave (``train.out``/last, resolved)."""
    return {(ROOT / load_config(p)[2].out / "last").resolve(): p for p in EXPERIMENTS.glob("*/config.toml")}


def test_every_experiment_has_its_notes_and_a_config_or_its_commands():
    """A training run keeps its config; an evaluation run (no training) keeps the commands it ran in its notes."""
    folders = [p for p in EXPERIMENTS.iterdir() if p.is_dir()]
    assert len(folders) >= 15
    for folder in folders:
        date, name = folder.name[:10], folder.name[11:]
        assert date.count("-") == 2 and name, f"{folder.name}: expected YYYY-MM-DD-name"
        notes = (folder / "notes.md").read_text()
        assert notes.startswith(f"# {name} ({date})")
        commands = "facaid " in notes or ".venv/bin/python " in notes  # the CLI, or a script of the project's
        assert (folder / "config.toml").is_file() or commands, folder.name


def test_the_shipped_checkpoint_is_the_last_link_of_the_experiments_chain():
    """Following ``train.init`` from run to run, the experiments marked as links of the shipped chain lead to one
    last run whose model and tokenizer are the shipped checkpoint's; each link trains its parent's model or adds
    what `train.init` may add (decoder blocks, the box bias). Runs tried and not shipped start from the shipped
    checkpoint or another experiment's run."""
    runs = _runs()
    configs = {path.parent.name: load_config(path) for path in runs.values()}
    chain = {path.parent.name for path in runs.values()
             if "in the chain that made the shipped checkpoint" in (path.parent / "notes.md").read_text()}
    assert len(chain) == 15
    parents = {}
    for name, (_, _, cfg) in configs.items():
        init = (ROOT / cfg.init).resolve()
        if init in runs:
            parents[name] = runs[init].parent.name
        elif name in chain:
            assert cfg.init == "runs/gpu/last" or not cfg.init, f"{name}: init {cfg.init} is no run of the chain"
        else:
            assert init == DEFAULT_CHECKPOINT.resolve(), f"{name}: init {cfg.init} is neither shipped nor a run"
    for name, parent in parents.items():
        model_config, parent_model = configs[name][0], configs[parent][0]  # the tokenizer may read more
        for key in FIXED:
            assert getattr(parent_model, key) == getattr(model_config, key), (name, key)
        for key in GROWN:
            assert getattr(parent_model, key) <= getattr(model_config, key), (name, key)
    last = [name for name in chain if name not in {parents[n] for n in chain if n in parents}]
    assert len(last) == 1, last
    model_config, tok_config, _ = configs[last[0]]
    shipped, shipped_tok = _shipped()
    assert shipped_tok == tok_config
    for key in (*FIXED, *GROWN):
        assert shipped[key] == getattr(model_config, key), key


def test_the_shipped_checkpoint_holds_weights_config_tokenizer_and_a_model_card():
    """No optimizer state and no logs: --resume state lives in a run's directory, logs in experiments/."""
    assert {p.name for p in DEFAULT_CHECKPOINT.iterdir()} == {"config.json", "model.safetensors", "tokenizer.json",
                                                             "README.md"}
    card = (DEFAULT_CHECKPOINT / "README.md").read_text()
    header, _, body = card.removeprefix("---\n").partition("\n---\n")
    assert card.startswith("---\n") and "license:" in header and "pipeline_tag:" in header
    for section in ("## Training data", "## Figures", "## Limits", "## How it was made"):
        assert section in body, section
