// The few OS hooks newlib and libstdc++ may reference, for firmware without an OS or a heap.
//
// Deliberately missing: _sbrk. Anything that reaches for the heap (malloc, new, printf's
// buffers, assert's fiprintf) therefore fails to link, and sections.ld adds a readable message.
// The stubs here are dropped by --gc-sections unless something references them.
#include <cerrno>
#include <cstdint>

#include "fw/io.hpp"

extern "C" {

// newlib's reentrant syscall layer (libc/reent/*) calls these. Output to fd 1/2 goes to the
// semihosting console, everything else fails with an errno.
int _write(int fd, const char* buf, int len) {
  if (fd != 1 && fd != 2) {
    errno = EBADF;
    return -1;
  }
  char chunk[65];
  int done = 0;
  while (done < len) {
    int n = 0;
    while (n < 64 && done + n < len) {
      chunk[n] = buf[done + n];
      ++n;
    }
    chunk[n] = '\0';
    fw::write0(chunk);  // note: SYS_WRITE0 stops at an embedded NUL
    done += n;
  }
  return len;
}
int _read(int, char*, int) {
  errno = EBADF;
  return -1;
}
int _close(int) {
  errno = EBADF;
  return -1;
}
int _lseek(int, int, int) {
  errno = ESPIPE;
  return -1;
}
struct stat;
int _fstat(int, struct stat*) {
  errno = EBADF;
  return -1;
}
int _isatty(int fd) { return fd <= 2 ? 1 : 0; }
int _getpid() { return 1; }
int _kill(int, int) {
  errno = EINVAL;
  return -1;
}
[[noreturn]] void _exit(int code) { fw::exit(code); }

// Replace newlib's abort() (raise -> _kill) and assert's handler (fiprintf -> heap).
[[noreturn]] void abort() {
  fw::print("\n*** abort()\n");
  fw::exit(fw::exit_abort);
}

[[noreturn]] void __assert_func(const char* file, int line, const char* func, const char* expr) {
  fw::print("\n*** assertion failed: ");
  fw::print(expr != nullptr ? expr : "?");
  fw::print(" at ");
  fw::print(file != nullptr ? file : "?");
  fw::print(":");
  fw::print_int(line);
  if (func != nullptr) {
    fw::print(" in ");
    fw::print(func);
  }
  fw::print("\n");
  fw::exit(fw::exit_assert);
}

// C++ runtime support without crtbegin.o (-nostartfiles) and without exceptions.
void* __dso_handle = nullptr;
// Static destructors are never run on this target: registering them is a no-op (and avoids
// newlib's atexit machinery).
int __cxa_atexit(void (*)(void*), void*, void*) { return 0; }
[[noreturn]] void __cxa_pure_virtual() {
  fw::print("\n*** pure virtual call\n");
  fw::exit(fw::exit_abort);
}

}  // extern "C"
