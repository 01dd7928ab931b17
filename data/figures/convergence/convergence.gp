# made by jetfit convergence; run in this folder: gnuplot convergence.gp
set terminal pngcairo size 640,480 font ',10' noenhanced
set datafile separator ','
set key outside right
set grid
$deg_interp << EOD
1,1.35924,0.621156,nan,nan,nan,nan
2,2.56963,2.06472,0.882893,0.262313,1.40282,0.969465
3,2.45153,1.3259,1.70749,0.826269,1.73468,0.739782
4,4.42408,3.77311,2.80522,2.33224,2.97767,2.40404
5,4.38581,3.48118,2.9925,2.20279,3.29381,2.41486
6,5.81831,4.8296,4.04257,3.1845,4.271,3.23236
7,6.12786,5.26699,4.61881,3.9536,4.88234,3.92559
8,7.17298,6.50725,5.49656,4.93853,5.67147,4.82284
9,7.53739,6.88402,6.05157,5.49391,6.42951,5.89697
EOD
set xlabel 'log(1/h)'
set ylabel 'log(1/delta)'
set output 'normal_interp.png'
set title 'exp graph: normal error (average) vs h, interp'
plot for [d=1:9] 'convergence.csv' skip 1 using (strcol(1) eq 'interp' && $2 == d ? log(1/$3) : 1/0):(log(1/$4)) with linespoints title sprintf('deg %d', d)
set output 'kmin_interp.png'
set title 'exp graph: kmin error (average) vs h, interp'
plot for [d=2:9] 'convergence.csv' skip 1 using (strcol(1) eq 'interp' && $2 == d ? log(1/$3) : 1/0):(log(1/$6)) with linespoints title sprintf('deg %d', d)
set output 'kmax_interp.png'
set title 'exp graph: kmax error (average) vs h, interp'
plot for [d=2:9] 'convergence.csv' skip 1 using (strcol(1) eq 'interp' && $2 == d ? log(1/$3) : 1/0):(log(1/$8)) with linespoints title sprintf('deg %d', d)
set output 'degree_interp.png'
set xlabel 'degree'
set ylabel 'log(1/delta)/log(1/h)'
set title 'exp graph: errors vs degree at h = 0.0625, interp'
plot $deg_interp using 1:2 with linespoints title 'normal_av', $deg_interp using 1:3 with linespoints title 'normal_max', $deg_interp using 1:4 with linespoints title 'kmin_av', $deg_interp using 1:5 with linespoints title 'kmin_max', $deg_interp using 1:6 with linespoints title 'kmax_av', $deg_interp using 1:7 with linespoints title 'kmax_max'
$deg_approx << EOD
1,1.58691,1.29012,nan,nan,nan,nan
2,2.25759,2.02937,0.919809,0.475594,1.2744,1.02405
3,3.15908,2.83093,1.80736,1.2441,1.99164,1.7578
4,3.92756,3.58146,2.36528,1.92463,2.8723,2.41951
5,4.47883,4.03575,2.94598,2.60575,3.21273,2.86909
6,5.11598,4.57134,3.50485,3.09045,4.03993,3.69087
7,5.45655,4.92237,4.00106,3.70824,4.293,3.95201
8,6.13192,5.72404,4.64308,4.04979,5.04274,4.48231
9,6.40954,5.87459,4.84252,4.40736,5.10817,4.61559
EOD
set xlabel 'log(1/h)'
set ylabel 'log(1/delta)'
set output 'normal_approx.png'
set title 'exp graph: normal error (average) vs h, approx'
plot for [d=1:9] 'convergence.csv' skip 1 using (strcol(1) eq 'approx' && $2 == d ? log(1/$3) : 1/0):(log(1/$4)) with linespoints title sprintf('deg %d', d)
set output 'kmin_approx.png'
set title 'exp graph: kmin error (average) vs h, approx'
plot for [d=2:9] 'convergence.csv' skip 1 using (strcol(1) eq 'approx' && $2 == d ? log(1/$3) : 1/0):(log(1/$6)) with linespoints title sprintf('deg %d', d)
set output 'kmax_approx.png'
set title 'exp graph: kmax error (average) vs h, approx'
plot for [d=2:9] 'convergence.csv' skip 1 using (strcol(1) eq 'approx' && $2 == d ? log(1/$3) : 1/0):(log(1/$8)) with linespoints title sprintf('deg %d', d)
set output 'degree_approx.png'
set xlabel 'degree'
set ylabel 'log(1/delta)/log(1/h)'
set title 'exp graph: errors vs degree at h = 0.0625, approx'
plot $deg_approx using 1:2 with linespoints title 'normal_av', $deg_approx using 1:3 with linespoints title 'normal_max', $deg_approx using 1:4 with linespoints title 'kmin_av', $deg_approx using 1:5 with linespoints title 'kmin_max', $deg_approx using 1:6 with linespoints title 'kmax_av', $deg_approx using 1:7 with linespoints title 'kmax_max'
