#pragma once
// The engine of `atonlab run` (docs/running.md): a protocol's trials rendered
// headless, answered by a model or scripted observer, each committed to the
// study file before the next is shown. run_command.cpp is the command line
// around it.
//
// The parts live in session/: stimulus_renderer.h (a frame's overrides → the
// displayed luminance around each judged light, cached), session_inputs.h
// (options, protocol and scene checked), condition_scene.h, resume.h,
// session_observer.h, session_display.h, trial_loop.h, trial_record.h, snapshot.h,
// true_value.h, progress.h, summary.h. run_session() drives them: load and
// validate everything, open the store, begin or resume a session, run the
// trials, summarise.
#include "atonlab/runner/session/run_options.h"
#include "atonlab/runner/session/session_observer.h"
#include "atonlab/runner/session/stimulus_renderer.h"
#include "atonlab/runner/session/true_value.h"

namespace atonlab::runner {

/// Runs `atonlab run` (RunOptions in session/run_options.h). Returns the exit status: 0
/// when the session completed, 128 + N when signal N stopped it between trials.
/// Throws InputError (bad protocol, scene, script or options),
/// gl::ContextUnavailable, store::StoreError.
int run_session(const RunOptions& options);

}  // namespace atonlab::runner
