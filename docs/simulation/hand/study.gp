# femdyn study: dexterous hand (generated; gnuplot study.gp)
set terminal pngcairo size 1100,700 font 'sans,11'
if (!exists('out')) out = 'study.png'
set output out
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel "wall time (s): median of 5 timed runs after a warm-up (3 for runs of 50 ms or longer)" noenhanced
set ylabel "relative state error: max(|Δθ| / max|θ|, |Δθ̇| / max|θ̇|)   (θ in rad, θ̇ in rad/s)" noenhanced
set title "Work-precision: dexterous hand, t = 0…0.25 s\nboth engines interpolate at the 20 samples (dense output; rk4, euler land on them)" noenhanced
set grid
set key outside right top
$d0 << EOD
0.000305436 2.68166
0.000541155 0.0395043
0.00109392 0.00103981
0.00215587 5.94753e-05
0.0042755 4.29053e-06
0.00859769 3.20245e-07
0.0172647 2.16919e-08
0.0373099 1.40889e-09
EOD
$d1 << EOD
0.000326475 1.45373
0.000559231 0.400687
0.00118387 0.192188
0.00261181 0.145298
0.00451393 0.0751868
0.00938776 0.0367531
0.018847 0.0180114
0.038773 0.0088978
0.0942149 0.00442004
0.17292 0.00220258
0.298309 0.0010994
0.637036 0.000549226
1.18451 0.000274494
2.26448 0.000137217
EOD
$d2 << EOD
0.00119084 0.0370038
0.00144665 0.00186963
0.00208319 0.000287571
0.00331677 7.65526e-06
0.00460937 5.02148e-07
0.00701927 4.76917e-08
0.0107888 4.86707e-09
0.0171544 4.87082e-10
EOD
$d3 << EOD
0.00287818 0.0415986
0.00428836 0.0180762
0.00521722 0.00173091
0.00693365 0.000439813
0.0101389 3.16347e-05
0.0143692 7.59951e-06
0.019685 6.3189e-07
0.0286503 2.28555e-07
0.0410306 3.49685e-08
EOD
$d4 << EOD
0.00796897 0.042707
0.0106971 0.00892503
0.0165944 0.000944218
0.0277171 0.000113009
0.053419 1.32092e-05
0.074907 1.54261e-06
0.127973 1.53051e-07
0.236635 1.61537e-08
0.438776 1.24309e-09
EOD
$d5 << EOD
0.0104462 0.034576
0.0191877 0.00209604
0.0372315 0.000161893
0.0772556 1.05925e-05
0.152226 8.94495e-07
0.315279 1.54692e-07
0.671429 1.49695e-08
1.4478 1.36031e-09
3.25423 1.50583e-10
EOD
$d6 << EOD
0.0074063 0.240009
0.0119919 0.0726855
0.0131151 0.00709669
0.0188274 0.000257463
0.0267112 0.000125106
0.0385096 1.61209e-05
0.0574398 1.99886e-06
0.101679 2.78136e-07
0.149763 4.54186e-08
EOD
$d7 << EOD
0.00700712 0.375649
0.00981576 0.0728741
0.0168828 0.00777684
0.0321496 0.00169302
0.0688932 0.00029962
0.136852 7.27313e-05
0.28505 1.37521e-05
0.6392 3.81344e-06
1.4732 8.1378e-07
EOD
$d8 << EOD
0.0168044 0.417636
0.060346 0.190743
0.166172 0.0581215
0.461808 0.0182363
1.40534 0.00556604
4.5037 0.00186561
EOD
$d9 << EOD
0.0136188 0.162466
0.0180667 0.0674078
0.0264386 0.00796782
0.0373391 0.00169481
0.0499867 0.000420301
0.089939 4.3428e-05
0.106232 4.78985e-06
0.137746 8.03535e-07
0.198704 9.20547e-08
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
