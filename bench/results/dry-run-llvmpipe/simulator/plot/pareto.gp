# Time against error per knob, Pareto front as a line, the default as a red star.
set terminal pngcairo size 1560,420 font 'sans,9' noenhanced
set output 'pareto.png'
set multiplot layout 1,3
set logscale xy
set grid
set key off
set format x '%.0e'
set xlabel 'error'
set ylabel 'time (ms)'
set title 'simulator_frames'
set xlabel 'none (0): frame times of the default pipeline (simulator_frames.md); kernel error in moving_pupil' font 'sans,7'
plot 'plot/simulator_frames.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/simulator_frames-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/simulator_frames.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/simulator_frames.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'simulator_frames_cie'
set xlabel 'none (0): frame times of the default pipeline (simulator_frames.md); kernel error in moving_pupil' font 'sans,7'
plot 'plot/simulator_frames_cie.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/simulator_frames_cie-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/simulator_frames_cie.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/simulator_frames_cie.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
unset multiplot
