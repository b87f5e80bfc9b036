#pragma once
// The PSF on the GPU (K2012 §4.2, §5.2): pupil-plane field → fp32 FFT →
// |F|², cyclic shift, unit sum by a double-precision reduction → one mip level
// → spectral integration → RGB PSF with unit luminance sum. Everything stays in
// GPU buffers; read_mono()/read_rgb() download for tests, files and the
// billboard kernel. Needs a current GL 4.5 context for its whole life.
#include <memory>
#include <vector>

#include "atonlab/stimuli/fft.h"
#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/placement.h"
#include "atonlab/stimuli/psf.h"

namespace atonlab::stimuli {

/// GPU time of the last generate() per stage (ms), from timer queries (fft_ms:
/// the CPU's steady clock when the FFT ran on the CPU; for a two-scale eye, the
/// CPU's whole mono PSF: pupil planes, FFTs and binning). generate_anchored():
/// upload_ms the CPU's pupil planes (unless drawn ahead) and their upload (steady clock), fft_ms
/// every anchor's transforms, mono_ms their |F|², binning and unit sums,
/// spectral_ms the samples from the anchors and the unit luminance.
struct PsfGpuTimings {
    double upload_ms = 0, fft_ms = 0, mono_ms = 0, spectral_ms = 0;
};

/// The CPU's share of GpuPsfGenerator::generate_anchored(): each anchor's
/// pupil plane drawn in double (a two-scale eye: its scatter and core fields,
/// pupil_parts) over W·λk/λ0, so that its FFT lands on λ0's grid, and rounded
/// once to float as the generator uploads it. It needs no GL context: the
/// glare stage has a worker thread make a moving pupil's next grid pupils ahead
/// of the frame that needs them (pupil_kernel_cache.h), and that frame then
/// only uploads them.
struct AnchoredPupilPlanes {
    int n = 0;
    std::vector<double> anchor_nm;  ///< spectral_anchor_wavelengths()
    bool two_scales = false;
    /// The generator's FFT placement they are for: gpu, the planes
    /// themselves; cpu, their spectra by FFTW in double.
    ComputePlacement fft = ComputePlacement::gpu;
    /// Anchor i: [i·parts] the scatter (a one-scale eye: the whole plane), [i·parts + 1] the core (parts = 2).
    std::vector<ComplexImage<float>> fields;
};

/// The fields generate_anchored(eye, samples, anchors, time_s) uploads, all
/// anchors at once on the cores, for a generator whose FFT runs at `fft`
/// (gpu or cpu; std::invalid_argument for automatic, which only a GL
/// context can resolve). Throws as pupil_plane() does.
AnchoredPupilPlanes anchored_pupil_planes(const EyeModel& eye, int n, const SpectralSamples& samples, int anchors,
                                          double time_s = 0.0, ComputePlacement fft = ComputePlacement::gpu);

class GpuPsfGenerator {
public:
    /// n: a power of two in [kGpuFftMinSize, kGpuFftMaxSize] (InputError, key "size", otherwise).
    /// fft: where the generator's FFT runs (placement.h). The pupil plane is
    /// drawn on the CPU anyway, so transforming it there (FFTW double, rounded
    /// once to float) and uploading the spectrum replaces the compute-shader
    /// FFT: far cheaper where the "GPU" is the CPU (a software rasteriser;
    /// `atonlab bench`, fft_n512 on llvmpipe: 18 ms against 190 ms, and exact),
    /// far dearer than a real GPU's. automatic: the CPU on a software
    /// rasteriser, else the GPU.
    explicit GpuPsfGenerator(int n, TwiddleSource twiddles = TwiddleSource::table_from_double,
                             ComputePlacement fft = ComputePlacement::automatic);
    ~GpuPsfGenerator();
    GpuPsfGenerator(GpuPsfGenerator&&) noexcept;
    GpuPsfGenerator& operator=(GpuPsfGenerator&&) noexcept;

    int size() const;
    /// The pupil-plane field at λ0 (n×n), the PSF's angular texel (degrees) and
    /// the spectral samples (at most 128; InputError, key "spectral_samples").
    void generate(const ComplexImage<double>& pupil_field, double degrees_per_texel, const SpectralSamples& samples);
    /// The same from a monochromatic PSF at λ0 already made (unit sum, n×n):
    /// upload, then the mip level and the spectral integration.
    void generate(const MonoPsf& psf_at_reference_wavelength, const SpectralSamples& samples);
    /// An eye's PSF at time_s: a one-scale eye (k2012_single, or no stretched
    /// scatter) transforms its pupil plane here (one FFT, on the GPU or the CPU
    /// as placed); a two-scale eye builds its parts on the CPU in double
    /// (mono_psf_reference: two FFTW transforms and the core's binning) and
    /// uploads the result.
    void generate(const EyeModel& eye, const SpectralSamples& samples, double time_s = 0.0);
    /// The anchored spectral path (spectral_path.h, the default) of an eye at
    /// time_s, the GPU twin of spectral_psf_anchored(): each anchor's pupil
    /// plane (a two-scale eye: its core and scatter fields, pupil_parts) drawn
    /// on the CPU in double, all anchors at once on the cores; here its
    /// transform(s) (the GPU's fp32 FFT, or FFTW double as placed), |F|², the
    /// core binned by area onto the scatter's grid, unit sum; then every sample
    /// from its anchors by Lanczos-3 and XYZ → RGB (psf_anchored.comp). One
    /// GPU wait: none until read_rgb(). `anchors` as spectral_anchor_wavelengths().
    /// `drawn`: the fields anchored_pupil_planes() made ahead for the same
    /// arguments and this generator's fft_placement() (the same bits as making
    /// them here); std::invalid_argument where its size, anchors, parts or FFT
    /// placement differ from these.
    void generate_anchored(const EyeModel& eye, const SpectralSamples& samples, int anchors, double time_s = 0.0,
                           const AnchoredPupilPlanes* drawn = nullptr);
    MonoPsf read_mono() const;
    RgbPsf read_rgb() const;
    PsfGpuTimings timings() const;
    /// Where the FFT runs (automatic resolved).
    ComputePlacement fft_placement() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace atonlab::stimuli
