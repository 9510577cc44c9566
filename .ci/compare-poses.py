#!/usr/bin/env python3
"""Compares pose lines (JSON, one per filter epoch) with `deadreckon stream`'s.

    compare-poses.py EXPECTED.jsonl ACTUAL.jsonl LABEL [TOLERANCE]

Both must have the same number of lines and keys; every value must agree
within TOLERANCE (default 1e-9, absolute: metres, radians, m/s, and the
covariances). Prints the largest difference seen; exits 1 on a mismatch.
"""
import json
import sys


def values(obj):
    for key in sorted(obj):
        v = obj[key]
        if isinstance(v, list):
            for i, x in enumerate(v):
                yield f"{key}[{i}]", x
        else:
            yield key, v


def main():
    expected_path, actual_path, label = sys.argv[1:4]
    tolerance = float(sys.argv[4]) if len(sys.argv) > 4 else 1e-9
    with open(expected_path) as f:
        expected = [json.loads(line) for line in f if line.strip()]
    with open(actual_path) as f:
        actual = [json.loads(line) for line in f if line.strip()]
    if not expected:
        sys.exit(f"{label}: no poses in {expected_path}")
    if len(expected) != len(actual):
        sys.exit(f"{label}: {len(actual)} poses, stream printed {len(expected)}")
    worst = (0.0, None, None)
    for n, (e, a) in enumerate(zip(expected, actual), start=1):
        if sorted(e) != sorted(a):
            sys.exit(f"{label}: pose {n}: keys {sorted(a)}, stream's {sorted(e)}")
        for (key, x), (_, y) in zip(values(e), values(a)):
            d = abs(x - y)
            if not d <= worst[0]:
                worst = (d, n, key)
    d, n, key = worst
    where = f" (pose {n}, {key})" if n else ""
    print(f"{label}: {len(actual)} poses, max |difference| {d:.3g}{where}")
    if d > tolerance:
        sys.exit(f"{label}: differs from stream by more than {tolerance:g}")


if __name__ == "__main__":
    main()
