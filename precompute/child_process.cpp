#include "precompute/child_process.h"

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <ctime>

#include <spawn.h>
#include <sys/wait.h>

extern char** environ;

namespace quiver {

namespace {

// Set by whichever thread takes the signal (MPI's own threads too), read by the waiting one.
std::atomic<int> caught{0};
static_assert(std::atomic<int>::is_always_lock_free, "written from a signal handler");

extern "C" void remember(int s) { caught.store(s); }

constexpr int kStopping[] = {SIGINT, SIGTERM, SIGHUP};
constexpr int kCount = sizeof kStopping / sizeof kStopping[0];

// The stopping signals caught (where not ignored) for as long as it lives, then as they were.
struct CaughtSignals {
  struct sigaction previous[kCount];
  CaughtSignals() {
    caught.store(0);
    struct sigaction action {};
    action.sa_handler = remember;
    sigemptyset(&action.sa_mask);
    for (int k = 0; k < kCount; ++k) {
      sigaction(kStopping[k], nullptr, &previous[k]);
      if (previous[k].sa_handler != SIG_IGN) sigaction(kStopping[k], &action, nullptr);
    }
  }
  ~CaughtSignals() {
    for (int k = 0; k < kCount; ++k) sigaction(kStopping[k], &previous[k], nullptr);
  }
  CaughtSignals(const CaughtSignals&) = delete;
  CaughtSignals& operator=(const CaughtSignals&) = delete;
};

void pause10ms() {
  const timespec pause{0, 10'000'000};
  nanosleep(&pause, nullptr);
}

// Whether `pid` ended within `polls` polls of 10 ms (its status in `status`).
bool reaped(pid_t pid, int& status, int polls) {
  for (int k = 0; k < polls; ++k, pause10ms()) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid || (done < 0 && errno == ECHILD)) return true;
  }
  return false;
}

// Asks the child to stop, then, after two seconds, makes it.
void stop(pid_t pid) {
  int status = 0;
  kill(pid, SIGTERM);
  if (reaped(pid, status, 200)) return;
  kill(pid, SIGKILL);
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
}

} // namespace

Interrupted::Interrupted(int s) : std::runtime_error(std::string("interrupted by ") + strsignal(s)), signal(s) {}

int runChild(const std::string& command, double seconds) {
  const CaughtSignals signals;
  std::string shell = "sh", dashC = "-c", text = command;
  char* argv[] = {shell.data(), dashC.data(), text.data(), nullptr};
  // The child starts with no signal blocked, whatever this thread blocks.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, "/bin/sh", nullptr, &attributes, argv, environ);
  posix_spawnattr_destroy(&attributes);
  if (error != 0) throw std::runtime_error(std::string("cannot start /bin/sh: ") + std::strerror(error));
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(std::fmin(seconds, 1e9));
  // Polled, so that a signal between a check and a blocking wait cannot be missed: the runs take
  // seconds, the polls 10 ms.
  for (;; pause10ms()) {
    if (const int s = caught.load()) {
      stop(pid);
      throw Interrupted(s);
    }
    if (std::chrono::steady_clock::now() > deadline) {
      stop(pid);
      throw OutOfTime("the child ran past its time");
    }
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) throw std::runtime_error(std::string("waitpid: ") + std::strerror(errno));
  }
  // Ctrl-C reaches the whole process group: the child may end of it before the poll sees it.
  if (const int s = caught.load()) throw Interrupted(s);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

} // namespace quiver
