#include "emit/output.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <ctime>
#include <mutex>
#include <set>

#include "model/error.hpp"

namespace proxgen::emit {

namespace fs = std::filesystem;

// ---------------------------------------------------------------- interrupt cleanup
namespace {

// Fixed storage: the signal handler may not allocate or lock. A slot's path is
// written completely before its flag is raised (signal fence), and the flag is
// lowered before the slot is reused, so the handler never reads a half-written path.
constexpr int kSlots = 64;
constexpr std::size_t kPathMax = 4096;
char gPaths[kSlots][kPathMax];
volatile std::sig_atomic_t gUsed[kSlots];
std::mutex gRegistryMutex;  // between threads registering; never taken by the handler
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
volatile std::sig_atomic_t gChild = 0;

extern "C" void removeTemporariesAndDie(int sig) {
  const int savedErrno = errno;
  // A child still writing into a temporary folder would refill it. SIGTERM
  // first, to the child's whole process group (a compiler driver and the
  // compiler proper it runs): the driver then removes its own temporaries (in
  // TMPDIR); SIGKILL if it has not gone within 5 s.
  if (const pid_t child = gChild; child > 0) {
    kill(-child, SIGTERM);
    bool gone = false;
    for (int k = 0; k < 500 && !gone; ++k) {
      const pid_t r = waitpid(child, nullptr, WNOHANG);
      gone = r == child || (r < 0 && errno != EINTR);
      if (!gone) {
        const timespec pause{0, 10 * 1000 * 1000};
        nanosleep(&pause, nullptr);
      }
    }
    if (!gone) {
      kill(-child, SIGKILL);
      while (waitpid(child, nullptr, 0) < 0 && errno == EINTR) {
      }
    }
    // The driver gone, the programs it ran (the compiler proper, the linker)
    // may still be in the group for a moment, and the linker may still create
    // its output (a registered name) after the removal below: up to 1 s for
    // the group to empty (a zombie still counts, so at most that long).
    for (int k = 0; k < 100 && kill(-child, 0) == 0; ++k) {
      const timespec pause{0, 10 * 1000 * 1000};
      nanosleep(&pause, nullptr);
    }
  }
  // Files first (unlink fails on a folder), then folders, innermost first:
  // repeat rmdir until no pass removes anything more (nested folders). A file
  // that reappears (a late writer) keeps its folder: more rounds while any
  // registered path still exists (20 at most, 10 ms apart).
  for (int round = 0; round < 20; ++round) {
    for (int k = 0; k < kSlots; ++k)
      if (gUsed[k]) unlink(gPaths[k]);
    for (int pass = 0; pass < kSlots; ++pass) {
      bool removed = false;
      for (int k = 0; k < kSlots; ++k)
        if (gUsed[k] && rmdir(gPaths[k]) == 0) removed = true;
      if (!removed) break;
    }
    bool left = false;
    for (int k = 0; k < kSlots && !left; ++k) left = gUsed[k] && access(gPaths[k], F_OK) == 0;
    if (!left) break;
    const timespec pause{0, 10 * 1000 * 1000};
    nanosleep(&pause, nullptr);
  }
  for (int k = 0; k < kSlots; ++k) gUsed[k] = 0;
  errno = savedErrno;
  // Die of the signal, as without the handler (the parent sees WIFSIGNALED).
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

std::string errnoText(int e) { return std::strerror(e); }

}  // namespace

void installInterruptCleanup() {
  struct sigaction sa {};
  sa.sa_handler = removeTemporariesAndDie;
  sigemptyset(&sa.sa_mask);
  for (int s : kSignals) sigaddset(&sa.sa_mask, s);  // one cleanup at a time
  sa.sa_flags = 0;
  for (int s : kSignals) {
    struct sigaction old {};
    // A signal ignored by the parent (nohup, `&` in a non-interactive shell) stays ignored.
    if (sigaction(s, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    sigaction(s, &sa, nullptr);
  }
}

int registerTemporary(const std::string& path) {
  if (path.size() >= kPathMax) throw Error(fmt::format("{}: path too long for a temporary", quoted(path)));
  const std::lock_guard<std::mutex> lock(gRegistryMutex);
  for (int k = 0; k < kSlots; ++k) {
    if (gUsed[k]) continue;
    std::memcpy(gPaths[k], path.c_str(), path.size() + 1);
    std::atomic_signal_fence(std::memory_order_seq_cst);
    gUsed[k] = 1;
    return k;
  }
  throw Error("internal: more than 64 temporary files at once");
}

void setInterruptChild(int pid) { gChild = pid; }

void unregisterTemporary(int slot) {
  if (slot < 0 || slot >= kSlots) return;
  gUsed[slot] = 0;
  std::atomic_signal_fence(std::memory_order_seq_cst);
}

// ---------------------------------------------------------------- atomic write
namespace {

// The signals of installInterruptCleanup held back while the files are renamed
// in: an interrupt then arrives after the last rename and the removal of the
// private folder, never between two renames.
class HoldSignals {
 public:
  HoldSignals() {
    sigset_t set;
    sigemptyset(&set);
    for (int s : kSignals) sigaddset(&set, s);
    pthread_sigmask(SIG_BLOCK, &set, &old_);
  }
  ~HoldSignals() { pthread_sigmask(SIG_SETMASK, &old_, nullptr); }
  HoldSignals(const HoldSignals&) = delete;
  HoldSignals& operator=(const HoldSignals&) = delete;

 private:
  sigset_t old_;
};

void checkName(const std::string& name, const std::string& outDir) {
  const bool bad = name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos ||
                   name.find('\0') != std::string::npos || name.rfind(".proxgen-tmp-", 0) == 0;
  if (bad) throw Error(describe(quoted(outDir), quoted(name), "not a plain file name for an output"));
}

const char* kindOf(mode_t m) {
  if (S_ISDIR(m)) return "a folder";
  if (S_ISLNK(m)) return "a symbolic link";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISSOCK(m)) return "a socket";
  if (S_ISCHR(m) || S_ISBLK(m)) return "a device";
  return "not a regular file";
}

void writeAll(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::system_error(errno ? errno : EIO, std::generic_category());
    done += std::size_t(n);
  }
}

// Everything writeFiles holds, released in reverse on the way out (success or not).
struct Transaction {
  std::string outDir, tmpPath, tmpName;
  int dirFd = -1, tmpFd = -1;
  bool createdDir = false;
  int tmpSlot = -1;
  std::vector<std::string> inTmp;  // names present in the private folder
  std::vector<int> slots;

  ~Transaction() {
    if (tmpFd >= 0) {
      for (const std::string& n : inTmp) unlinkat(tmpFd, n.c_str(), 0);
      close(tmpFd);
    }
    if (!tmpName.empty() && dirFd >= 0) unlinkat(dirFd, tmpName.c_str(), AT_REMOVEDIR);
    for (int s : slots) unregisterTemporary(s);
    unregisterTemporary(tmpSlot);
    if (dirFd >= 0) close(dirFd);  // releases the lock
    if (createdDir) rmdir(outDir.c_str());  // only if it stayed empty
  }
};

}  // namespace

std::vector<std::string> writeFiles(const std::vector<OutputFile>& files, const std::string& outDir) {
  if (outDir.empty()) throw Error("--out: the output folder is empty");
  std::set<std::string> seen;
  for (const OutputFile& f : files) {
    checkName(f.name, outDir);
    if (!seen.insert(f.name).second) throw Error(describe(quoted(outDir), quoted(f.name), "written twice"));
  }
  const auto fail = [&](const std::string& path, const std::string& what) -> void {
    throw Error(fmt::format("{}: {}", quoted(path), what));
  };

  Transaction t;
  t.outDir = outDir;
  struct stat st {};
  // The folder itself may be a link to a folder (the user named it); what is
  // inside is only ever reached through its descriptor.
  if (stat(outDir.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode)) fail(outDir, "exists and is not a folder");
  } else if (errno == ENOENT) {
    std::error_code ec;
    fs::create_directories(outDir, ec);
    if (ec) fail(outDir, fmt::format("cannot create the folder ({})", ec.message()));
    t.createdDir = true;
  } else {
    fail(outDir, fmt::format("cannot use the folder ({})", errnoText(errno)));
  }
  t.dirFd = open(outDir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (t.dirFd < 0) fail(outDir, fmt::format("cannot open the folder ({})", errnoText(errno)));
  // Concurrent runs into this folder take turns here; the lock goes with the descriptor.
  while (flock(t.dirFd, LOCK_EX) != 0)
    if (errno != EINTR) fail(outDir, fmt::format("cannot lock the folder ({})", errnoText(errno)));

  // The private folder: a fresh name (mkdtemp, mode 0700) nobody else can have planted links in.
  std::string pattern = (fs::path(outDir) / ".proxgen-tmp-XXXXXX").string();
  {
    const HoldSignals hold;  // created and registered as one step
    if (!mkdtemp(pattern.data())) fail(outDir, fmt::format("cannot create a temporary folder in it ({})", errnoText(errno)));
    t.tmpPath = pattern;
    t.tmpName = fs::path(pattern).filename().string();
    t.tmpSlot = registerTemporary(t.tmpPath);
  }
  t.tmpFd = openat(t.dirFd, t.tmpName.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (t.tmpFd < 0) fail(t.tmpPath, fmt::format("cannot open the temporary folder ({})", errnoText(errno)));

  for (const OutputFile& f : files) {
    const std::string shown = (fs::path(outDir) / f.name).string();
    t.slots.push_back(registerTemporary((fs::path(t.tmpPath) / f.name).string()));
    const int fd = openat(t.tmpFd, f.name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                          f.executable ? 0777 : 0666);
    if (fd < 0) fail(shown, fmt::format("cannot be written ({})", errnoText(errno)));
    t.inTmp.push_back(f.name);
    try {
      writeAll(fd, f.content);
      if (fsync(fd) != 0 && errno != EINVAL) throw std::system_error(errno, std::generic_category());
    } catch (const std::system_error& e) {
      close(fd);
      fail(shown, fmt::format("cannot be written ({})", e.code().message()));
    }
    if (close(fd) != 0) fail(shown, fmt::format("cannot be written ({})", errnoText(errno)));
  }

  // Every destination is checked before any is replaced.
  std::vector<bool> exists(files.size(), false);
  for (std::size_t k = 0; k < files.size(); ++k) {
    const std::string shown = (fs::path(outDir) / files[k].name).string();
    if (fstatat(t.dirFd, files[k].name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0) {
      if (!S_ISREG(st.st_mode))
        fail(shown, fmt::format("exists and is {}; proxgen replaces only regular files (nothing was written)",
                                kindOf(st.st_mode)));
      exists[k] = true;
    } else if (errno != ENOENT) {
      fail(shown, fmt::format("cannot be checked ({})", errnoText(errno)));
    }
  }

  // Rename each in. An existing file is exchanged with the new one (the old
  // one lands in the private folder), so a failure midway can swap every
  // finished step back. Where the file system cannot exchange, a plain rename.
  const HoldSignals hold;
  enum Step { kNone, kExchanged, kCreated, kReplaced };
  std::vector<Step> done(files.size(), kNone);
  const auto undo = [&] {
    for (std::size_t j = files.size(); j-- > 0;) {
      const char* n = files[j].name.c_str();
      if (done[j] == kExchanged) renameat2(t.tmpFd, n, t.dirFd, n, RENAME_EXCHANGE);
      if (done[j] == kCreated) renameat(t.dirFd, n, t.tmpFd, n);
    }
  };
  for (std::size_t k = 0; k < files.size(); ++k) {
    const char* n = files[k].name.c_str();
    int rc = renameat2(t.tmpFd, n, t.dirFd, n, exists[k] ? RENAME_EXCHANGE : RENAME_NOREPLACE);
    Step step = exists[k] ? kExchanged : kCreated;
    if (rc != 0 && (errno == EINVAL || errno == ENOSYS)) {
      rc = renameat(t.tmpFd, n, t.dirFd, n);
      step = kReplaced;
    }
    if (rc != 0) {
      const int e = errno;
      undo();
      fail((fs::path(outDir) / files[k].name).string(),
           fmt::format("cannot be replaced ({}; nothing was written)", errnoText(e)));
    }
    done[k] = step;
  }

  std::vector<std::string> written;
  for (const OutputFile& f : files) written.push_back((fs::path(outDir) / f.name).string());
  t.createdDir = false;
  return written;  // ~Transaction removes the old files and the private folder, then unlocks
}

}  // namespace proxgen::emit
