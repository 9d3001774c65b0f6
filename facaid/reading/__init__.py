"""Structures read off an annotation: the lattice reader (`lattice`: floors of tiles with exceptions, the editable
procedure) and its typical copies and their deltas (`units`)."""
