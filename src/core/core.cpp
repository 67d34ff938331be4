// Compiles every shared header once for the CPU so that a header that is not valid C++ fails the
// library build, not a downstream user's.
#include "msm/msm.h"
