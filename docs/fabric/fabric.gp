set terminal pngcairo size 1200,440 font ',10'
if (!exists('outfile')) outfile = 'fabric.png'
set output outfile
set datafile separator ','
set multiplot layout 1,2 title 'drape-cli fabric: the textile lab'
set logscale x 2
set xrange [2.6:15]
set xtics ('3.125' 3.125, '6.25' 6.25, '12.5' 12.5)
set xlabel 'lattice spacing (mm)'
set grid
set title 'Peirce cantilever: bending length against (B / (rho g))^{1/3}, every preset'
set ylabel 'error (%)'
set yrange [-30:10]
set key bottom right
plot 'cantilever.csv' every ::1 using ((strcol(5) eq 'gauss-seidel' && $16 == 0 && $4 == 2) ? $2 * 1000 * (1 + -0.03) : 1/0):($12 * 100) with points pt 4 ps 1.2 title '2 sweeps, GS', 'cantilever.csv' every ::1 using ((strcol(5) eq 'gauss-seidel' && $16 == 0 && $4 == 16) ? $2 * 1000 * (1 + 0) : 1/0):($12 * 100) with points pt 6 ps 1.2 title '16 sweeps, GS', 'cantilever.csv' every ::1 using ((strcol(5) eq 'lines' && $16 == 0 && $4 == 2) ? $2 * 1000 * (1 + 0.03) : 1/0):($12 * 100) with points pt 8 ps 1.2 title '2 sweeps, lines', 'cantilever.csv' every ::1 using ((strcol(5) eq 'lines' && $16 == 0 && $4 == 16) ? $2 * 1000 * (1 + 0.06) : 1/0):($12 * 100) with points pt 10 ps 1.2 title '16 sweeps, lines', 'cantilever.csv' every ::1 using ((strcol(5) eq 'lines' && $16 == 1 && $4 == 2) ? $2 * 1000 * (1 + 0.09) : 1/0):($12 * 100) with points pt 12 ps 1.2 title '2 sweeps, lines, 10 substeps', 5 with lines dt 2 lc rgb 'black' title '+-5 %', -5 with lines dt 2 lc rgb 'black' notitle
set title 'Cusick drape coefficient, 4 sweeps with lines (10, 20, 40 substeps)'
set ylabel 'drape coefficient'
set yrange [0:1]
set key bottom right
plot 'drape-series.csv' every ::1 using ($1 * 1000):2 with linespoints lw 2 pt 7 title 'silk', 'drape-series.csv' every ::1 using ($1 * 1000):3 with linespoints lw 2 pt 7 title 'jersey', 'drape-series.csv' every ::1 using ($1 * 1000):4 with linespoints lw 2 pt 7 title 'cotton', 'drape-series.csv' every ::1 using ($1 * 1000):5 with linespoints lw 2 pt 7 title 'denim', 'drape-series.csv' every ::1 using ($1 * 1000):6 with linespoints lw 2 pt 7 title 'polyester'
unset multiplot
