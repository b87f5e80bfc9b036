#pragma once
// `atonlab view SCENE.toml [--set key=value]...` (docs/view.md): an
// interactive preview window. Exit status: 0, 2 bad input, 3 no window or no
// GL 4.5, 4 the study file given with --db failed.
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace atonlab::runner {

struct ViewOptions {
    std::string scene;
    std::vector<std::string> overrides;
    double time_s = 0.0;
    bool paused = false;
    int frames = 0;          ///< > 0: stop after this many frames (with a fixed 1/60 s step)
    std::string screenshot;  ///< write the last displayed frame here (PNG)
    std::string keys;        ///< scripted keys, one per frame: "g,t,w*30"
    std::string display;     ///< with db: encode for this display's measured calibration
    std::string db;
    bool visible = true;
};

void add_view_command(CLI::App& app, ViewOptions& options);
int run_view(const ViewOptions& options);

}  // namespace atonlab::runner
