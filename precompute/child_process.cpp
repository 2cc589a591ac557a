#include "precompute/child_process.h"

#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>

#include <spawn.h>
#include <sys/wait.h>

extern char** environ;

namespace quiver {

namespace {

volatile std::sig_atomic_t caught = 0;

extern "C" void remember(int s) { caught = s; }

constexpr int kStopping[] = {SIGINT, SIGTERM, SIGHUP};
constexpr int kCount = sizeof kStopping / sizeof kStopping[0];

// The stopping signals caught (where not ignored) for as long as it lives, then as they were.
struct CaughtSignals {
  struct sigaction previous[kCount];
  CaughtSignals() {
    caught = 0;
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

} // namespace

Interrupted::Interrupted(int s) : std::runtime_error(std::string("interrupted by ") + strsignal(s)), signal(s) {}

int runChild(const std::string& command) {
  const CaughtSignals signals;
  std::string shell = "sh", dashC = "-c", text = command;
  char* argv[] = {shell.data(), dashC.data(), text.data(), nullptr};
  pid_t pid = 0;
  if (const int error = posix_spawn(&pid, "/bin/sh", nullptr, nullptr, argv, environ); error != 0)
    throw std::runtime_error(std::string("cannot start /bin/sh: ") + std::strerror(error));
  int status = 0;
  // Polled, so that a signal between a check and a blocking wait cannot be missed: the runs take
  // seconds, the polls 10 ms.
  for (;;) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) throw std::runtime_error(std::string("waitpid: ") + std::strerror(errno));
    if (caught) {
      const int s = caught;
      kill(pid, SIGTERM);
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      throw Interrupted(s);
    }
    const timespec pause{0, 10'000'000};
    nanosleep(&pause, nullptr);
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

} // namespace quiver
