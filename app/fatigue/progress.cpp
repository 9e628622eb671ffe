#include "fatigue/progress.hpp"

#include <unistd.h>

namespace app::fatigue {

bool show_progress(bool no_progress, int fd) { return !no_progress && isatty(fd) == 1; }

}  // namespace app::fatigue
