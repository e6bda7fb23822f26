set terminal pngcairo size 1500,360 font ',10'
set output 'docs/stability/stability.png'
set datafile separator ','
set multiplot layout 1,5 title 'Undamped oscillator, 1 kg on a spring: stable (green), damped (blue), diverged (red); line: linear theory dt = bound / omega'
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel 'dt (s)'
set ylabel 'k (N/m)'
unset key
set xrange [1e-05:0.1]
set yrange [5:2e7]
set title 'explicit-euler'
plot 'docs/stability/stability.csv' using ((strcol(1) eq 'explicit-euler') ? $3 : 1/0):2:(strcol(5) eq 'stable' ? 0x2ca02c : strcol(5) eq 'damped' ? 0x1f77b4 : 0xd62728) with points pt 5 ps 0.6 lc rgb variable
set title 'symplectic-euler'
plot 'docs/stability/stability.csv' using ((strcol(1) eq 'symplectic-euler') ? $3 : 1/0):2:(strcol(5) eq 'stable' ? 0x2ca02c : strcol(5) eq 'damped' ? 0x1f77b4 : 0xd62728) with points pt 5 ps 0.6 lc rgb variable, [y=5:2e7] '+' using (2/sqrt(y)):(y) with lines lw 2 lc rgb 'black'
set title 'verlet'
plot 'docs/stability/stability.csv' using ((strcol(1) eq 'verlet') ? $3 : 1/0):2:(strcol(5) eq 'stable' ? 0x2ca02c : strcol(5) eq 'damped' ? 0x1f77b4 : 0xd62728) with points pt 5 ps 0.6 lc rgb variable, [y=5:2e7] '+' using (2/sqrt(y)):(y) with lines lw 2 lc rgb 'black'
set title 'midpoint'
plot 'docs/stability/stability.csv' using ((strcol(1) eq 'midpoint') ? $3 : 1/0):2:(strcol(5) eq 'stable' ? 0x2ca02c : strcol(5) eq 'damped' ? 0x1f77b4 : 0xd62728) with points pt 5 ps 0.6 lc rgb variable
set title 'rk4'
plot 'docs/stability/stability.csv' using ((strcol(1) eq 'rk4') ? $3 : 1/0):2:(strcol(5) eq 'stable' ? 0x2ca02c : strcol(5) eq 'damped' ? 0x1f77b4 : 0xd62728) with points pt 5 ps 0.6 lc rgb variable, [y=5:2e7] '+' using (2.82843/sqrt(y)):(y) with lines lw 2 lc rgb 'black'
unset multiplot
