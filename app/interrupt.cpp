#include "app/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <stdexcept>

#include "engine/solver/neighbours.h"

namespace phyxel::app {
namespace {

std::atomic<int> g_signal{0};
std::atomic<bool> g_installed{false};
static_assert(std::atomic<int>::is_always_lock_free, "the handler needs a lock-free atomic");

struct sigaction g_previous_int, g_previous_term;

// Async-signal-safe: an atomic store, or _exit on the second signal.
extern "C" void on_signal(int sig) {
  int none = 0;
  if (!g_signal.compare_exchange_strong(none, sig)) _exit(128 + sig);
}

}  // namespace

InterruptGuard::InterruptGuard() {
  if (g_installed.exchange(true)) throw std::logic_error("InterruptGuard: one at a time");
  g_signal.store(0);
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // an interrupted read or write goes on; the loop polls the flag
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
  // The neighbour search, which may take seconds before the run loop polls, polls it too.
  set_search_stop([] { return g_signal.load(std::memory_order_relaxed) != 0; });
}

InterruptGuard::~InterruptGuard() {
  set_search_stop({});
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
  g_installed.store(false);
}

int InterruptGuard::received() {
  return g_signal.load(std::memory_order_relaxed);
}

int interrupted_exit_status(int sig) {
  return 128 + sig;
}

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return "signal";
  }
}

}  // namespace phyxel::app
