# Build time and traversal speed against triangle count, log-log, with the
# fitted BSP build exponent (build ~ n^b) and the paper's exact build rate
# (25-65 triangles per second) for reference. Reads the random-ray rows of
# DIR/bench.csv (the meshes), DIR/interior.csv (sponza, conference) and
# DIR/scaling.csv (generated icospheres and the full dragon):
#   gnuplot -e "dir='docs/perf'" scripts/plot_scaling.gp
# Writes DIR/scaling.png, DIR/scaling.svg and DIR/scaling-fit.txt ("b <value> kd_b <value>").
if (!exists("dir")) dir = 'docs/perf'
data = '< tail -q -n +2 ' . dir . '/bench.csv ' . dir . '/interior.csv ' . dir . '/scaling.csv'
set datafile separator ','
sel(m) = (strcol(3) eq 'random' && strcol(4) eq m)
# Meshes (not the icospheres) get their name beside the bsp point.
named(m) = sel(m) && strstrt(strcol(1), 'icosphere') == 0
lx(m) = sel(m) ? log10($2) : 1/0
fb(x) = ab + b * x
fk(x) = ak + bk * x
ab = -4; b = 1.2; ak = -5; bk = 1.0
set fit quiet logfile '/dev/null'
fit fb(x) data using (lx('bsp')):(log10($6)) via ab, b
fit fk(x) data using (lx('kd')):(log10($6)) via ak, bk
set print dir . '/scaling-fit.txt'
print sprintf("b %.3f kd_b %.3f", b, bk)
set print
modes = "bsp kd embree"
set logscale xy
set grid
set key top left box
set xlabel 'triangles'
do for [fmt in "png svg"] {
  if (fmt eq "png") { set terminal pngcairo size 1400,560 font ',10' } else { set terminal svg size 1400,560 dynamic font 'sans,10' }
  set output dir . '/scaling.' . fmt
  set multiplot layout 1,2 title 'Scaling: shared meshes and generated icospheres (random rays)'
  set ylabel 'build seconds'
  plot for [i=1:words(modes)] data using (sel(word(modes,i)) ? $2 : 1/0):6 with points pt (i+4) ps 1.5 lw 2 title word(modes,i), \
       data using (named('bsp') ? $2 : 1/0):6:1 with labels left offset 0.8,-0.4 font ',8' notitle, \
       10**ab * x**b with lines dt 2 lc 1 title sprintf('bsp fit: n^{%.2f}', b), \
       10**ak * x**bk with lines dt 3 lc 2 title sprintf('kd fit: n^{%.2f}', bk), \
       x / 65.0 with lines lw 2 lc rgb '#999999' title 'paper, exact build: 65 triangles/s', \
       x / 25.0 with lines lw 2 dt 4 lc rgb '#999999' title 'paper: 25 triangles/s'
  set ylabel 'Mrays/s (single rays, all threads)'
  plot for [i=1:words(modes)] data using (sel(word(modes,i)) ? $2 : 1/0):7 with points pt (i+4) ps 1.5 lw 2 title word(modes,i)
  unset multiplot
}
