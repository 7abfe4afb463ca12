// SIGINT and SIGTERM ask a run to stop: the run loop ends its step, writes a checkpoint, the
// series, a frame and summary.json, and `tlsph` exits with 128 + the signal number (130, 143). The
// handlers are one-shot (SA_RESETHAND): a second signal ends the process at once.
#pragma once

#include <csignal>

namespace tlsph {

// The signal that asked for the stop, 0 if none. A signal handler can only talk to the program
// through a variable of static storage: this is the one.
inline volatile std::sig_atomic_t& stopSignal() {
  static volatile std::sig_atomic_t signal = 0;
  return signal;
}

inline bool stopRequested() {
  return stopSignal() != 0;
}

extern "C" inline void tlsphOnStopSignal(int signal) {
  stopSignal() = signal;
}

inline void installStopHandlers() {
  stopSignal() = 0;
  struct sigaction action = {};
  action.sa_handler = tlsphOnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // A file grown past the size limit (ulimit -f) is a failed write the run reports, with a
  // checkpoint attempt, rather than a signal that kills it.
  std::signal(SIGXFSZ, SIG_IGN);
}

}  // namespace tlsph
