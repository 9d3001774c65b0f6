"""The heuristic facade generator: style presets S, production picker H_p and argument picker H_a.

`generate(seed)` is deterministic: the same seed (and style) gives the same procedure on every machine. The
builder makes valid procedures by construction: `generate_procedure` validates each as JSON input is validated;
`generate`, the training data's hot path, leaves that to the tests (thousands of seeds of every style) and checks
only the expansion, as it executes the procedure.
"""

from facaid.generator.build import TRAINING_STYLES, Sample, generate, generate_procedure, generate_rows
from facaid.generator.styles import PRESETS, STYLE_NAMES, Style, sample_style

__all__ = ["PRESETS", "STYLE_NAMES", "TRAINING_STYLES", "Sample", "Style", "generate", "generate_procedure",
           "generate_rows", "sample_style"]
