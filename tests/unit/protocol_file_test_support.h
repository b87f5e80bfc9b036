#pragma once
// What the protocol file's tests (test_protocol_file*.cpp) share: the example
// protocols, and inline protocols after a fixed 9-line header with the two
// ways to read them (the protocol, or the one-sentence error it gives), and
// random answers for a schedule.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/rng.h"

namespace atonlab::protocols::protocol_file_test {

inline std::filesystem::path source_dir() {
    return std::filesystem::path(ATONLAB_SOURCE_DIR);
}
inline std::filesystem::path example(std::string_view name) {
    return source_dir() / "protocols" / "examples" / name;
}

inline const std::vector<std::string> kExamples = {"glare_brightness_2afc.toml", "glare_brightness_adjust.toml",
                                                   "glare_constant_stimuli.toml", "flash_detection.toml",
                                                   "glare_side_by_side.toml"};

/// An inline protocol: this header (9 lines), then its body.
inline constexpr const char* kHeader = R"([protocol]
scene = "scene.toml"
seed = 5

[display]
width_px = 800
height_px = 600
width_m = 0.4
viewing_distance_m = 0.6
)";

inline Protocol parse(const std::string& body) {
    return parse_protocol(std::string(kHeader) + body, "inline.toml");
}

inline std::string error_of(const std::string& body) {
    try {
        (void)parse(body);
    } catch (const atonlab::InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

/// A response the task takes, drawn from `rng`.
inline Response random_response(Task task, Rng& rng) {
    switch (task) {
        case Task::TwoAfc:
            return rng.coin() ? Response::Left : Response::Right;
        case Task::YesNo:
            return rng.coin() ? Response::Yes : Response::No;
        case Task::Adjust: {
            constexpr Response kActions[] = {Response::CoarseUp, Response::CoarseDown, Response::FineUp,
                                             Response::FineDown, Response::Confirm};
            return kActions[rng.below(5)];
        }
    }
    return Response::No;
}

}  // namespace atonlab::protocols::protocol_file_test
