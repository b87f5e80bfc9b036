// libFuzzer target: the scene-file loader (stimuli/src/scene_file.cpp) on
// arbitrary text. Any input must either give a Scene or an InputError (exit 2
// in the binary); anything else (another exception, a crash, an ASan or UBSan
// report, a timeout) is a finding (docs/fuzzing.md).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        (void)atonlab::stimuli::parse_scene(text, "fuzz.toml", {});
    } catch (const atonlab::InputError&) {
        // A refusal with a sentence: the expected outcome for bad input.
    }
    return 0;
}
