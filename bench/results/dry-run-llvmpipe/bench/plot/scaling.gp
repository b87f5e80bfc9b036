# Frame time against the number of lights, per series.
set terminal pngcairo size 900,600 font 'sans,10' noenhanced
set output 'scaling.png'
set logscale xy
set grid
set key top left
set xlabel 'lights'
set ylabel 'frame time (ms)'
set xrange [0.35:20000]
set xtics ('0' 0.5, '1' 1, '10' 10, '100' 100, '1000' 1000, '10000' 10000)
set title 'K2012 table 6.2 scene: frame time against the number of lights'
plot 'plot/scaling-visible__overlapping.dat' using 1:2:3:4 with yerrorlines title 'visible, overlapping', \
     'plot/scaling-visible__apart.dat' using 1:2:3:4 with yerrorlines title 'visible, apart', \
     'plot/scaling-visible__apart__skips_off_.dat' using 1:2:3:4 with yerrorlines title 'visible, apart (skips off)', \
     'plot/scaling-culled__behind_the_eye.dat' using 1:2:3:4 with yerrorlines title 'culled: behind the eye', \
     'plot/scaling-culled__dark_in_rhythm.dat' using 1:2:3:4 with yerrorlines title 'culled: dark in rhythm', \
     'plot/scaling-culled__too_dim.dat' using 1:2:3:4 with yerrorlines title 'culled: too dim'
