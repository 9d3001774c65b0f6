"""Evaluation: tree edit distance, noise, held-out synthetic facades, reports."""
