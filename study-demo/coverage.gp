# ulam study: coverage; redraw with: cd study-demo && gnuplot coverage.gp
set terminal pngcairo size 1000,500 font 'sans,10'
set output 'coverage.png'
set datafile separator ','
set grid
set title 'coverage of the 95% interval at the largest budget, with its 95% binomial interval'
set style data histograms
set style histogram errorbars gap 1 lw 1
set style fill solid 0.6
set yrange [0:1.05]
set ylabel 'share of runs whose 95% interval holds x_I'
set xtics rotate by 35 right font ',8'
set bmargin 10
set rmargin 7
set key off
set label 1 '0.95' at graph 1, first 0.95 offset 0.5, 0 left font ',8'
plot 'bars.csv' skip 1 u 3:5:6:xtic(1), 0.95 dt 2 lc 'black'

set output
