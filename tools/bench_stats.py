"""Shared by the tools/bench-* scripts: medians with a distribution-free interval."""
import math


def interval(values):
    """Median and the narrowest order-statistics interval covering ~95% (binomial)."""
    v = sorted(values)
    n = len(v)
    med = v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])
    if n < 6:
        return med, v[0], v[-1]
    best = (0, n - 1)
    for k in range(1, n // 2):
        cover = sum(math.comb(n, i) for i in range(k, n - k + 1)) / 2.0**n
        if cover >= 0.95:
            best = (k, n - 1 - k)
    return med, v[best[0]], v[best[1]]
