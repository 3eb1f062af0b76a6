"""Whether two fiber-atlas files hold the same results, bit for bit.

Usage: atlas_same_results.py A.h5 B.h5. Every group, dataset and attribute
of one is in the other with the same type, shape and bytes, except what
says when and how fast a run was: the root attributes created_utc and
attribute_digest (a digest of every attribute, created_utc included) and the
wall times (fibers/sim_seconds, fibers/fit_seconds, models/*/seconds).
Exit status 0 when the same, 1 (naming each difference) otherwise.
"""
import sys

import h5py
import numpy as np

WALL_TIMES = {"sim_seconds", "fit_seconds", "seconds"}


def objects(f):
    found = {"/": f}
    f.visititems(lambda name, obj: found.__setitem__(name, obj))
    return found


def same_attrs(name, x, y):
    problems = []
    for key in sorted(set(x.attrs) | set(y.attrs)):
        # attribute_digest covers created_utc (docs/FILE_FORMAT.md).
        if name == "/" and key in ("created_utc", "attribute_digest"):
            continue
        if key not in x.attrs or key not in y.attrs:
            problems.append(f"{name}@{key}: only in one file")
        elif not np.array_equal(np.asarray(x.attrs[key]), np.asarray(y.attrs[key])):
            problems.append(f"{name}@{key}: differs")
    return problems


def main(a_path, b_path):
    with h5py.File(a_path, "r") as a, h5py.File(b_path, "r") as b:
        oa, ob = objects(a), objects(b)
        problems = [f"{n}: only in one file" for n in sorted(set(oa) ^ set(ob))]
        datasets = 0
        for name in sorted(set(oa) & set(ob)):
            x, y = oa[name], ob[name]
            problems += same_attrs(name, x, y)
            if not isinstance(x, h5py.Dataset):
                continue
            if name.split("/")[-1] in WALL_TIMES:
                continue
            u, v = x[...], y[...]
            if u.dtype != v.dtype or u.shape != v.shape or u.tobytes() != v.tobytes():
                problems.append(f"{name}: data differs")
            datasets += 1
    for p in problems:
        print("DIFFERENT:", p)
    print(f"{datasets} datasets compared: {'different' if problems else 'bit-identical'}")
    return 1 if problems or datasets == 0 else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
