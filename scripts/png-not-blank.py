#!/usr/bin/env python3
"""Exit 0 if the PNG named on the command line shows something: at least 16
distinct colours and at least 1% of its pixels unlike the most common one.
Exit 1, with one line on stderr, if it is blank, missing or not a PNG.
Reads 8-bit RGB and RGBA, the formats a browser screenshot takes."""
import struct
import sys
import zlib
from collections import Counter


def pixels(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        raise ValueError(f"PNG format (depth {depth}, colour type {colour}, interlace {interlace}) not read here")
    bpp = 3 if colour == 2 else 4
    raw, stride = zlib.decompress(idat), width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return [row[i:i + 3] for row in rows[::4] for i in range(0, stride, 4 * bpp)]  # every fourth, each way


def main():
    try:
        sample = pixels(sys.argv[1])
    except (OSError, ValueError, struct.error, zlib.error, TypeError) as e:
        print(f"png-not-blank: {sys.argv[1]}: {e}", file=sys.stderr)
        return 1
    counts = Counter(sample)
    background = counts.most_common(1)[0][1]
    if len(counts) < 16 or len(sample) - background < len(sample) // 100:
        print(f"png-not-blank: {sys.argv[1]}: blank ({len(counts)} colours)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
