#!/usr/bin/env python3
"""Share of a PNG picture that the tissue covers: the pixels coloured by the colour map
(saturation above 0.3; the background's gradient and the text are greyish).

Usage: picture_coverage.py FILE LOW HIGH -- fails unless LOW <= share <= HIGH.
Reads 8-bit RGB or RGBA PNG files without interlacing, as VTK writes them."""

import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG file")
    pos, chunks = 8, {}
    idat = b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            chunks["IHDR"] = body
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", chunks["IHDR"])
    if depth != 8 or colour not in (2, 6) or interlace:
        sys.exit(f"{path}: only 8-bit RGB(A) PNG without interlacing is read here")
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            left = line[i - channels] if i >= channels else 0
            up = previous[i]
            corner = previous[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + left) & 255
            elif kind == 2:
                line[i] = (line[i] + up) & 255
            elif kind == 3:
                line[i] = (line[i] + (left + up) // 2) & 255
            elif kind == 4:
                p = left + up - corner
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - corner)
                line[i] = (line[i] + (left if pa <= pb and pa <= pc else up if pb <= pc else corner)) & 255
        rows.append(line)
        previous = line
    return width, height, channels, rows


def main():
    path, low, high = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
    width, height, channels, rows = read_png(path)
    covered = 0
    for line in rows:
        for x in range(width):
            r, g, b = line[x * channels:x * channels + 3]
            top, bottom = max(r, g, b), min(r, g, b)
            if top > 0 and (top - bottom) / top > 0.3:
                covered += 1
    share = covered / (width * height)
    print(f"{path}: the tissue covers {100 * share:.1f} % of {width} x {height} pixels")
    if not low <= share <= high:
        sys.exit(f"expected between {100 * low:.0f} % and {100 * high:.0f} %")


if __name__ == "__main__":
    main()
