#!/bin/bash
# the sized sweep: shipped induction against regularize + consensus + soft cuts, clean and perturbed (seed 1)
cd "$(dirname "$0")/../.." || exit 1
S=experiments/2026-12-03-lattice/sweep.py
D=experiments/2026-12-03-lattice
.venv/bin/python $S --every 3 --sizing --json $D/sized-shipped.json
.venv/bin/python $S --every 3 --sizing --snap 0.012 --consensus 0.6 --soft 0.1 --json $D/sized-lattice.json
.venv/bin/python $S --every 3 --sizing --perturb 1 --json $D/sized-shipped-p1.json
.venv/bin/python $S --every 3 --sizing --perturb 1 --snap 0.012 --consensus 0.6 --soft 0.1 --json $D/sized-lattice-p1.json
