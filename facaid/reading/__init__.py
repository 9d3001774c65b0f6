"""Structures read off an annotation, the first stage of `facaid.pipeline.reconstruct`: the exact structure
(`induce`), and the lattice reader (`lattice`: floors of tiles with exceptions, the editable procedure) in its steps,
the grid of floors and tiles (`grid`) and the typical floor and bay with every other cell's deltas (`tiles`, over the
typical copies of `units`); the windows as a person counts them, in rows and columns (`windows`)."""
