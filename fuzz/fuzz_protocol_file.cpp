// libFuzzer target: the protocol-file loader (protocols/src/protocol_file.cpp)
// on arbitrary text, and for a protocol it accepts, the first trials of its
// schedule (every procedure is built and answered), as `atonlab run` would.
// An InputError is the expected refusal; anything else is a finding
// (docs/fuzzing.md).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"

namespace p = atonlab::protocols;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    p::Protocol protocol;
    try {
        protocol = p::parse_protocol(text, "fuzz/protocol.toml");
    } catch (const atonlab::InputError&) {
        return 0;  // a refusal with a sentence
    }
    // An accepted protocol must schedule and take its task's answers.
    p::Schedule schedule(protocol);
    for (int i = 0; i < 40; ++i) {
        const auto trial = schedule.next();
        if (!trial) break;
        switch (trial->task) {
            case p::Task::TwoAfc:
                schedule.record(i % 3 == 0 ? p::Response::Left : p::Response::Right);
                break;
            case p::Task::YesNo:
                schedule.record(i % 3 == 0 ? p::Response::No : p::Response::Yes);
                break;
            case p::Task::Adjust:
                schedule.record(i % 4 == 3 ? p::Response::Confirm
                                           : (i % 2 ? p::Response::CoarseUp : p::Response::FineDown));
                break;
        }
    }
    return 0;
}
