"""WebP decoded by libwebp itself, at a reduced size where asked: PIL decodes a WebP whole through its animation
decoder, holding four full-size copies (a 72 KB WebP of 16,000 x 2,490 took 613 MB), and cannot draft it.

libwebp's advanced API (`WebPDecode` with a `WebPDecoderConfig`) scales while it decodes, a few rows at a time, into
a buffer of the size asked for, and writes into ours, so a 40 MP WebP read at 1,000 px holds the small picture and
libwebp's row buffers. The library is the one PIL loaded (its own `_webp` module links it), found by its path, or
the system's; its ABI is `WEBP_DECODER_ABI_VERSION` 2.x, stable since libwebp 0.5.
"""

from __future__ import annotations

import ctypes
import ctypes.util
from functools import cache

import numpy as np

ABI = 0x0209  # WEBP_DECODER_ABI_VERSION: libwebp checks its major byte only
MODE_RGB, MODE_RGBA = 0, 1  # WEBP_CSP_MODE
STATUS = {1: "out of memory", 2: "an invalid parameter", 3: "bitstream error (the file is damaged)",
          4: "an unsupported feature (an animation?)", 5: "suspended", 6: "decoding was cancelled",
          7: "not enough data (the file is truncated)"}  # VP8StatusCode

_u8p = ctypes.POINTER(ctypes.c_uint8)


class _Features(ctypes.Structure):
    _fields_ = [("width", ctypes.c_int), ("height", ctypes.c_int), ("has_alpha", ctypes.c_int),
                ("has_animation", ctypes.c_int), ("format", ctypes.c_int), ("pad", ctypes.c_uint32 * 5)]


class _RGBA(ctypes.Structure):
    _fields_ = [("rgba", _u8p), ("stride", ctypes.c_int), ("size", ctypes.c_size_t)]


class _YUVA(ctypes.Structure):
    _fields_ = [("y", _u8p), ("u", _u8p), ("v", _u8p), ("a", _u8p), ("y_stride", ctypes.c_int),
                ("u_stride", ctypes.c_int), ("v_stride", ctypes.c_int), ("a_stride", ctypes.c_int),
                ("y_size", ctypes.c_size_t), ("u_size", ctypes.c_size_t), ("v_size", ctypes.c_size_t),
                ("a_size", ctypes.c_size_t)]


class _Planes(ctypes.Union):
    _fields_ = [("RGBA", _RGBA), ("YUVA", _YUVA)]


class _Buffer(ctypes.Structure):
    _fields_ = [("colorspace", ctypes.c_int), ("width", ctypes.c_int), ("height", ctypes.c_int),
                ("is_external_memory", ctypes.c_int), ("u", _Planes), ("pad", ctypes.c_uint32 * 4),
                ("private_memory", _u8p)]


class _Options(ctypes.Structure):
    _fields_ = [(name, ctypes.c_int) for name in (
        "bypass_filtering", "no_fancy_upsampling", "use_cropping", "crop_left", "crop_top", "crop_width",
        "crop_height", "use_scaling", "scaled_width", "scaled_height", "use_threads", "dithering_strength", "flip",
        "alpha_dithering_strength")] + [("pad", ctypes.c_uint32 * 5)]


class _Config(ctypes.Structure):
    _fields_ = [("input", _Features), ("output", _Buffer), ("options", _Options)]


@cache
def _library() -> ctypes.CDLL:
    from PIL import _webp  # noqa: F401  (loads the libwebp PIL was built with)

    try:
        with open("/proc/self/maps") as maps:  # Linux: the path of the copy loaded (a wheel bundles its own)
            paths = {line.split()[-1] for line in maps if len(line.split()) >= 6}
    except OSError:
        paths = set()
    for path in sorted(paths):
        name = path.rsplit("/", 1)[-1]
        if name.startswith("libwebp") and ".so" in name and not name.startswith(("libwebpdemux", "libwebpmux")):
            return _typed(ctypes.CDLL(path))
    found = ctypes.util.find_library("webp")
    if not found:
        raise OSError("libwebp was not found: WebP photos cannot be read")
    return _typed(ctypes.CDLL(found))


def _typed(lib: ctypes.CDLL) -> ctypes.CDLL:
    lib.WebPInitDecoderConfigInternal.argtypes = [ctypes.POINTER(_Config), ctypes.c_int]
    lib.WebPGetFeaturesInternal.argtypes = [ctypes.c_char_p, ctypes.c_size_t, ctypes.POINTER(_Features),
                                            ctypes.c_int]
    lib.WebPDecode.argtypes = [ctypes.c_char_p, ctypes.c_size_t, ctypes.POINTER(_Config)]
    lib.WebPFreeDecBuffer.argtypes = [ctypes.POINTER(_Buffer)]
    lib.WebPFreeDecBuffer.restype = None
    return lib


def decode(data: bytes, size: tuple[int, int] | None = None, alpha: bool = False) -> np.ndarray:
    """The WebP in ``data`` as an (h, w, 3) RGB or, with ``alpha``, (h, w, 4) RGBA uint8 array, scaled to ``size``
    (w, h; by default its own) while it is decoded. Raises OSError naming what libwebp found wrong: a damaged or
    truncated file, an animation."""
    lib = _library()
    config = _Config()
    if not lib.WebPInitDecoderConfigInternal(ctypes.byref(config), ABI):
        raise OSError("libwebp's decoder ABI does not match")
    status = lib.WebPGetFeaturesInternal(data, len(data), ctypes.byref(config.input), ABI)
    if status:
        raise OSError(f"the WebP cannot be read: {STATUS.get(status, status)}")
    full = (config.input.width, config.input.height)
    w, h = size or full
    out = np.empty((h, w, 4 if alpha else 3), dtype=np.uint8)
    if (w, h) != full:
        config.options.use_scaling, config.options.scaled_width, config.options.scaled_height = 1, w, h
    config.output.colorspace = MODE_RGBA if alpha else MODE_RGB
    config.output.is_external_memory = 1
    config.output.u.RGBA.rgba = out.ctypes.data_as(_u8p)
    config.output.u.RGBA.stride = out.strides[0]
    config.output.u.RGBA.size = out.nbytes
    status = lib.WebPDecode(data, len(data), ctypes.byref(config))
    lib.WebPFreeDecBuffer(ctypes.byref(config.output))  # ours is external: frees libwebp's own bits only
    if status:
        raise OSError(f"the WebP cannot be read: {STATUS.get(status, status)}")
    return out
