set terminal svg size 1440,440 dynamic font 'sans,11'
set output 'benchmarks/results/error_vs_time/error_vs_time.svg'
set datafile separator ','
set logscale xy; set grid; set key bottom left font ',9'
set multiplot layout 1,3
set title 'chain: error vs time per frame'; set xlabel 'wall time per frame [ms]'; set ylabel 'RMS error / size'
plot 'benchmarks/results/error_vs_time/error_vs_time.csv' using (strcol(1) eq 'chain' ? $5 : NaN):(strcol(1) eq 'chain' ? $6 : NaN) with points pt 7 ps 0.5 lc rgb '#999999' title 'all substeps x iterations', \
     'benchmarks/results/error_vs_time/error_vs_time.csv' using (strcol(1) eq 'chain' && $3 == 1 ? $5 : NaN):(strcol(1) eq 'chain' && $3 == 1 ? $6 : NaN) with linespoints pt 5 lc rgb '#1f77b4' title 'n substeps x 1 iteration', \
     'benchmarks/results/error_vs_time/error_vs_time.csv' using (strcol(1) eq 'chain' && $2 == 1 ? $5 : NaN):(strcol(1) eq 'chain' && $2 == 1 ? $6 : NaN) with linespoints pt 9 lc rgb '#d62728' title '1 substep x n iterations'
set title 'nh_bar: error vs time per frame'; set xlabel 'wall time per frame [ms]'; set ylabel 'RMS error / size'
plot 'benchmarks/results/error_vs_time/error_vs_time.csv' using (strcol(1) eq 'nh_bar' ? $5 : NaN):(strcol(1) eq 'nh_bar' ? $6 : NaN) with points pt 7 ps 0.5 lc rgb '#999999' title 'all substeps x iterations', \
     'benchmarks/results/error_vs_time/error_vs_time.csv' using (strcol(1) eq 'nh_bar' && $3 == 1 ? $5 : NaN):(strcol(1) eq 'nh_bar' && $3 == 1 ? $6 : NaN) with linespoints pt 5 lc rgb '#1f77b4' title 'n substeps x 1 iteration', \
     'benchmarks/results/error_vs_time/error_vs_time.csv' using (strcol(1) eq 'nh_bar' && $2 == 1 ? $5 : NaN):(strcol(1) eq 'nh_bar' && $2 == 1 ? $6 : NaN) with linespoints pt 9 lc rgb '#d62728' title '1 substep x n iterations'
set title 'nh_cube: error vs time per frame'; set xlabel 'wall time per frame [ms]'; set ylabel 'RMS error / size'
plot 'benchmarks/results/error_vs_time/error_vs_time.csv' using (strcol(1) eq 'nh_cube' ? $5 : NaN):(strcol(1) eq 'nh_cube' ? $6 : NaN) with points pt 7 ps 0.5 lc rgb '#999999' title 'all substeps x iterations', \
     'benchmarks/results/error_vs_time/error_vs_time.csv' using (strcol(1) eq 'nh_cube' && $3 == 1 ? $5 : NaN):(strcol(1) eq 'nh_cube' && $3 == 1 ? $6 : NaN) with linespoints pt 5 lc rgb '#1f77b4' title 'n substeps x 1 iteration', \
     'benchmarks/results/error_vs_time/error_vs_time.csv' using (strcol(1) eq 'nh_cube' && $2 == 1 ? $5 : NaN):(strcol(1) eq 'nh_cube' && $2 == 1 ? $6 : NaN) with linespoints pt 9 lc rgb '#d62728' title '1 substep x n iterations'
unset multiplot
