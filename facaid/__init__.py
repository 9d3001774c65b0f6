"""FaçAID: neuro-symbolic facade reconstruction.

The library: labels, segmentations, the split grammar and its executors, the facade generator, rendering.
"""

__version__ = "0.1.0"
