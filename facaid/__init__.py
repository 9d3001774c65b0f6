"""FaçAID: neuro-symbolic facade reconstruction.

The library: labels, segmentations, the split grammar and its executors, the facade generator, rendering.
"""

__version__ = "0.1.0"


def __getattr__(name):
    # `facaid.reconstruct` without importing torch and transformers for every `import facaid`
    if name in ("reconstruct", "ReconstructOptions"):
        from facaid import pipeline

        return getattr(pipeline, name)
    if name == "complete":
        from facaid.completion import complete

        return complete
    raise AttributeError(f"module 'facaid' has no attribute {name!r}")
