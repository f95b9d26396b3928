# femdyn study: dexterous finger (generated; gnuplot study.gp)
set terminal pngcairo size 1100,700 font 'sans,11'
if (!exists('out')) out = 'study.png'
set output out
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel "wall time (s): median of 5 timed runs after a warm-up (3 for runs of 50 ms or longer)" noenhanced
set ylabel "relative state error: max(|Δθ| / max|θ|, |Δθ̇| / max|θ̇|)   (θ in rad, θ̇ in rad/s)" noenhanced
set title "Work-precision: dexterous finger, t = 0…1 s\nboth engines interpolate at the 20 samples (dense output; rk4, euler land on them)" noenhanced
set grid
set key outside right top
$d0 << EOD
7.9821e-05 2.5594e-06
0.000127291 1.52988e-07
0.000226158 9.35156e-09
0.000407651 5.78136e-10
0.000865047 3.59493e-11
EOD
$d1 << EOD
7.1817e-05 0.0108241
0.000132204 0.00542546
0.000203966 0.00271609
0.000404257 0.00135888
0.000831988 0.000679653
0.00225522 0.000339879
0.00347785 0.000169953
0.00689483 8.49795e-05
0.0132697 4.24906e-05
0.0270413 2.12455e-05
0.0524895 1.06228e-05
0.105901 5.31141e-06
0.215213 2.65572e-06
0.444613 1.32787e-06
0.85928 6.63886e-07
EOD
$d2 << EOD
0.000115711 0.000726745
8.7169e-05 0.000292667
8.9823e-05 8.55721e-05
9.4679e-05 9.2785e-06
0.000115974 8.80161e-07
0.000157571 1.31644e-07
0.000226657 1.3113e-08
0.000291243 1.06812e-09
0.000439105 1.52235e-10
0.000653431 7.81676e-12
EOD
$d3 << EOD
9.4271e-05 0.00694103
8.1832e-05 0.000898337
0.000115944 0.000189026
0.000173547 2.98072e-05
0.000184615 3.2094e-06
0.000239867 2.54077e-07
0.000324651 8.68596e-08
0.000415148 1.07787e-08
0.000568133 1.58493e-09
EOD
$d4 << EOD
0.00134974 0.0239113
0.00153583 0.000721019
0.00181173 0.000136516
0.00191186 1.22988e-05
0.00242314 1.76671e-06
0.00318232 9.27971e-08
0.00465346 9.63662e-09
0.00681685 1.16329e-09
0.0123651 1.05591e-10
EOD
$d5 << EOD
0.00137614 0.00269831
0.00181079 0.000415872
0.0020035 4.17505e-05
0.00420157 4.2109e-06
0.00445014 4.24858e-07
0.00767805 4.25439e-08
0.0150855 4.24823e-09
0.0360554 4.24385e-10
0.0658408 4.2565e-11
EOD
$d6 << EOD
0.00143683 0.031742
0.00148721 0.00291504
0.0016067 0.000787903
0.00165368 0.000437344
0.00201178 3.56369e-05
0.00223307 9.00661e-06
0.00274355 9.71716e-07
0.00357726 1.23362e-07
0.0046075 3.20381e-08
EOD
$d7 << EOD
0.00145607 0.0103452
0.00158843 0.00259286
0.00194668 0.000562786
0.00276805 0.000132014
0.00484028 2.9002e-05
0.00935014 6.40788e-06
0.017821 1.38312e-06
0.0380189 2.98863e-07
0.094318 6.4879e-08
EOD
$d8 << EOD
0.00142999 0.0566741
0.00209827 0.0184961
0.00348493 0.00612333
0.00855789 0.00195669
0.0259505 0.000620121
0.0806417 0.000196135
0.240213 6.20383e-05
0.768024 1.96192e-05
2.5341 6.20434e-06
EOD
$d9 << EOD
0.000958439 0.0146098
0.00117188 0.00326877
0.00144206 0.000230181
0.00204061 7.17601e-05
0.00230679 5.491e-06
0.00306442 6.75337e-07
0.00382733 1.22082e-07
0.00478439 2.98945e-08
0.00702617 4.69395e-09
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
