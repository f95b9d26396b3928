# femdyn study: dexterous finger (generated; gnuplot study.gp)
set terminal pngcairo size 1100,700 font 'sans,11'
if (!exists('out')) out = 'study.png'
set output out
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel "wall time (s): median of 5 timed runs after a warm-up (3 for runs of 50 ms or longer)" noenhanced
set ylabel "relative state error: max(|Δθ| / max|θ|, |Δθ̇| / max|θ̇|)   (θ in rad, θ̇ in rad/s)" noenhanced
set title "Work-precision: dexterous finger, t = 0…1 s\nboth engines land on each of the 20 samples" noenhanced
set grid
set key outside right top
$d0 << EOD
6.7347e-05 2.5594e-06
0.000105149 1.52988e-07
0.000202384 9.35156e-09
0.000399285 5.78136e-10
0.000821752 3.59493e-11
EOD
$d1 << EOD
6.7933e-05 0.0108241
0.000105994 0.00542546
0.000231627 0.00271609
0.000414345 0.00135888
0.00084066 0.000679653
0.00168835 0.000339879
0.00331535 0.000169953
0.00679583 8.49795e-05
0.0136634 4.24906e-05
0.0268598 2.12455e-05
0.0573894 1.06228e-05
0.113391 5.31141e-06
0.231778 2.65572e-06
0.428353 1.32787e-06
0.871688 6.63886e-07
EOD
$d2 << EOD
0.000249343 6.51137e-09
0.000174778 6.51137e-09
0.000173223 6.51137e-09
0.000151124 6.50087e-09
0.000150046 6.49341e-09
0.000242591 3.53738e-09
0.000319715 6.04551e-10
0.00039517 2.58173e-11
0.000563609 6.8615e-12
EOD
$d3 << EOD
0.000110185 0.00089902
8.9782e-05 0.000694326
0.000196762 7.54724e-05
0.000260664 1.50265e-05
0.000311916 2.28689e-06
0.000347208 3.66681e-07
0.000484409 6.99886e-08
0.000547477 8.54101e-09
0.000795751 7.58341e-10
EOD
$d4 << EOD
0.00123863 1.60136e-06
0.00122607 1.60136e-06
0.00118074 1.60136e-06
0.00130466 1.60136e-06
0.00181818 5.68855e-07
0.00260843 4.83547e-08
0.00405581 4.43798e-09
0.00562634 5.92706e-10
0.0101388 7.85786e-11
EOD
$d5 << EOD
0.000883975 2.68472e-05
0.000816133 2.68472e-05
0.000958316 2.24411e-05
0.00184889 3.17689e-06
0.00338729 3.81546e-07
0.00722643 4.172e-08
0.0153284 4.13972e-09
0.0317088 4.20232e-10
0.0653272 4.24013e-11
EOD
$d6 << EOD
0.00152225 2.60956e-07
0.00152887 2.60956e-07
0.0015957 2.60956e-07
0.00148359 2.60956e-07
0.00154455 2.60956e-07
0.00155904 2.60956e-07
0.00223593 6.52586e-08
0.00340264 9.92868e-09
0.00413733 1.6694e-09
EOD
$d7 << EOD
0.000777938 0.000746121
0.000745358 0.000746121
0.00118293 0.000494862
0.00194392 0.000123053
0.00382575 2.76056e-05
0.00815356 6.29373e-06
0.0168372 1.37002e-06
0.037337 2.9728e-07
0.0964209 6.46854e-08
EOD
$d8 << EOD
0.000848294 0.0212471
0.00141864 0.0161686
0.00388309 0.00588022
0.00915499 0.00192382
0.0257179 0.000617774
0.0748865 0.000195899
0.246332 6.20247e-05
0.837226 1.96177e-05
2.62272 6.20408e-06
EOD
$d9 << EOD
0.000908839 0.0146153
0.00116031 0.00325832
0.00149862 0.000268931
0.00199854 7.15196e-05
0.00234238 5.491e-06
0.00300946 6.75337e-07
0.00394817 1.21915e-07
0.00501718 2.97528e-08
0.00738338 4.68728e-09
EOD
plot keyentry with lines lt nodraw title '{/:Bold femdyn} (solid)', \
     $d0 using 1:2 with linespoints lw 2 pt 7 dt 1 lc rgb '#d62728' title 'rk4' noenhanced, \
     $d1 using 1:2 with linespoints lw 2 pt 7 dt 1 lc rgb '#ff7f0e' title 'euler' noenhanced, \
     $d2 using 1:2 with linespoints lw 2 pt 7 dt 1 lc rgb '#8c564b' title 'dopri' noenhanced, \
     $d3 using 1:2 with linespoints lw 2 pt 7 dt 1 lc rgb '#e377c2' title 'bdf' noenhanced, \
     keyentry with lines lt nodraw title ' ', \
     keyentry with lines lt nodraw title '{/:Bold Simbody} (dashed)', \
     $d4 using 1:2 with linespoints lw 1.5 pt 6 dt 2 lc rgb '#1f77b4' title 'RungeKuttaMerson' noenhanced, \
     $d5 using 1:2 with linespoints lw 1.5 pt 6 dt 2 lc rgb '#2ca02c' title 'RungeKutta3' noenhanced, \
     $d6 using 1:2 with linespoints lw 1.5 pt 6 dt 2 lc rgb '#17becf' title 'RungeKuttaFeldberg' noenhanced, \
     $d7 using 1:2 with linespoints lw 1.5 pt 6 dt 2 lc rgb '#9467bd' title 'Verlet' noenhanced, \
     $d8 using 1:2 with linespoints lw 1.5 pt 6 dt 2 lc rgb '#7f7f7f' title 'SemiExplicitEuler2' noenhanced, \
     $d9 using 1:2 with linespoints lw 1.5 pt 6 dt 2 lc rgb '#393b79' title 'CPodes' noenhanced
