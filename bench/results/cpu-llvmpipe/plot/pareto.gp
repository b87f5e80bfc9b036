# Time against error per knob, Pareto front as a line, the default as a red star.
set terminal pngcairo size 1560,2520 font 'sans,9' noenhanced
set output 'pareto.png'
set multiplot layout 6,3
set logscale xy
set grid
set key off
set format x '%.0e'
set xlabel 'error'
set ylabel 'time (ms)'
set title 'psf_size'
set xlabel 'relative L2 of the display kernel vs N=2048 double' font 'sans,7'
plot 'plot/psf_size.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/psf_size-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/psf_size.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/psf_size.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'spectral_samples'
set xlabel 'relative L2 of the RGB PSF vs the same path in double at 120 samples (N=256)' font 'sans,7'
plot 'plot/spectral_samples.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/spectral_samples-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/spectral_samples.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/spectral_samples.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'spectral_path'
set xlabel 'relative L2 of the RGB PSF vs exact 120 wavelengths (N=256)' font 'sans,7'
plot 'plot/spectral_path.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/spectral_path-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/spectral_path.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/spectral_path.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'spectral_path_no_E'
set xlabel 'relative L2 of the RGB PSF vs exact 120 wavelengths (N=256)' font 'sans,7'
plot 'plot/spectral_path_no_E.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/spectral_path_no_E-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/spectral_path_no_E.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/spectral_path_no_E.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'fft_n512'
set xlabel 'relative L2 vs FFTW double' font 'sans,7'
plot 'plot/fft_n512.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/fft_n512-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/fft_n512.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/fft_n512.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'fft_n1024'
set xlabel 'relative L2 vs FFTW double' font 'sans,7'
plot 'plot/fft_n1024.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/fft_n1024-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/fft_n1024.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/fft_n1024.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'fft_n2048'
set xlabel 'relative L2 vs FFTW double' font 'sans,7'
plot 'plot/fft_n2048.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/fft_n2048-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/fft_n2048.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/fft_n2048.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'pupil_tolerance'
set xlabel 'worst relative L2 of the PSF vs the exact pupil (N=256, hippus)' font 'sans,7'
plot 'plot/pupil_tolerance.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/pupil_tolerance-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/pupil_tolerance.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/pupil_tolerance.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'area_layers'
set xlabel 'worst relative L2 vs the exact disc convolution, radii 0–32 px' font 'sans,7'
plot 'plot/area_layers.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/area_layers-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/area_layers.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/area_layers.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'hdr_format'
set xlabel 'max continuous display code change vs the RGBA32F frame (CPU double tone mapping)' font 'sans,7'
plot 'plot/hdr_format.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/hdr_format-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/hdr_format.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/hdr_format.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'adaptation_stride'
set xlabel 'max display code change (continuous) from the adaptation error' font 'sans,7'
plot 'plot/adaptation_stride.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/adaptation_stride-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/adaptation_stride.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/adaptation_stride.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'tonemap_empirical'
set xlabel 'max display code difference (8 bit, dithered) vs the CPU double reference' font 'sans,7'
plot 'plot/tonemap_empirical.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/tonemap_empirical-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/tonemap_empirical.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/tonemap_empirical.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'tonemap_perceptual'
set xlabel 'max display code difference (8 bit, dithered) vs the CPU double reference' font 'sans,7'
plot 'plot/tonemap_perceptual.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/tonemap_perceptual-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/tonemap_perceptual.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/tonemap_perceptual.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'tonemap_reinhard'
set xlabel 'max display code difference (8 bit, dithered) vs the CPU double reference' font 'sans,7'
plot 'plot/tonemap_reinhard.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/tonemap_reinhard-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/tonemap_reinhard.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/tonemap_reinhard.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'tonemap_kakimoto'
set xlabel 'max display code difference (8 bit, dithered) vs the CPU double reference' font 'sans,7'
plot 'plot/tonemap_kakimoto.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/tonemap_kakimoto-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/tonemap_kakimoto.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/tonemap_kakimoto.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'tonemap_linear'
set xlabel 'max display code difference (8 bit, dithered) vs the CPU double reference' font 'sans,7'
plot 'plot/tonemap_linear.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/tonemap_linear-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/tonemap_linear.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/tonemap_linear.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'tonemap_clamp'
set xlabel 'max display code difference (8 bit, dithered) vs the CPU double reference' font 'sans,7'
plot 'plot/tonemap_clamp.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/tonemap_clamp-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/tonemap_clamp.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/tonemap_clamp.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'display_skips'
set xlabel 'max display code change (continuous, before dither) vs the exact frame' font 'sans,7'
plot 'plot/display_skips.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/display_skips-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/display_skips.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/display_skips.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
unset multiplot
