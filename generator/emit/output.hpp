// Writing the files of one generation into a folder: all of them or none, never
// through a planted symbolic link, serialised with any other proxgen writing
// into the same folder, and cleaned up when the process is interrupted.
// Every output of proxgen (the solver's two files, the files `verify --keep`
// keeps, other outputs later) goes through writeFiles.
#pragma once

#include <string>
#include <vector>

namespace proxgen::emit {

/// One file to write: a plain file name (no folder part) and its bytes.
struct OutputFile {
  std::string name;
  std::string content;
  bool executable = false;  // mode 0777 instead of 0666 (before the umask)
};

/// Writes `files` into `outDir` (created if missing) so that they appear
/// together or not at all:
///  - the folder is locked (flock on the folder itself) for the whole write, so
///    concurrent runs into one folder serialise and never mix their files;
///  - every file is first written into a fresh private folder
///    (`.proxgen-tmp-XXXXXX`, mkdtemp) inside `outDir`, created exclusively
///    (O_CREAT | O_EXCL | O_NOFOLLOW), so no planted link is ever written through;
///  - every destination is checked before anything is replaced: one that
///    exists and is not a regular file (a folder, a symbolic link, a FIFO) is an
///    error and nothing changes;
///  - then each file is renamed over its destination (a rename replaces the
///    name, never follows a link), the old one kept in the private folder until
///    all are in, so a failure midway puts the old files back;
///  - the private folder is registered for removal on SIGINT/SIGTERM/SIGHUP
///    (installInterruptCleanup).
/// Throws proxgen::Error naming the file and the cause. Returns the paths written.
std::vector<std::string> writeFiles(const std::vector<OutputFile>& files, const std::string& outDir);

/// Removes, on SIGINT, SIGTERM, SIGHUP or SIGQUIT, every path registered with
/// registerTemporary that is still registered, then dies of the signal as it
/// would have. The handler only calls kill, waitpid, nanosleep, unlink, rmdir,
/// signal and raise (async-signal-safe). Called once by the CLI's main.
void installInterruptCleanup();

/// Registers a temporary file or (empty) folder for removal if the process is
/// interrupted; returns a slot for unregisterTemporary. Register a folder
/// before the files in it: they are removed newest first. At most 64 at once;
/// beyond that (or for a path of 4 kB or more) throws proxgen::Error.
int registerTemporary(const std::string& path);
void unregisterTemporary(int slot);

/// The child process (a compiler, verify's driver), leader of its own process
/// group, that the interrupt handler stops (SIGTERM to the group, so a compiler
/// removes its own temporaries; SIGKILL after 5 s) and waits for before it
/// removes the temporaries the child writes into; 0: none.
void setInterruptChild(int pid);

}  // namespace proxgen::emit
