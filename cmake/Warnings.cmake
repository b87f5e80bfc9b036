# Compile policy for every atonlab target (after pbrt's pbrt_warnings).
add_library(atonlab_warnings INTERFACE)
target_compile_options(atonlab_warnings INTERFACE
  -Wall -Wextra -Wpedantic
  -Wshadow                 # a shadowed name in numeric code is a bug waiting to happen
  -Wconversion             # silent double -> float narrowing changes photometric results
  -Wno-sign-conversion     # size_t/int mixing in loops is noise, -Wconversion covers the real cases
  -Wnon-virtual-dtor
  -Wold-style-cast
  -Wimplicit-fallthrough)
if(ATONLAB_WERROR)
  target_compile_options(atonlab_warnings INTERFACE -Werror)
endif()

add_library(atonlab_sanitize INTERFACE)
if(ATONLAB_SANITIZE)
  target_compile_options(atonlab_sanitize INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(atonlab_sanitize INTERFACE -fsanitize=address,undefined)
  # GCC's -Wmaybe-uninitialized is unreliable under the sanitizers' instrumentation
  # (GCC's manual: "sanitizers tend to increase the rate of false positive warnings, most notably those around -Wmaybe-uninitialized"): GCC 12 reports std::function's
  # members inside <regex> as maybe uninitialized, which stopped the
  # ATONLAB_SANITIZE=1 build three times (test_image_commands, test_run_session,
  # test_procedure_registry). The normal build keeps the warning.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(atonlab_sanitize INTERFACE -Wno-maybe-uninitialized)
  endif()
endif()

# The fuzz build (fuzz/, docs/fuzzing.md): every library instrumented for
# libFuzzer's coverage, with ASan and UBSan; only the fuzz targets link the
# fuzzer's main (-fsanitize=fuzzer). clang only.
if(ATONLAB_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "ATONLAB_FUZZ needs clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++ "
                        "-DCMAKE_C_COMPILER=clang, as scripts/fuzz.sh does")
  endif()
  target_compile_options(atonlab_sanitize INTERFACE -fsanitize=fuzzer-no-link,address,undefined
                         -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(atonlab_sanitize INTERFACE -fsanitize=address,undefined)
endif()

# Every atonlab library and executable links this.
add_library(atonlab_policy INTERFACE)
target_link_libraries(atonlab_policy INTERFACE atonlab_warnings atonlab_sanitize)
