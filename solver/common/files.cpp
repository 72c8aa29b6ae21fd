#include "contact/files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace contact {

namespace {

[[noreturn]] void fail(const std::string& path, const char* step) {
  const int code = errno;
  throw FileError("cannot " + std::string(step) + " '" + path + "': " + std::strerror(code), code);
}

// Removes tmp, keeping errno (the reason a caller reports).
void remove_keeping_errno(const std::string& tmp) {
  const int saved = errno;
  ::unlink(tmp.c_str());
  errno = saved;
}

}  // namespace

PendingFile::PendingFile(std::string path) : path_(std::move(path)), tmp_(path_ + ".tmp") {
  ::unlink(tmp_.c_str());  // a leftover (or a planted link) is never written through
}

void PendingFile::abandon() {
  if (!open_) return;
  open_ = false;
  remove_keeping_errno(tmp_);
}

void PendingFile::commit(bool durable) {
  if (!open_) throw FileError("cannot rename '" + tmp_ + "' onto '" + path_ + "': abandoned or renamed before", 0);
  try {
    if (durable) sync_file(tmp_);
  } catch (...) {
    abandon();
    throw;
  }
  if (::rename(tmp_.c_str(), path_.c_str()) != 0) {
    abandon();
    fail(path_, "rename onto");
  }
  open_ = false;
  if (!durable) return;
  const auto slash = path_.find_last_of('/');
  sync_directory(slash == std::string::npos ? "." : path_.substr(0, slash));
}

void replace_file_atomically(const std::string& path, const std::function<void(const std::string& tmp)>& write,
                             bool durable) {
  PendingFile file(path);
  write(file.tmp());  // whatever it throws: the destructor removes tmp
  file.commit(durable);
}

void write_file_atomically(const std::string& path, std::string_view content, bool durable) {
  replace_file_atomically(
      path,
      [content](const std::string& tmp) {
        const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
        if (fd < 0) fail(tmp, "create");
        std::size_t written = 0;
        while (written < content.size()) {
          const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
          if (n < 0) {
            if (errno == EINTR) continue;
            const int saved = errno;
            ::close(fd);
            errno = saved;
            fail(tmp, "write");
          }
          written += static_cast<std::size_t>(n);
        }
        ::close(fd);
      },
      durable);
}

std::string read_whole_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) fail(path, "open");
  std::string content;
  char buffer[65536];
  while (true) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int saved = errno;
      ::close(fd);
      errno = saved;
      fail(path, "read");
    }
    if (n == 0) break;
    content.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return content;
}

void sync_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) fail(path, "open");
  if (::fsync(fd) != 0) {
    const int saved = errno;
    ::close(fd);
    errno = saved;
    fail(path, "fsync");
  }
  ::close(fd);
}

void sync_directory(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace contact
