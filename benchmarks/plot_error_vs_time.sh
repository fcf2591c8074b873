#!/usr/bin/env bash
# plot_error_vs_time.sh — draws error_vs_time's CSV files: per file one PNG
# with a grid of panels, one per case, the error against the wall time per
# frame (log-log): every substeps x iterations run as a grey point, the
# substep-only runs (n x 1) and the iteration-only runs (1 x n) as lines
# with markers, and the Pareto front (the runs no other run beats on both
# error and time) as a thick black line, also written as <name>_pareto.csv.
# Runs with error 0 are in the Pareto CSV but cannot be drawn on log axes.
# Titles are plain text (gnuplot's enhanced text, which would set "nh_bar"
# as a subscript, is off).
set -euo pipefail

usage() {
  cat <<EOF
Usage: benchmarks/plot_error_vs_time.sh [--out DIR] [--run BUILD_DIR] [CSV ...] [-- ERROR_VS_TIME_ARGS ...]

Plots error_vs_time's CSV files (case,substeps,iterations,sweeps,ms_per_frame,error,...), one PNG each,
named after the CSV's folder: DIR/<folder>.png and DIR/<folder>_pareto.csv (the Pareto front per case).

  --out DIR          where the PNG and the Pareto CSV files go (default: ./error_vs_time_plots)
  --run BUILD_DIR    first run BUILD_DIR/benchmarks/error_vs_time --out DIR/error_vs_time_run (arguments
                     after -- go to it), then plot its CSV
  CSV ...            the files to plot (default: the committed ones,
                     benchmarks/results/error_vs_time*/error_vs_time.csv)
  -h, --help         this text

Needs gnuplot (Debian gnuplot-nox) with the pngcairo terminal.
EOF
}

out=./error_vs_time_plots
build=""
csvs=()
run_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --out) [ $# -ge 2 ] || { echo "plot_error_vs_time.sh: --out needs a folder" >&2; exit 2; }; out=$2; shift 2 ;;
    --run) [ $# -ge 2 ] || { echo "plot_error_vs_time.sh: --run needs a build folder" >&2; exit 2; }; build=$2; shift 2 ;;
    --) shift; run_args=("$@"); break ;;
    -*) echo "plot_error_vs_time.sh: unknown option $1 (--help lists them)" >&2; exit 2 ;;
    *) csvs+=("$1"); shift ;;
  esac
done
command -v gnuplot >/dev/null || { echo "plot_error_vs_time.sh: gnuplot not found (apt-get install gnuplot-nox)" >&2; exit 1; }
mkdir -p "$out"

if [ -n "$build" ]; then
  "$build/benchmarks/error_vs_time" --out "$out/error_vs_time_run" "${run_args[@]}"
  csvs+=("$out/error_vs_time_run/error_vs_time.csv")
fi
if [ ${#csvs[@]} -eq 0 ]; then
  here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
  csvs=("$here"/results/error_vs_time*/error_vs_time.csv)
fi

for csv in "${csvs[@]}"; do
  [ -r "$csv" ] || { echo "plot_error_vs_time.sh: cannot read $csv" >&2; exit 1; }
  head -n 1 "$csv" | grep -q '^case,substeps,iterations,sweeps,ms_per_frame,error' ||
    { echo "plot_error_vs_time.sh: $csv is not error_vs_time's CSV (its header differs)" >&2; exit 1; }
  name=$(basename "$(dirname "$(cd "$(dirname "$csv")" && pwd)/x")")
  cases=$(tail -n +2 "$csv" | cut -d, -f1 | awk '!seen[$0]++')
  n=$(echo "$cases" | wc -l)
  cols=$(( n < 3 ? n : 3 ))
  rows=$(( (n + cols - 1) / cols ))

  # The Pareto front per case: by time, each run with less error than every faster one.
  pareto="$out/${name}_pareto.csv"
  echo "case,substeps,iterations,sweeps,ms_per_frame,error" > "$pareto"
  tail -n +2 "$csv" | sort -t, -k1,1 -s -k5,5g |
    awk -F, '$1 != c { c = $1; best = "" } best == "" || $6 < best { best = $6; print $1","$2","$3","$4","$5","$6 }' >> "$pareto"

  # Each series in its own file (a filtered-out row inside a gnuplot series would break its line).
  data=$(mktemp -d)
  for c in $cases; do
    # A run with error 0 (one that matches the reference) has no place on log axes: left out of the plot.
    awk -F, -v c="$c" 'NR > 1 && $1 == c && $6 > 0' "$csv" > "$data/$c.all"
    awk -F, '$3 == 1' "$data/$c.all" | sort -t, -k4,4n > "$data/$c.substeps"
    awk -F, '$2 == 1' "$data/$c.all" | sort -t, -k4,4n > "$data/$c.iterations"
    awk -F, -v c="$c" '$1 == c && $6 > 0' "$pareto" > "$data/$c.pareto"
  done
  gp="$out/$name.gp"
  {
    echo "set terminal pngcairo size $((560 * cols)),$((440 * rows)) font 'sans,10' noenhanced"
    echo "set output '$out/$name.png'"
    echo "set datafile separator ','"
    echo "set logscale xy; set format xy '%g'; set grid xtics ytics lc rgb '#dddddd'; set key bottom left font ',8' opaque"
    echo "set xlabel 'wall time per frame [ms]'; set ylabel 'RMS error / body size'"
    echo "set multiplot layout $rows,$cols title '$name: error against run time per case (Pareto front in black)'"
    for c in $cases; do
      echo "set title '$c'"
      echo "plot '$data/$c.all' using 5:6 with points pt 7 ps 0.6 lc rgb '#aaaaaa' title 'all substeps x iterations', \\"
      echo "     '$data/$c.substeps' using 5:6 with linespoints lw 1.5 pt 5 ps 0.8 lc rgb '#1f77b4' title 'n substeps x 1 iteration', \\"
      echo "     '$data/$c.iterations' using 5:6 with linespoints lw 1.5 pt 9 ps 0.9 lc rgb '#d62728' title '1 substep x n iterations', \\"
      echo "     '$data/$c.pareto' using 5:6 with linespoints lw 3 pt 6 ps 1.4 lc rgb '#000000' title 'Pareto front'"
    done
    echo "unset multiplot"
  } > "$gp"
  gnuplot "$gp"
  rm -r "$data"
  echo "wrote $out/$name.png and $pareto ($n cases)"
done
