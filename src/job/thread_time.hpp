// The CPU time of the calling thread: job stage timings and dry-run estimates that a busy
// machine does not inflate with the time a worker waits for a core (wall-clock laps did).
#pragma once
#include <time.h>

namespace trivox::job::detail {

/// This thread's CPU time in seconds (CLOCK_THREAD_CPUTIME_ID).
inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace trivox::job::detail
