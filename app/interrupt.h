// SIGINT and SIGTERM for `phyxel run` and `phyxel view`: the first one asks the command to stop
// (it finishes the current step, writes what it has and exits with 128 + the signal number:
// 130 for SIGINT, 143 for SIGTERM); a second one ends the process at once with _exit(128 +
// its number), writing nothing more (the files already written are whole: the writers replace
// files atomically).
#pragma once

namespace phyxel::app {

// Installs the handlers for its lifetime and restores the previous ones after. One at a time.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  // The first signal received since the guard was made (SIGINT or SIGTERM), 0 while none.
  static int received();
};

// 128 + sig: the exit status of a run stopped by signal `sig`.
int interrupted_exit_status(int sig);
// "SIGINT", "SIGTERM" (another signal: "signal").
const char* signal_name(int sig);

}  // namespace phyxel::app
