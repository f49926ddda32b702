#!/usr/bin/python3
"""The full-width 3D landslide from its 0.2 m strip, for the run-out benchmark (issue 6).

usage: landslide_tile.py STRIP_DIR OUT_DIR COPIES END_TIME THREADS
       landslide_tile.py --time DIR       (prints the run-out time of DIR/checkpoint.h5)

STRIP_DIR holds the checkpoint of `mpmc run workflows/slope_3d.yaml` with the strip
overrides (bench/landslide_runout.sh); the strip is one cell (0.2 m) wide with slip walls on
both sides, so COPIES of it side by side along y are the slope COPIES x 0.2 m wide in the
same state, point for point (docs/landslide.md).  OUT_DIR/checkpoint.h5 is that slope with
the run-out stage to end at END_TIME (stage time, s) on THREADS threads; `mpmc resume OUT_DIR`
continues it (from a finished run's checkpoint too: the run-out's end raised, resume goes on
from where it ended).  Needs h5py (Debian: python3-h5py).
"""
import os
import re
import shutil
import sys

import h5py
import numpy as np


def runout_time(meta):
    """The run-out stage's time in a workflow checkpoint's record: its stage_time while the
    run-out (stage 2) is under way, the time it ended at when the run finished (stage 3)."""
    stage = int(re.search(r"^stage (\d+)$", meta, re.M).group(1))
    if stage < 3:
        return float(re.search(r"^stage_time (\S+)$", meta, re.M).group(1))
    return float(re.findall(r"^done (\S+) ", meta, re.M)[2])


def main(src, dst, copies, end_time, threads):
    os.makedirs(dst, exist_ok=True)
    shutil.copy(os.path.join(src, "checkpoint.h5"), os.path.join(dst, "checkpoint.h5"))
    width = 0.2
    with h5py.File(os.path.join(dst, "checkpoint.h5"), "r+") as f:
        part = f["particles"]
        n = int(part.attrs["n"])
        for name in list(part.keys()):
            a = part[name][()]
            t = np.concatenate([a] * copies, axis=0)
            if name in ("x", "x0"):
                for c in range(copies):
                    t[c * n:(c + 1) * n, 1] += c * width
            elif name == "id":
                for c in range(copies):
                    t[c * n:(c + 1) * n] += c * n
            del part[name]
            part.create_dataset(name, data=t)
        part.attrs["n"] = n * copies
        # point sets: the sides only on the outer copies, the rest in every copy
        for key in f["sets"]:
            ds = f["sets"][key]
            name = ds.attrs["name"].decode()
            a = ds[()]
            cs = [0] if name == "side_y0" else [copies - 1] if name == "side_y1" else range(copies)
            t = np.concatenate([a + c * n for c in cs])
            attrs = dict(ds.attrs)
            del f["sets"][key]
            f["sets"].create_dataset(key, data=t)
            f["sets"][key].attrs.update(attrs)
        # node sets (grid indices i, j, k): shifted by a cell per copy, shared planes once
        for key in f["node_sets"]:
            ds = f["node_sets"][key]
            name = ds.attrs["name"].decode()
            a = ds[()]
            if name == "side_y1":
                t = a.copy()
                t[:, 1] += copies - 1
            elif name == "side_y0":
                t = a
            else:
                parts = []
                for c in range(copies):
                    s = a.copy()
                    s[:, 1] += c
                    parts.append(s)
                t = np.unique(np.concatenate(parts), axis=0)
            attrs = dict(ds.attrs)
            del f["node_sets"][key]
            f["node_sets"].create_dataset(key, data=t)
            f["node_sets"][key].attrs.update(attrs)
        cfg = f["config"]
        hi = cfg.attrs["grid_hi"].copy()
        hi[1] = width * copies
        cfg.attrs["grid_hi"] = hi
        ints = cfg.attrs["dim_basis_fbar_solver_nthreads_forcedt"].copy()
        ints[4] = threads
        cfg.attrs["dim_basis_fbar_solver_nthreads_forcedt"] = ints
        walls = f["walls"][()]
        for w in walls:  # the y_hi wall's plane: its lower bound in y
            if w[5] == width:
                w[5] = width * copies
        f["walls"][...] = walls
        meta = f.attrs["meta"].decode()
        meta = re.sub(r"set threads=\d+", "set threads=%d" % threads, meta)
        meta = re.sub(r"set stages\.2\.end\.time=\S+", "set stages.2.end.time=%r" % end_time, meta)
        if copies > 1:  # the scene's own width and geometry
            meta = re.sub(r"set grid\.hi=\S+\n", "", meta)
            meta = re.sub(r"set geometry\.0\.file=\S+\n", "", meta)
        meta = re.sub(r"set checkpoint_interval=\S+\n", "", meta)
        # no checkpoints within the run: the one at its end is the state the chain goes on from
        meta = meta.replace("set snapshot_plots=[]\n", "set snapshot_plots=[]\nset checkpoint_interval=100000\n")
        f.attrs["meta"] = np.bytes_(meta)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--time":
        with h5py.File(os.path.join(sys.argv[2], "checkpoint.h5"), "r") as f:
            print(repr(runout_time(f.attrs["meta"].decode())))
        sys.exit(0)
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]))
