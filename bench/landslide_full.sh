#!/usr/bin/env bash
# The full 3D landslide's strength reduction and run-out (311,250 points; 0.5 s + 5 s at
# dt = 5e-5 s, 110,000 steps) run end to end on THREADS threads and timed (issue 6: under 60
# minutes on 2 cores).
#
#   bench/landslide_full.sh [WORK_DIR] [THREADS] [SR_END] [RUNOUT_END]
#                                               (defaults /tmp/landslide_full 2 0.5 5.0)
#
# The slope is 25 copies of its 0.2 m strip side by side, point for point (slip walls on
# both sides: docs/landslide.md), so the strip runs the gravity stage alone (one thread,
# ~25 s), bench/landslide_tile.py (h5py) widens its checkpoint to the full 5 m, and
# `mpmc resume` runs the strength reduction and the run-out of workflows/slope_3d.yaml on the
# full slope with the scene's outputs (a snapshot at the reduction's end and every 0.5 s of
# the run-out, the checkpoint at each stage's end).  The scene is copied into WORK_DIR (its
# mesh path made absolute), cut after the gravity stage for the strip and whole again for
# the resume.  SR_END and RUNOUT_END (stage times, s) shorten the two stages for a quick
# check of the script.  Prints the two stages' steps and wall times (summary.json), the
# resume's wall time and peak memory, and the run-out distance.  BIN (default
# build/workflows/mpmc) picks the executable.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-/tmp/landslide_full}
threads=${2:-2}
sr_end=${3:-0.5}
ro_end=${4:-5.0}
bin=${BIN:-$root/build/workflows/mpmc}
py=/usr/bin/python3
$py -c 'import h5py' 2>/dev/null ||
  { echo "landslide_full.sh: needs h5py for /usr/bin/python3 (Debian: apt-get install python3-h5py)" >&2; exit 1; }
[ -x "$bin" ] || { echo "landslide_full.sh: $bin: no such executable (build first, or set BIN)" >&2; exit 1; }
mkdir -p "$work"
work=$(cd "$work" && pwd)
sed "s|file: \.\./meshes/slope_3d\.geo|file: $root/meshes/slope_3d.geo|" \
  "$root/workflows/slope_3d.yaml" > "$work/full.yaml"
grep -q "file: $root/meshes/slope_3d.geo" "$work/full.yaml" ||
  { echo "landslide_full.sh: workflows/slope_3d.yaml: its geometry file line was not found" >&2; exit 1; }
# the gravity stage alone, on the strip
awk '/^  - name: strength_reduction/ {exit} {print}' "$work/full.yaml" > "$work/scene.yaml"
"$bin" run "$work/scene.yaml" --out "$work/strip" --threads 1 --quiet --force \
  --set grid.cell_size=0.2 --set 'grid.hi=[55,0.2,6]' \
  --set "geometry.0.file=$root/meshes/slope_3d_strip.geo" --set 'snapshot_plots=[]'
# the whole scene again (the checkpoint names scene.yaml), the strip widened to the slope
cp "$work/full.yaml" "$work/scene.yaml"
$py "$root/bench/landslide_tile.py" "$work/strip" "$work/slope" 25 "$ro_end" "$threads"
t0=$(date +%s.%N)
resume=("$bin" resume "$work/slope" --quiet
  --set "stages.strength_reduction.end.time=$sr_end" --set "stages.runout.end.time=$ro_end")
if [ -x /usr/bin/time ]; then # the peak resident set too (Debian package time)
  /usr/bin/time -f "%M" -o "$work/maxrss" "${resume[@]}"
else
  echo 0 > "$work/maxrss"
  "${resume[@]}"
fi
t1=$(date +%s.%N)
$py - "$work/slope/summary.json" "$t0" "$t1" "$work/maxrss" "$threads" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
wall = float(sys.argv[3]) - float(sys.argv[2])
rss_kib = int(open(sys.argv[4]).read().split()[-1])
steps, secs = 0, 0.0
for st in s["stages"][1:]:  # the gravity stage ran on the strip
    steps += st["steps"]
    secs += st["wall_seconds"]
    print("%-18s %7d steps %8.1f s  %.2f ms/step" %
          (st["name"], st["steps"], st["wall_seconds"], 1e3 * st["wall_seconds"] / max(st["steps"], 1)))
rss = "%.0f MiB" % (rss_kib / 1024) if rss_kib else "not measured (no /usr/bin/time)"
print("strength reduction + run-out: %d steps in %.1f min (stages' wall time); the resume %.1f min"
      " wall, peak RSS %s; %d points, %s threads, %s kernels"
      % (steps, secs / 60, wall / 60, rss, s["particles"], sys.argv[5], s["kernels"]))
print("run-out distance %.3f m, status %s" % (s.get("runout_distance", float("nan")), s["status"]))
EOF
