#pragma once
// When a command draws a progress bar: only on a terminal, never into a pipe, a file or a
// CI log (where the carriage returns would pile up as one long line).
//
// Thread context: non-real-time command code.

namespace app::fatigue {

/// True when `fd` is a terminal and the user did not pass --no-progress.
bool show_progress(bool no_progress, int fd);

}  // namespace app::fatigue
