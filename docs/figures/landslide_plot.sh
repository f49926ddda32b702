#!/bin/sh
# Figures of the 3D landslide (docs/landslide.md) from `mpmc run` output directories, with
# h5dump (Debian hdf5-tools) and gnuplot only.  Times are counted from the strength
# reduction (the end of the gravity stage), as in the paper's Figs 15 and 16.
#
#   landslide_plot.sh snapshots RUN_DIR PREFIX [T ...]
#       side views (x-z, looking along y) coloured by the equivalent plastic strain at the
#       snapshots nearest T s after the reduction (default 1.5 2.5 3.5 5.5):
#       PREFIX_eps_p_<T>s.png
#   landslide_plot.sh runout OUT.png LABEL=RUN_DIR [LABEL=RUN_DIR ...]
#       run-out distance against time after the reduction, one line per run (series.csv)
set -eu

die() { echo "landslide_plot.sh: $*" >&2; exit 1; }
command -v gnuplot >/dev/null 2>&1 || die "gnuplot not found (Debian gnuplot-nox)"

# the simulated time at the end of the gravity stage (the first stage) from summary.json
reduction_time() {
  sed -n 's/.*{"name": "[^"]*", "sim_time": \([0-9.eE+-]*\),.*/\1/p' "$1/summary.json" | head -n 1
}

snapshots() {
  run=$1; prefix=$2; shift 2
  [ $# -gt 0 ] || set -- 1.5 2.5 3.5 5.5
  command -v h5dump >/dev/null 2>&1 || die "h5dump not found (Debian hdf5-tools)"
  h5=$run/snapshots.h5
  [ -f "$h5" ] || die "$h5 not found"
  t0=$(reduction_time "$run")
  [ -n "$t0" ] || die "no gravity stage in $run/summary.json"
  scene=$(sed -n 's/.*"scene": "\([^"]*\)".*/\1/p' "$run/summary.json" | head -n 1)
  h=$(sed -n 's/.*"cell_size": \([0-9.eE+-]*\).*/\1/p' "$run/summary.json" | head -n 1)
  fbar=$(sed -n 's/.*"fbar": \([a-z"]*\).*/\1/p' "$run/summary.json" | tr -d '"' | head -n 1)
  basis=$(sed -n 's/.*"basis": "\([^"]*\)".*/\1/p' "$run/summary.json" | head -n 1)
  [ "$fbar" = false ] && form=standard || form=F-bar
  scene="$scene ($form, $basis, h = $h m)"
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  # every snapshot's time
  for g in $(h5dump -n "$h5" | sed -n 's/^ *group *\/\(snapshot_[0-9]*\)$/\1/p'); do
    t=$(h5dump -a "/$g/time" "$h5" | sed -n 's/^ *(0): *//p')
    echo "$g $t"
  done >"$tmp/times"
  for T in "$@"; do
    best=$(awk -v want="$T" -v t0="$t0" '{ d = $2 - t0 - want; if (d < 0) d = -d;
             if (!n++ || d < bd) { bd = d; b = $1; bt = $2 - t0 } } END { printf "%s %.3f\n", b, bt }' "$tmp/times")
    g=${best% *}; tt=${best#* }
    h5dump -d "/$g/position" -y -w 0 -o "$tmp/x" "$h5" >/dev/null
    h5dump -d "/$g/eps_p" -y -w 0 -o "$tmp/e" "$h5" >/dev/null
    # one "x y z eps_p" row per point, far points (large y) first so near ones are drawn last
    tr -d ' ' <"$tmp/e" | tr ',' '\n' | sed '/^$/d' >"$tmp/e1"
    tr -d ' ' <"$tmp/x" | sed '/^$/d' | tr ',' ' ' | paste -d ' ' - "$tmp/e1" | sort -g -r -k2,2 >"$tmp/p"
    out="${prefix}_eps_p_${T}s.png"
    gnuplot <<EOF
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) { set terminal pngcairo size 1400,380 font ',12' } else { set terminal png size 1400,380 }
set output '$out'
set size ratio -1
set xrange [0:55]
set yrange [0:6]
set xlabel 'x [m]'
set ylabel 'z [m]'
set title '$scene: equivalent plastic strain, $tt s after the strength reduction (side view)' noenhanced
set palette defined (0 '#313695', 1 '#4575b4', 2 '#74add1', 3 '#abd9e9', 4 '#fee090', 5 '#fdae61', 6 '#f46d43', 7 '#d73027', 8 '#a50026')
set cbrange [0:2]
set cblabel 'eps_p (clipped at 2)' noenhanced
set arrow from 14.95,0 to 14.95,6 nohead dt 2 lc rgb 'gray40'
plot '$tmp/p' using 1:3:(\$4 > 2 ? 2 : \$4) with points pt 7 ps 0.3 lc palette notitle
EOF
    echo "$out ($g, t = $tt s after the reduction)"
  done
}

runout() {
  out=$1; shift
  [ $# -gt 0 ] || die "runout: no LABEL=RUN_DIR"
  plot=""
  for arg in "$@"; do
    label=${arg%%=*}; run=${arg#*=}
    [ -f "$run/series.csv" ] || die "$run/series.csv not found"
    t0=$(reduction_time "$run")
    col=$(head -n 1 "$run/series.csv" | tr ',' '\n' | grep -n '^runout_distance$' | cut -d: -f1)
    [ -n "$col" ] || die "$run/series.csv has no runout_distance column"
    plot="$plot${plot:+, }'$run/series.csv' skip 1 using (\$2 - $t0):$col with lines lw 2 title '$label'"
  done
  gnuplot <<EOF
set datafile separator ','
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) { set terminal pngcairo size 900,600 font ',12' } else { set terminal png size 900,600 }
set output '$out'
set xlabel 'time after the strength reduction [s]'
set ylabel 'run-out distance [m]'
set xrange [0:5.5]
set grid
set key top left noenhanced
plot $plot
EOF
  echo "$out"
}

cmd=${1:-}
[ $# -gt 0 ] && shift
case $cmd in
  snapshots) [ $# -ge 2 ] || die "usage: $0 snapshots RUN_DIR PREFIX [T ...]"; snapshots "$@" ;;
  runout) [ $# -ge 2 ] || die "usage: $0 runout OUT.png LABEL=RUN_DIR ..."; runout "$@" ;;
  *) die "usage: $0 snapshots RUN_DIR PREFIX [T ...] | runout OUT.png LABEL=RUN_DIR ..." ;;
esac
