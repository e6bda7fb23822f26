set terminal pngcairo size 900,600 font ',11'
if (!exists('outfile')) outfile = 'performance.png'
set output outfile
set logscale xy
set grid
set key top left
set xlabel 'particles (hang2, N x N)'
set ylabel 'ms per simulated frame (1/60 s)'
set title 'hang2: wall time per frame against particle count'
plot 'performance.dat' index 0 with linespoints lw 2 pt 7 title 'Drape, 1 thread', 'performance.dat' index 1 with linespoints lw 2 pt 7 title 'Drape, 2 threads', 'performance.dat' index 2 with linespoints dt 2 pt 5 title 'naive Gauss-Seidel, 10 sweeps', 'performance.dat' index 3 with linespoints dt 2 pt 5 title 'naive Gauss-Seidel, 200 sweeps', 2.5e-4*x with lines dt 3 lc 'gray' title 'linear in particles'
