#!/usr/bin/env python3
"""Compares the corner brightness of two 8-bit RGBA/RGB PNGs (standard library only).

usage: corners.py WITH_EFFECT.png WITHOUT_EFFECT.png
Exits 0 when every corner of the first image is darker than the same corner of the second
while the centres stay about as bright; prints the mean luminances either way.
"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or color not in (2, 6) or interlace:
                sys.exit(f"{path}: only 8-bit RGB/RGBA non-interlaced PNGs are handled")
            bpp = 4 if color == 6 else 3
        elif kind == b"IDAT":
            idat += body
    raw = zlib.decompress(idat)
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return width, height, bpp, rows


def mean(img, x0, y0, w, h):
    _, _, bpp, rows = img
    total = 0
    for y in range(y0, y0 + h):
        for x in range(x0, x0 + w):
            r, g, b = rows[y][x * bpp:x * bpp + 3]
            total += 0.2126 * r + 0.7152 * g + 0.0722 * b
    return total / (w * h)


def regions(width, height):
    s = max(2, min(width, height) // 8)
    return {"top-left": (0, 0), "top-right": (width - s, 0), "bottom-left": (0, height - s),
            "bottom-right": (width - s, height - s),
            "centre": ((width - s) // 2, (height - s) // 2)}, s


def main():
    with_fx, without = read_png(sys.argv[1]), read_png(sys.argv[2])
    if with_fx[:2] != without[:2]:
        sys.exit("images differ in size")
    where, s = regions(*with_fx[:2])
    ok = True
    for name, (x, y) in where.items():
        a, b = mean(with_fx, x, y, s, s), mean(without, x, y, s, s)
        if name == "centre":
            good = abs(a - b) <= 0.05 * b + 2
        else:
            good = a < b - 1  # at least one 8-bit step darker on average
        print(f"{name:13s} with effect {a:7.2f}  without {b:7.2f}  {'ok' if good else 'WRONG'}")
        ok &= good
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
