set terminal pngcairo size 1000,650 font 'sans,11'
set output 'scaling.png'
set logscale xy
set xrange [5:1500]
set xlabel 'bodies n (random serial chain)'
set ylabel 'ns per call (median)'
set key top left
set grid
set title 'femdyn (solid) and Simbody (dashed) on random chains, same run'
plot 'chains.dat' u 1:2 w lp lw 2 lc 1 t 'femdyn M^s', \
     '' u 1:3 w lp lw 2 lc 2 t 'femdyn h', \
     '' u 1:4 w lp lw 2 lc 3 t 'femdyn τ', \
     '' u 1:5 w lp lw 2 lc 4 t 'femdyn q̈', \
     '' u 1:6 w lp dt 2 lc 1 t 'Simbody M', \
     '' u 1:9 w lp dt 2 lc 4 t 'Simbody q̈', \
     '' u 1:(5e2*$1) w l lc 'gray' dt 3 t 'O(n)', \
     '' u 1:(5e1*$1*$1) w l lc 'gray' dt 4 t 'O(n²)'
