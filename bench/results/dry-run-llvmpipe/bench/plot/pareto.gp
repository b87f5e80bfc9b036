# Time against error per knob, Pareto front as a line, the default as a red star.
set terminal pngcairo size 1560,2940 font 'sans,9' noenhanced
set output 'pareto.png'
set multiplot layout 7,3
set logscale xy
set grid
set key off
set format x '%.0e'
set xlabel 'error'
set ylabel 'time (ms)'
set title 'psf_size'
set xlabel 'relative L2 of the display kernel vs N=128 double' font 'sans,7'
plot 'plot/psf_size.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/psf_size-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/psf_size.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/psf_size.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'spectral_samples'
set xlabel 'relative L2 of the RGB PSF vs the same path in double at 32 samples (N=64)' font 'sans,7'
plot 'plot/spectral_samples.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/spectral_samples-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/spectral_samples.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/spectral_samples.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'spectral_path'
set xlabel 'relative L2 of the RGB PSF vs exact 32 wavelengths (N=64)' font 'sans,7'
plot 'plot/spectral_path.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/spectral_path-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/spectral_path.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/spectral_path.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'spectral_path_k2012'
set xlabel 'relative L2 of the RGB PSF vs exact 32 wavelengths (N=64)' font 'sans,7'
plot 'plot/spectral_path_k2012.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/spectral_path_k2012-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/spectral_path_k2012.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/spectral_path_k2012.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'cie_veil'
set xlabel '|L/E ÷ CIE GSF − 1| at the pixel nearest θ to the right of the light (age 25, p = 0.5)' font 'sans,7'
plot 'plot/cie_veil.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/cie_veil-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/cie_veil.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/cie_veil.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'cie_veil_methods'
set xlabel 'worst |L/E ÷ CIE GSF − 1| at 1°, 2°, 5°, 10°, 15° from one light (age 25, p = 0.5)' font 'sans,7'
plot 'plot/cie_veil_methods.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/cie_veil_methods-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/cie_veil_methods.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/cie_veil_methods.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'cie_veil_crossover'
set xlabel 'largest per-pixel |direct − FFT| / (|direct| + 1e-12 of the peak)' font 'sans,7'
plot 'plot/cie_veil_crossover.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/cie_veil_crossover-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/cie_veil_crossover.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/cie_veil_crossover.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'psf_rebuild'
set xlabel 'relative L2 of the RGB PSF vs the one-thread PSF (0: identical)' font 'sans,7'
plot 'plot/psf_rebuild.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/psf_rebuild-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/psf_rebuild.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/psf_rebuild.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'fft_n128'
set xlabel 'relative L2 vs FFTW double' font 'sans,7'
plot 'plot/fft_n128.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/fft_n128-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/fft_n128.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/fft_n128.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'pupil_tolerance'
set xlabel 'worst relative L2 of the PSF vs the exact pupil (N=64, hippus)' font 'sans,7'
plot 'plot/pupil_tolerance.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/pupil_tolerance-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/pupil_tolerance.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/pupil_tolerance.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'moving_pupil'
set xlabel 'worst relative L2 of the kernel vs the exact pupil's (N=64, dusk to night, 10 s)' font 'sans,7'
plot 'plot/moving_pupil.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/moving_pupil-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/moving_pupil.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/moving_pupil.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'area_layers'
set xlabel 'worst relative L2 vs the exact disc convolution, radii 0–8 px' font 'sans,7'
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
set title 'tonemap_pfstools'
set xlabel 'mean |display code difference| (8 bit) vs pfstmo_reinhard02, sRGB-rounded' font 'sans,7'
plot 'plot/tonemap_pfstools.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/tonemap_pfstools-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/tonemap_pfstools.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/tonemap_pfstools.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
set title 'display_skips'
set xlabel 'max display code change (continuous, before dither) vs the exact frame' font 'sans,7'
plot 'plot/display_skips.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/display_skips-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/display_skips.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/display_skips.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
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
set title 'eye_validation'
set xlabel '|core FWHM / diffraction limit 1.029 λ/D − 1|; the whole table in eye_validation.md' font 'sans,7'
plot 'plot/eye_validation.dat' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \
     'plot/eye_validation-front.dat' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \
     'plot/eye_validation.dat' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \
     'plot/eye_validation.dat' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'
unset multiplot
