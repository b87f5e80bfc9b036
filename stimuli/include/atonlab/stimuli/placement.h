#pragma once
// Where a glare stage's heavy arithmetic runs (issue 27 item 1): the `cie`
// veil's frame convolution and the PSF's FFTs. Automatic picks the
// GPU on a hardware driver and the CPU on a software rasteriser (llvmpipe,
// softpipe, swrast), where "the GPU" is the same CPU without FFTW; a scene's
// `[glare] placement` forces either (docs/scene-file.md). The placement a
// frame used is written with every render, EXR header and trial.
#include <optional>
#include <string_view>

namespace atonlab::stimuli {

enum class ComputePlacement {
    automatic,  ///< the CPU on a software rasteriser, else the GPU
    gpu,        ///< compute shaders, fp32 (each placement's error: docs/pipeline.md)
    cpu,        ///< FFTW double
};

std::string_view placement_name(ComputePlacement p);  ///< "automatic", "gpu", "cpu"
std::optional<ComputePlacement> placement_from_name(std::string_view name);

/// Whether the current GL context renders in software (llvmpipe, softpipe, swrast).
bool software_renderer();
/// `p` with automatic resolved for the current GL context (gpu or cpu): the
/// CPU where there is no current context (a caller without GL: the unit
/// tests, `atonlab glare`).
ComputePlacement resolve_placement(ComputePlacement p);

}  // namespace atonlab::stimuli
