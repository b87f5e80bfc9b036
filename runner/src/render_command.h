#pragma once
// `atonlab render` (docs/scene-file.md): one frame of a scene to EXR and PNG.
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace atonlab::runner {

struct RenderOptions {
    std::string scene;
    std::string exr;
    std::string png;
    double time_s = 0.0;
    std::vector<std::string> overrides;
    bool half = false;
    std::optional<double> white_cd_m2;
};

void add_render_command(CLI::App& app, RenderOptions& options);
int run_render(const RenderOptions& options);

}  // namespace atonlab::runner
