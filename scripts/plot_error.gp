# Error against run time, one point per mode and scene (docs/performance.md).
# Reads DIR/bench.csv written by `bsprt bench` (columns: see apps/bench_report.h):
#   gnuplot -e "dir='docs/perf'; rays='vertex'" scripts/plot_error.gp
# Writes DIR/error-vs-time-RAYS.png and .svg. x: wall ns per ray (single rays,
# all threads); left: lost + farther (leaks) per million rays; right: max |t - t_exact|
# in ulps over rays both hit (0 drawn at 0.5 so it shows on the log axis).
if (!exists("dir")) dir = 'docs/perf'
if (!exists("rays")) rays = 'vertex'
csv = dir . '/bench.csv'
set datafile separator ','
modes = "kd bsp bsp-zero-eps bsp-certified embree embree-fast brute-certified exact"
scenes = system("tail -n +2 " . csv . " | cut -d, -f1 | awk '!s[$0]++' | tr '\\n' ' '")
set key outside right top box
set logscale x
set xlabel 'ns per ray (single rays, all threads) — lower is faster'
set grid
do for [fmt in "png svg"] {
  if (fmt eq "png") { set terminal pngcairo size 1400,560 font ',10' } else { set terminal svg size 1400,560 dynamic font 'sans,10' }
  set output dir . '/error-vs-time-' . rays . '.' . fmt
  set multiplot layout 1,2 title sprintf("Error against run time on %s rays (one point per mode and scene; exact reference: CGAL)", rays)
  set ylabel 'lost + farther (leaks) per million rays'
  unset logscale y
  set yrange [-5:*]
  plot for [i=1:words(modes)] csv skip 1 using \
       ((strcol(3) eq rays && strcol(4) eq word(modes,i)) ? $25 : 1/0):24 \
       with points pt (i+4) ps 1.6 lw 2 title word(modes,i)
  set ylabel 'max t error (ulps) — 0 drawn at 0.5'
  set logscale y
  set yrange [0.3:*]
  plot for [i=1:words(modes)] csv skip 1 using \
       ((strcol(3) eq rays && strcol(4) eq word(modes,i)) ? $25 : 1/0):($22 > 0.5 ? $22 : 0.5) \
       with points pt (i+4) ps 1.6 lw 2 title word(modes,i)
  unset multiplot
  unset yrange
}
