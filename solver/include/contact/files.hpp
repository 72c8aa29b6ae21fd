// Files replaced so that a crash never leaves half of one: the one atomic write that the result file writer
// (result.hdf, result.xmf) and contactd's job store (state.json, job.json) both use, and reading a file back.
//
// A file is written as "<path>.tmp" and renamed over `path`: a crash of the process leaves either the old or
// the new file under `path`, never a partial one. With `durable` the temporary file is fsync'ed before the rename
// and its directory after it, so the new content also survives a power failure.
//
// No function here follows a symbolic link in the last component of a path it opens (O_NOFOLLOW): a link planted
// in a data directory must not make a writer overwrite another file. Errors are FileError, naming the path and
// the failed step ("cannot fsync '<path>': No space left on device").
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace contact {

// A failed system call on a file: the message names the path and the step; `code` is the errno (ENOSPC...).
class FileError : public std::runtime_error {
 public:
  FileError(const std::string& message, int code) : std::runtime_error(message), code_(code) {}
  int code() const { return code_; }

 private:
  int code_;
};

// The replacement of `path` spread over time, for a file written piece by piece (the result file streamed as the
// steps are solved): the pieces go to tmp() = "<path>.tmp" (a leftover is removed at construction), commit()
// syncs it (with `durable`) and renames it over `path`; abandon(), or destruction before a commit, removes it.
class PendingFile {
 public:
  explicit PendingFile(std::string path);
  ~PendingFile() { abandon(); }
  PendingFile(const PendingFile&) = delete;
  PendingFile& operator=(const PendingFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& tmp() const { return tmp_; }
  void commit(bool durable = true);  // throws FileError (the tmp file is removed then)
  void abandon();                    // idempotent; nothing after a commit

 private:
  std::string path_, tmp_;
  bool open_ = true;
};

// Replaces `path` atomically with what write(tmp) creates at tmp = "<path>.tmp" (a leftover tmp is removed
// first). Whatever write() throws is rethrown after tmp is removed; the fsync and rename steps throw FileError.
void replace_file_atomically(const std::string& path, const std::function<void(const std::string& tmp)>& write,
                             bool durable = true);

// replace_file_atomically() with `content` as the new file (tmp created with O_EXCL | O_NOFOLLOW).
void write_file_atomically(const std::string& path, std::string_view content, bool durable = true);

// The whole file; throws FileError if it cannot be read.
std::string read_whole_file(const std::string& path);

// fsync a file; throws FileError if that fails.
void sync_file(const std::string& path);

// fsync a directory (after a rename or an unlink inside it); errors are ignored.
void sync_directory(const std::string& path);

}  // namespace contact
