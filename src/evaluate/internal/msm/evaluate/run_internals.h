// The evaluation's hook for the CLI tests (`msm evaluate --stop-after`), outside the installed API:
// this header is on msm::evaluate's include path in the build tree only (src/evaluate/CMakeLists.txt)
// and is not installed.
#pragma once

#include <cstdint>

namespace msm::evaluate {

// After this many candidates of this rank are checkpointed, run_evaluation ends the process at once
// (std::_Exit(3), as if killed), so that a test can resume from the checkpoint. < 0 (the default):
// never. For the whole process; set before run_evaluation.
void set_stop_after(std::int64_t candidates);

} // namespace msm::evaluate
