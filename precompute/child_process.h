#pragma once
// A helper program (gmsh: GPL, so run, never linked) as a child process that does not outlive an
// interrupted bake. std::system() ignored SIGINT while the child ran and left SIGTERM's default:
// a bake killed while gmsh meshed left gmsh running and its temporary folder behind.
#include <stdexcept>
#include <string>

namespace quiver {

// SIGINT, SIGTERM or SIGHUP arrived while a child ran: the child was terminated and waited for.
// Thrown so that the stack (and its temporary folders) unwinds; quiver-bake's main then raises the
// signal again, and the bake ends as signalled.
struct Interrupted : std::runtime_error {
  int signal;
  explicit Interrupted(int s);
};

// The child still ran when its time was up: it was terminated and waited for.
struct OutOfTime : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Runs `command` with /bin/sh -c and waits for it, at most `seconds` (infinity: as long as it
// runs); returns its exit status (128 + the signal that killed it). Throws Interrupted or OutOfTime
// (above), or std::runtime_error when /bin/sh cannot start. Signals the bake ignores (nohup's
// SIGHUP) stay ignored.
int runChild(const std::string& command, double seconds);

} // namespace quiver
