#include "isolated_call.h"

#include <fmt/format.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <new>
#include <stdexcept>

namespace fignet::bullet {

namespace {

// The process's current virtual size in bytes (first field of /proc/self/statm, in pages).
std::size_t current_address_space() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  statm >> pages;
  return pages * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}

void write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    data += n, size -= static_cast<std::size_t>(n);
  }
}

// The child's side: run, then send a status byte ('+' result, '-' error message) and the payload.
[[noreturn]] void run_child(int fd, const std::function<std::string()>& work,
                            const IsolationLimits& limits) {
  const rlim_t memory = current_address_space() + limits.extra_memory_bytes;
  const rlimit limit{memory, memory};
  ::setrlimit(RLIMIT_AS, &limit);
  ::alarm(limits.seconds);
  std::string payload;
  char status = '+';
  try {
    payload = work();
  } catch (const std::bad_alloc&) {
    status = '-', payload = "out of memory";
  } catch (const std::exception& e) {
    status = '-', payload = e.what();
  } catch (...) {
    status = '-', payload = "unknown error";
  }
  write_all(fd, &status, 1);
  write_all(fd, payload.data(), payload.size());
  ::_exit(0);
}

}  // namespace

std::string run_isolated(const std::function<std::string()>& work, const IsolationLimits& limits) {
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error(fmt::format("pipe: {}", std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw std::runtime_error(fmt::format("fork: {}", std::strerror(errno)));
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], work, limits);
  }
  ::close(fds[1]);
  std::string received;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    received.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    if (signal == SIGALRM) {
      throw std::runtime_error(fmt::format("gave up after {} s", limits.seconds));
    }
    throw std::runtime_error(fmt::format("the parser crashed ({})", ::strsignal(signal)));
  }
  if (received.empty()) throw std::runtime_error("the parser exited without a result");
  if (received[0] == '-') throw std::runtime_error(received.substr(1));
  return received.substr(1);
}

}  // namespace fignet::bullet
