#!/usr/bin/env python3
"""Writes the PNG seeds of the image and compare fuzz targets (tests/fuzz/corpus/{image,compare}):
small PNGs of every colour type and bit depth stb reads, interlaced and not. The EXR seeds come
from make_exr_seeds.cpp (OpenEXR), the compare seeds pair them (see fuzz_compare.cpp).
    tests/fuzz/seeds/make_image_seeds.py tests/fuzz/corpus"""
import os
import struct
import sys
import zlib


def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def png(width, height, colour_type, depth, samples, interlace=0, palette=None):
    """samples(x, y) -> list of channel values; rows unfiltered (filter 0: stb's other filters are
    reached by mutation); interlace 1: the seven Adam7 passes."""
    passes = [(0, 0, 1, 1)] if not interlace else [
        (0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
    raw = b""
    for x0, y0, dx, dy in passes:
        for y in range(y0, height, dy):
            row = b""
            for x in range(x0, width, dx):
                for v in samples(x, y):
                    row += struct.pack(">H", v) if depth == 16 else bytes([v])
            if row:
                raw += bytes([0]) + row
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, depth, colour_type, 0, 0, interlace))
    if palette:
        out += chunk(b"PLTE", bytes(palette))
    return out + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def main(root):
    image = os.path.join(root, "image")
    os.makedirs(image, exist_ok=True)
    seeds = {
        "grey8.png": png(4, 3, 0, 8, lambda x, y: [x * 60 + y]),
        "grey16.png": png(3, 2, 0, 16, lambda x, y: [x * 20000 + y]),
        "grey_alpha8.png": png(2, 2, 4, 8, lambda x, y: [x * 200, y * 255]),
        "rgb8.png": png(3, 3, 2, 8, lambda x, y: [x * 100, y * 100, 50]),
        "rgb16.png": png(2, 2, 2, 16, lambda x, y: [x * 60000, y * 60000, 1000]),
        "rgba8_interlaced.png": png(5, 4, 6, 8, lambda x, y: [x * 50, y * 60, 7, 128], interlace=1),
        "palette.png": png(3, 2, 3, 8, lambda x, y: [(x + y) % 2], palette=[255, 0, 0, 0, 0, 255]),
    }
    for name, data in seeds.items():
        with open(os.path.join(image, name), "wb") as f:
            f.write(data)
    # compare: options byte, 32-bit little-endian length of the reference, reference, test (run
    # make_exr_seeds first). Options: bit 0 shadow signal, bits 1-3 channel, bit 4 mask.
    compare = os.path.join(root, "compare")
    os.makedirs(compare, exist_ok=True)
    pairs = [
        ("same_y", 0, "none_float_y.exr", "pxr24_float_y.exr"),
        ("size_mismatch", 0, "none_float_y.exr", "one_pixel.exr"),
        ("named_channel", 4 << 1, "piz_float_named.exr", "piz_float_named.exr"),
        ("masked_shadow", 1 | 16, "zip_half_rgba.exr", "b44a_half_rgba.exr"),
        ("rgb_luminance", 0, "zips_float_rgb.exr", "tiled_zip_float_rgb.exr"),
        ("png_red_channel", 2 << 1, "rgb8.png", "rgb8.png"),
        ("unknown_channel", 7 << 1, "grey8.png", "grey8.png"),
    ]
    for name, options, reference, test in pairs:
        a = open(os.path.join(image, reference), "rb").read()
        b = open(os.path.join(image, test), "rb").read()
        with open(os.path.join(compare, name), "wb") as f:
            f.write(bytes([options]) + struct.pack("<I", len(a)) + a + b)


if __name__ == "__main__":
    main(sys.argv[1])
