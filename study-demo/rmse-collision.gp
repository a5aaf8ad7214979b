# ulam study: rmse-collision; redraw with: cd study-demo && gnuplot rmse-collision.gp
set terminal pngcairo size 1100,750 font 'sans,10'
set output 'rmse-collision.png'
set datafile separator ','
set grid
set title 'ulam study: RMSE of x_{2} against seconds per run, collision estimator'
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel 'seconds per run'
set ylabel 'RMSE (reference lines: the error of one run)'
set key outside bottom center horizontal maxrows 4 font ',8'
Y0 = 2.34009e-09
set yrange [Y0:*]
set fit quiet
set fit logfile '/dev/null'
f(x) = a / sqrt(x)
a = 0
fit f(x) 'summary.csv' u 8:4 via a
M = "adjoint-collision-plain forward-collision-plain "
C = "#1b9e77 #d95f02 #7570b3 #e7298a #66a61e #a6761d"
B = "1000 10000 "
P = "7 5 9 11 13 6 4 8 10 12 1 2 3 14 15 16"
stats 'summary.csv' u ($8 > 0 ? $8 : 1/0) nooutput
X0 = STATS_min
X1 = STATS_max
stats 'reference.csv' u (strcol(1) ne 'lapack' && $2 > 0 ? $2 : 1/0) nooutput
X0 = 10**floor(log10(STATS_min < X0 ? STATS_min : X0))
X1 = 10**ceil(log10(STATS_max > X1 ? STATS_max : X1))
set xrange [X0:X1]
LX = 0.02234038799906557
LY = 4.4408920985006262e-16
lx = LX < X0 ? X0 : LX > X1 ? X1 : LX
ly = LY < Y0 ? 2 * Y0 : LY
lt = 'LAPACK: error 4.4e-16 in 0.0223 s '.(LY < Y0 ? '↓' : '').(LX > X1 ? '→' : LX < X0 ? '←' : '')
if (lx != LX || ly != LY) {
  if (lx > sqrt(X0 * X1)) {
    set label 1 lt at lx, ly right offset character -1.5, 0 font ',9'
  } else {
    set label 1 lt at lx, ly left offset character 1.5, 0 font ',9'
  }
}
plot for [i=1:words(M)] 'summary.csv' u (strcol(1) eq word(M, i) && $11 == 0 ? $8 : 1/0):4 w l lw 2 linecolor rgb word(C, i) dashtype i title word(M, i), for [i=1:words(M)] for [j=1:words(B)] 'summary.csv' u (strcol(1) eq word(M, i) && $2 == word(B, j) + 0 && $11 == 0 ? $8 : 1/0):4 w p linecolor rgb word(C, i) pointtype (word(P, j) + 0) notitle, for [j=1:words(B)] NaN w p lc 'black' pointtype (word(P, j) + 0) title sprintf('%.0f walks', word(B, j) + 0), 'reference.csv' u (strcol(1) eq 'gs' ? $2 : 1/0):3 w l lw 3 lc 'gray50' t 'Gauss-Seidel, whole vector', '' u (strcol(1) eq 'lapack' ? lx : 1/0):(ly) w p pt 9 ps 2 lc 'web-green' t 'LAPACK dgesv', '' u (strcol(1) eq 'cg' || strcol(1) eq 'gmres' ? $2 : 1/0):3 w lp lw 1 pt 3 lc 'dark-cyan' t 'Krylov', f(x) dt 4 lc 'gray30' t '1/sqrt(t)'

set output
