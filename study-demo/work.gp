# ulam study: work; redraw with: cd study-demo && gnuplot work.gp
set terminal pngcairo size 1000,500 font 'sans,10'
set output 'work.png'
set datafile separator ','
set grid
set title 'work-normalised variance RMSE^2 x seconds at the largest budget (lower wins)'
set style data histograms
set style fill solid 0.6
set logscale y
set format y '10^{%L}'
set ylabel 'RMSE^2 x seconds per run'
set xtics rotate by 35 right font ',8'
set bmargin 10
set key off
plot 'bars.csv' skip 1 u 2:xtic(1)

set output
