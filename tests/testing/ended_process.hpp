#pragma once
// A process ID that no running process has, as a process killed mid-write leaves in the names of
// its temporary files.

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

namespace priormap::testing {

/// The ID of a child process that has ended and been reaped: free until the system hands it out
/// again, which takes a whole cycle of process IDs.
inline pid_t EndedProcessId() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

}  // namespace priormap::testing
