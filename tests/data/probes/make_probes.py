#!/usr/bin/env python3
"""Writes the small light probes of the `msm lights` command-line tests (tools/msm/CMakeLists.txt):
uncompressed scanline OpenEXR files of 16x8 float RGB texels, made by hand so that they may hold
what no image editor writes (NaN, infinity, negative radiance, radiance too large to sum); and
4:3 cube-map crosses of 16x12 (faces of 4²). Run it in this folder to remake them."""
import math
import struct

W, H = 16, 8


def attribute(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def exr(path, texel, W=W, H=H):
    channels = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    box = struct.pack("<iiii", 0, 0, W - 1, H - 1)
    header = (attribute("channels", "chlist", channels) + attribute("compression", "compression", b"\0") +
              attribute("dataWindow", "box2i", box) + attribute("displayWindow", "box2i", box) +
              attribute("lineOrder", "lineOrder", b"\0") + attribute("pixelAspectRatio", "float", struct.pack("<f", 1)) +
              attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0)) +
              attribute("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    start = 8 + len(header) + 8 * H
    line = 8 + 3 * 4 * W
    out = b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + header
    out += b"".join(struct.pack("<Q", start + y * line) for y in range(H))
    for y in range(H):
        rows = [[texel(x, y)[k] for x in range(W)] for k in (2, 1, 0)]  # B, G, R
        out += struct.pack("<ii", y, 3 * 4 * W) + b"".join(struct.pack("<%df" % W, *r) for r in rows)
    with open(path, "wb") as f:
        f.write(out)
    return out


def lamp(x, y):  # a dim room with one bright lamp above the horizon
    return (50.0, 45.0, 40.0) if (x, y) == (5, 2) else (0.2, 0.2, 0.25)


good = exr("lamp.exr", lamp)
exr("black.exr", lambda x, y: (0.0, 0.0, 0.0))
exr("nan.exr", lambda x, y: (math.nan, 0, 0) if (x, y) == (3, 4) else lamp(x, y))
exr("inf.exr", lambda x, y: (0, math.inf, 0) if (x, y) == (3, 4) else lamp(x, y))
exr("negative.exr", lambda x, y: (-1.0, -1.0, -1.0) if y >= 4 else lamp(x, y))
with open("truncated.exr", "wb") as f:
    f.write(good[: len(good) // 2])
# Radiance above msm::probe::kMaxProbeRadiance (1e20): refused; a lamp of 1e15, refused only at
# --intensity 1e6 (1e21 after it).
exr("bright.exr", lambda x, y: (1e30, 1e30, 1e30) if (x, y) == (5, 2) else lamp(x, y))
exr("sunny.exr", lambda x, y: (1e15, 1e15, 1e15) if (x, y) == (5, 2) else lamp(x, y))


def cross_lamp(x, y):  # a horizontal cross (4s x 3s, s = 4): the lamp on the +Y face's cell
    return (50.0, 45.0, 40.0) if (x, y) == (5, 1) else (0.2, 0.2, 0.25)


exr("cross.exr", cross_lamp, 16, 12)
exr("cross_nan.exr", lambda x, y: (math.nan, 0, 0) if (x, y) == (5, 5) else cross_lamp(x, y), 16, 12)
exr("cross_negative.exr", lambda x, y: (-1.0, -1.0, -1.0) if y >= 6 else cross_lamp(x, y), 16, 12)
exr("cross_black.exr", lambda x, y: (0.0, 0.0, 0.0), 16, 12)
