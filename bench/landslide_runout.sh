#!/usr/bin/env bash
# The full 3D landslide's run-out (311,250 points), timed at four points of it (issue 6).
#
#   bench/landslide_runout.sh [WORK_DIR] [STEPS] [THREADS]     (defaults /tmp/landslide 1000 2)
#
# The full slope's gravity and strength-reduction stages take hours; the slope is 25 copies
# of its 0.2 m strip side by side (slip walls on both sides: docs/landslide.md), so the strip
# is run instead (one thread, ~2 min) and resumed to 1, 2.5 and 4 s of the run-out (~6 min);
# each of the four states is tiled 25x (bench/landslide_tile.py, h5py) and resumed for STEPS
# steps on THREADS threads.  Prints per state the step time and the phases (seconds: the
# summary's phase_seconds less the checkpoint's, i.e. of these STEPS alone) and the estimate
# for the 110,000 steps of strength reduction and run-out.  Later states are reused when
# WORK_DIR already has them; BIN (default build/workflows/mpmc) picks the executable.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-/tmp/landslide}
steps=${2:-1000}
threads=${3:-2}
bin=${BIN:-$root/build/workflows/mpmc}
py=/usr/bin/python3
tile="$py $root/bench/landslide_tile.py"
mkdir -p "$work"
if [ ! -f "$work/s0/checkpoint.h5" ]; then
  (cd "$root/workflows" && "$bin" run slope_3d.yaml --out "$work/s0" --threads 1 --quiet --force \
    --set grid.cell_size=0.2 --set 'grid.hi=[55,0.2,6]' --set geometry.0.file=../meshes/slope_3d_strip.geo \
    --set stages.2.end.time=0.0005 --set 'snapshot_plots=[]')
fi
# the strip to later run-out times (the checkpoint at each end)
prev=s0
for st in 1:1.0 2:2.5 3:4.0; do
  k=${st%%:*}
  if [ ! -f "$work/s$k/checkpoint.h5" ]; then
    $tile "$work/$prev" "$work/s$k" 1 "${st#*:}" 1
    "$bin" resume "$work/s$k" --quiet
  fi
  prev=s$k
done
dt=$(awk "BEGIN{print $steps * 5e-5}")
for k in 0 1 2 3; do
  # the timed run resumes from the strip's state at its own stage time: end = that + STEPS dt
  t0=$($tile --time "$work/s$k")
  $tile "$work/s$k" "$work/f$k" 25 "$(awk "BEGIN{printf \"%.10g\", $t0 + $dt}")" "$threads"
  "$bin" resume "$work/f$k" --quiet
  $py - "$work/f$k" "$work/s$k" "$steps" "$t0" <<'EOF'
import h5py, json, sys
out, src, steps, t0 = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
s = json.load(open(out + "/summary.json"))
names = list(s["phase_seconds"])  # the order of the checkpoint's stats_phase_seconds
before = h5py.File(src + "/checkpoint.h5", "r")["config"].attrs["stats_phase_seconds"]
ph = {n: s["phase_seconds"][n] - b for n, b in zip(names, before)}
tot = sum(ph.values())
print("run-out %.2f s: %d steps %.2f s (%.2f ms/step, 110,000 steps %.1f min) | " %
      (t0, steps, tot, 1e3 * tot / steps, tot / steps * 110000 / 60) +
      " ".join("%s %.2f" % (n, v) for n, v in ph.items()))
EOF
done
