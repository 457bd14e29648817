#pragma once
// dsp::Spill on disk: an unnamed temporary file (O_TMPFILE, gone when closed or when the
// process dies), written through a buffer and read back in large blocks. What keeps the
// samples an evaluation reads twice out of memory when the run is long.
#include "dsp/core/spill.hpp"

#include <filesystem>

namespace eical::drivers {

// Spills in `dir` (a disk, not tmpfs: /var/tmp, or eicald's recording directory).
// A spill that cannot be created, written or read throws std::runtime_error naming the
// directory — a fault of the storage, not of the run (no InputError: nothing in dsp/
// mistakes it for bad input and carries on with a flag).
dsp::SpillFactory file_spills(std::filesystem::path dir);

// $TMPDIR when set, else /var/tmp (which Debian keeps on disk).
std::filesystem::path default_spill_dir();

}  // namespace eical::drivers
