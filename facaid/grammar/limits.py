"""The grammar's limits: what a procedure may hold, checked when one is parsed and when one is executed."""

from facaid.segmentation import MAX_SIDE

MAX_DEPTH = 32
MAX_NODES = 8192
MAX_CHILDREN = 64
MAX_COUNT = 256
MAX_EXCEPTIONS = 1024  # per repeat
MAX_LEAVES = 100_000  # rectangles after repeats and mirrors are expanded
MAX_INSTANCES = 100_000  # node instances laid out (`layout.count_expansion`): what executing a tree costs
MAX_META_CHARS = 65_536
MAX_EXTENT = float(MAX_SIDE)  # pixels: a procedure executes to a segmentation, whose sides stop there too
