#pragma once
// Upper limits on numbers read from scene and protocol files and the command
// line, shared by both readers so a value one accepts the other accepts too
// (docs/fuzzing.md, "Limits on input"). Each is checked where the value is
// read, so no value can reach an internal error further on.

namespace atonlab::limits {

/// The most pixels a side of the display may have. OpenGL 4.5 guarantees
/// textures and framebuffers of 16384 texels a side (the smallest value an
/// implementation may give for GL_MAX_TEXTURE_SIZE and
/// GL_MAX_FRAMEBUFFER_WIDTH/HEIGHT in the GL 4.5 core profile), so every
/// context atonlab runs on can allocate a frame this wide; 16385 cannot be
/// relied on (Mesa llvmpipe refuses it: "framebuffer is incomplete").
inline constexpr int kMaxDisplaySidePx = 16384;

/// The most pixels a display may have in all: 2^26 = 67,108,864 (8192 × 8192;
/// 8K UHD, 7680 × 4320, is 33 Mpx). The pipeline keeps several full-frame
/// RGBA float targets; at this size each is 1 GiB, which a GPU (or llvmpipe's
/// system memory) can still allocate.
inline constexpr long long kMaxDisplayPixels = 1LL << 26;

/// The longest duration in a protocol, seconds: one day. Durations are counted
/// in whole refreshes in an int (runner::frames_for refuses more than 1e9
/// frames); a day at the highest refresh rate a protocol may name (1000 Hz) is
/// 8.64e7 frames, and stays below 1e9 up to 11.5 kHz, a rate no display has.
inline constexpr double kMaxDurationS = 86400.0;

}  // namespace atonlab::limits
