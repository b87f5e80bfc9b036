#pragma once
// Every adaptive procedure of atonlab::protocols, for code that builds them all
// (the protocol-file parser, the runner).
#include "atonlab/protocols/adjustment.h"
#include "atonlab/protocols/constant_stimuli.h"
#include "atonlab/protocols/forced_choice.h"
#include "atonlab/protocols/interleaver.h"
#include "atonlab/protocols/procedure.h"
#include "atonlab/protocols/quest.h"
#include "atonlab/protocols/rng.h"
#include "atonlab/protocols/staircase.h"
#include "atonlab/protocols/weighted_staircase.h"
