#!/usr/bin/python3
"""Compare two result files (or two folders of them) bit for bit, apart from what measures time.

Usage: compare_results.py A B     (files, or folders: every *.hdf of A against the same name in B)

Every dataset and attribute must have the same shape, type and bytes (NaN equal to NaN), except those whose name
says they measure time or the run (elapsed_seconds, *_seconds, created, solver_version, compiler, host, ...) and
times in seconds within texts (messages).
Used to show that a refactoring changes no result (docs/architecture.md, "Changing the structure").
Exit 0 when all agree, 1 otherwise (each difference printed)."""
import os
import re
import sys

import h5py
import numpy as np

IGNORED = ("seconds", "created", "solver_version", "compiler", "host", "threads", "job_file")


def ignored(name):
    leaf = name.rsplit("/", 1)[-1]
    return any(word in leaf for word in IGNORED)


TIMES = re.compile(r"[0-9.e+-]+ s\b")  # "F products 0.0425 s" in a message


def same(a, b):
    if isinstance(a, str) and isinstance(b, str):
        return TIMES.sub("T s", a) == TIMES.sub("T s", b)
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind == "f":
        return np.array_equal(a, b, equal_nan=True)
    return np.array_equal(a, b)


def compare_attrs(path, a, b, out):
    for key in sorted(set(a.attrs) | set(b.attrs)):
        if ignored(key):
            continue
        if key not in a.attrs or key not in b.attrs:
            out.append(f"{path}@{key}: only in {'first' if key in a.attrs else 'second'}")
        elif not same(a.attrs[key], b.attrs[key]):
            out.append(f"{path}@{key}: {a.attrs[key]!r} != {b.attrs[key]!r}")


def compare_files(fa, fb):
    out = []
    with h5py.File(fa, "r") as a, h5py.File(fb, "r") as b:
        compare_attrs("/", a, b, out)
        names_a, names_b = [], []
        a.visit(names_a.append)
        b.visit(names_b.append)
        for name in sorted(set(names_a) | set(names_b)):
            if ignored(name):
                continue
            if name not in a or name not in b:
                out.append(f"/{name}: only in {'first' if name in a else 'second'}")
                continue
            x, y = a[name], b[name]
            compare_attrs("/" + name, x, y, out)
            if isinstance(x, h5py.Dataset) and not same(x[()], y[()]):
                out.append(f"/{name}: values differ")
    return out


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    a, b = sys.argv[1:]
    pairs = [(a, b)]
    if os.path.isdir(a):
        pairs = [(os.path.join(a, f), os.path.join(b, f)) for f in sorted(os.listdir(a)) if f.endswith(".hdf")]
    bad = 0
    for fa, fb in pairs:
        if not os.path.exists(fb):
            print(f"{fb}: missing")
            bad += 1
            continue
        diffs = compare_files(fa, fb)
        print(f"{os.path.basename(fa)}: {'identical' if not diffs else f'{len(diffs)} differences'}")
        for d in diffs[:20]:
            print("   ", d)
        bad += bool(diffs)
    print(f"{len(pairs) - bad} of {len(pairs)} identical")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
