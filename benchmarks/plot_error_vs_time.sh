#!/usr/bin/env bash
# Runs error_vs_time and plots error against wall time per frame (log-log),
# one panel per case: points of equal total sweeps joined, substep-only runs
# (1 iteration) and iteration-only runs (1 substep) highlighted.
#   benchmarks/plot_error_vs_time.sh [BUILD_DIR] [OUT_DIR] [extra error_vs_time args]
set -euo pipefail
build=${1:-build}
out=${2:-error_vs_time_out}
shift $(( $# > 2 ? 2 : $# ))
"$build/benchmarks/error_vs_time" --out "$out" "$@"
command -v gnuplot >/dev/null || { echo "gnuplot not found (apt-get install gnuplot-nox): CSV only"; exit 0; }
csv="$out/error_vs_time.csv"
cases=$(tail -n +2 "$csv" | cut -d, -f1 | sort -u)
n=$(echo "$cases" | wc -l)
{
  echo "set terminal svg size $((480 * n)),440 dynamic font 'sans,11'"
  echo "set output '$out/error_vs_time.svg'"
  echo "set datafile separator ','"
  echo "set logscale xy; set grid; set key bottom left font ',9'"
  echo "set multiplot layout 1,$n"
  for c in $cases; do
    echo "set title '$c: error vs time per frame'; set xlabel 'wall time per frame [ms]'; set ylabel 'RMS error / size'"
    echo "plot '$csv' using (strcol(1) eq '$c' ? \$5 : NaN):(strcol(1) eq '$c' ? \$6 : NaN) with points pt 7 ps 0.5 lc rgb '#999999' title 'all substeps x iterations', \\"
    echo "     '$csv' using (strcol(1) eq '$c' && \$3 == 1 ? \$5 : NaN):(strcol(1) eq '$c' && \$3 == 1 ? \$6 : NaN) with linespoints pt 5 lc rgb '#1f77b4' title 'n substeps x 1 iteration', \\"
    echo "     '$csv' using (strcol(1) eq '$c' && \$2 == 1 ? \$5 : NaN):(strcol(1) eq '$c' && \$2 == 1 ? \$6 : NaN) with linespoints pt 9 lc rgb '#d62728' title '1 substep x n iterations'"
  done
  echo "unset multiplot"
} > "$out/error_vs_time.gp"
gnuplot "$out/error_vs_time.gp"
echo "wrote $out/error_vs_time.svg"
