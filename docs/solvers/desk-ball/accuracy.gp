set terminal pngcairo size 900,600 font ',10'
if (!exists('outfile')) outfile = 'accuracy.png'
set output outfile
set datafile separator ','
set logscale xy
set key top right
set xlabel 'CPU time per simulated second (s)'
set ylabel 'worst structural strain over the run'
set title 'desk-ball: error against run time (Pareto front joined)'
plot 'accuracy.csv' skip 1 using 2:3 with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'configurations', \
     '' skip 1 using 2:($6 == 1 ? $3 : 1/0) smooth unique with linespoints pt 7 ps 1.6 lw 2 lc rgb '#d62728' title 'Pareto front', \
     '' skip 1 using 2:3:1 with labels offset 0,1 font ',7' notitle
