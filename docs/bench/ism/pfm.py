"""PFM images for the ISM bench scripts (gi-render / gi-reference write them)."""
import struct


def read_pfm(path):
    """(width, height, channels, values): a flat tuple, rows as stored."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        n = 3 if kind == b"PF" else 1
        fmt = ("<" if scale < 0 else ">") + "f" * (w * h * n)
        return w, h, n, struct.unpack(fmt, f.read()[: 4 * w * h * n])
