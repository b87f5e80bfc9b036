#pragma once
// InputError and SourceLocation live in common/ (atonlab/common/error.h), below
// every library that reads input; this header keeps the old include working.
#include "atonlab/common/error.h"
