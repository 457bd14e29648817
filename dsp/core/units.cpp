// dsp/core is header-mostly; this translation unit keeps the folder a real library and
// checks that the core headers compile on their own.
#include "dsp/core/units.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/frame.hpp"
#include "dsp/core/run.hpp"
#include "dsp/core/run_meta.hpp"
