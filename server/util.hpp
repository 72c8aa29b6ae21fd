// Small helpers shared by the server's parts: clocks and ISO 8601 times, job ids, base64url, constant-time
// comparison, durable file writes and the log.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace contactd {

// Wall-clock time as microseconds since the Unix epoch (UTC).
std::int64_t now_unix_us();

// ISO 8601 UTC with microseconds, e.g. "2024-05-01T12:00:00.123456Z". Event and job timestamps use it.
std::string iso8601_us(std::int64_t unix_us);
inline std::string now_iso8601() { return iso8601_us(now_unix_us()); }

// A random (version 4) UUID in lower case, from std::random_device. Thread-safe.
std::string new_job_id();

// True for the ids new_job_id() makes (lower-case UUID v4). Anything else is never looked up on disk.
bool is_job_id(std::string_view text);

// RFC 4648 base64url without padding, and its inverse (false on a character outside the alphabet).
std::string base64url_encode(std::string_view bytes);
bool base64url_decode(std::string_view text, std::string& bytes);

// Compares in time independent of where the strings differ (the token check).
bool constant_time_equal(std::string_view a, std::string_view b);

// A failed system call on a file: the message names the path and the step; `code` is the errno (ENOSPC...).
class FileError : public std::runtime_error {
 public:
  FileError(const std::string& message, int code) : std::runtime_error(message), code_(code) {}
  int code() const { return code_; }

 private:
  int code_;
};

// The file functions below never follow a symbolic link in the last component of a path (O_NOFOLLOW): the data
// directory holds only files the server wrote, and a link planted there must not make it read or overwrite
// another file. Errors are FileError.

// Writes `content` to `path` atomically: "<path>.tmp" is written and renamed over `path`, so a crash leaves
// either the old or the new file, never a partial one under `path`. With `durable` the file is fsync'ed before
// the rename and the directory after it (the new content survives a power failure too); without, the rename
// still makes the change atomic for a crash of the process. Throws FileError naming the path and the failed step.
void write_file_atomically(const std::string& path, std::string_view content, bool durable = true);

// A public version of an error message: hexadecimal addresses (HDF5 prints "buf = 0x7fb8...") are masked and
// `data_dir` is written "<data-dir>". The full text goes to the log only.
std::string public_message(const std::string& text, const std::string& data_dir);

// The whole file; throws std::runtime_error if it cannot be read.
std::string read_whole_file(const std::string& path);

// fsync a file; throws std::runtime_error if that fails.
void sync_file(const std::string& path);

// fsync a directory (after a rename or an unlink inside it); errors are ignored.
void sync_directory(const std::string& path);

// One line to stderr with a UTC time stamp: "2024-05-01T12:00:00.123456Z contactd: <text>".
void log_line(const std::string& text);

}  // namespace contactd
