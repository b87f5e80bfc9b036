#pragma once
// InputError and SourceLocation live in common (atonlab/common/input_error.h),
// the one error type of every library's input; this header stays so that the
// files that include it by its old name need no edit.
#include "atonlab/common/input_error.h"
