#include "jobs/event_log.hpp"

#include "common/log.hpp"
#include "common/time.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <cstring>
#include <string_view>

namespace contactd {

namespace {

const char* const kTypes[] = {"state", "iteration", "step", "end", "adaptive_step", "load_step"};
constexpr std::uint64_t kUnwritten = ~std::uint64_t{0};

std::uint8_t type_index(const std::string& type) {
  for (std::uint8_t i = 0; i < sizeof kTypes / sizeof *kTypes; ++i)
    if (type == kTypes[i]) return i;
  return 0;
}

// The seq and type at the start of a line this class wrote ({"seq":N,"type":"T",...}); false otherwise.
bool parse_prefix(std::string_view line, std::int64_t& seq, std::string& type) {
  static const std::string_view seq_key = "{\"seq\":";
  if (line.substr(0, seq_key.size()) != seq_key) return false;
  std::size_t i = seq_key.size();
  std::int64_t value = 0;
  const std::size_t digits_begin = i;
  while (i < line.size() && line[i] >= '0' && line[i] <= '9' && i - digits_begin < 18)
    value = value * 10 + (line[i++] - '0');
  if (i == digits_begin) return false;
  static const std::string_view type_key = ",\"type\":\"";
  if (line.substr(i, type_key.size()) != type_key) return false;
  i += type_key.size();
  const std::size_t end = line.find('"', i);
  if (end == std::string_view::npos) return false;
  seq = value;
  type = std::string(line.substr(i, end - i));
  return true;
}

}  // namespace

EventLog::EventLog(std::string path, std::uint64_t max_bytes) : path_(std::move(path)), max_bytes_(max_bytes) {}

EventLog::~EventLog() {
  if (fd_ >= 0) ::close(fd_);
}

namespace {

// Copies the first `bytes` of `from` into a new file `to` (never through a link), fsync'ed.
bool copy_prefix(int from, const std::string& to, std::uint64_t bytes) {
  const int out = ::open(to.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (out < 0) return false;
  std::vector<char> buffer(1 << 20);
  std::uint64_t done = 0;
  bool ok = true;
  while (ok && done < bytes) {
    const ssize_t n =
        ::pread(from, buffer.data(), std::min<std::uint64_t>(buffer.size(), bytes - done), static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    for (ssize_t w = 0; ok && w < n;) {
      const ssize_t m = ::write(out, buffer.data() + w, static_cast<std::size_t>(n - w));
      if (m < 0 && errno == EINTR) continue;
      ok = m > 0;
      w += m > 0 ? m : 0;
    }
    done += static_cast<std::uint64_t>(n);
  }
  ok = ok && done == bytes && ::fsync(out) == 0;
  ::close(out);
  return ok;
}

}  // namespace

std::int64_t EventLog::load() {
  std::lock_guard<std::mutex> lock(mutex_);
  offsets_.clear();
  types_.clear();
  recent_.clear();
  file_size_ = 0;
  const int fd = open_for_load();
  if (fd < 0) return 0;  // no events yet
  const LoadScan scan = index_lines(fd);
  file_size_ = scan.good_bytes;
  if (scan.damaged)
    set_damaged_file_aside(fd);
  else if (scan.torn)
    cut_torn_line(fd, scan.read_bytes);
  ::close(fd);
  return static_cast<std::int64_t>(offsets_.size());
}

int EventLog::open_for_load() {
  const int fd = ::open(path_.c_str(), O_RDWR | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0 && errno == ELOOP) {  // a symbolic link planted in the store: moved aside (the link, not its target)
    const std::string aside = path_ + ".damaged-" + std::to_string(now_unix_us() / 1000000);
    problem_ = "events.ndjson was a symbolic link (moved to " + aside.substr(aside.rfind('/') + 1) + ")";
    if (::rename(path_.c_str(), aside.c_str()) != 0)
      problem_ += "; cannot move it: " + std::string(std::strerror(errno));
    log_line("events: " + path_ + ": " + problem_);
  }
  return fd;
}

EventLog::LoadScan EventLog::index_lines(int fd) {
  // One pass in chunks of 1 MiB: each complete line is indexed by its prefix; the lines are never all in memory.
  constexpr std::size_t kChunk = 1 << 20;
  constexpr std::size_t kLongestLine = 64u << 20;  // no event is this long: a file without newlines is damage
  std::vector<char> chunk(kChunk);
  std::string line;  // the current line, possibly spanning chunks
  LoadScan scan;
  while (!scan.damaged) {
    const ssize_t n = ::pread(fd, chunk.data(), chunk.size(), static_cast<off_t>(scan.read_bytes));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      scan.torn = !line.empty();  // the crash hit the one write() of the last line
      break;
    }
    scan.read_bytes += static_cast<std::uint64_t>(n);
    std::size_t from = 0;
    while (from < static_cast<std::size_t>(n)) {
      const char* begin = chunk.data() + from;
      const void* nl = std::memchr(begin, '\n', static_cast<std::size_t>(n) - from);
      const std::size_t take =
          nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - begin) : static_cast<std::size_t>(n) - from;
      line.append(begin, take);
      from += take;
      if (!nl) break;
      ++from;  // the newline
      if (!index_line(line, scan.good_bytes)) {
        scan.damaged = true;
        break;
      }
      scan.good_bytes += line.size() + 1;  // events read back stay on disk only: a finished job costs no memory
      line.clear();
    }
    if (line.size() > kLongestLine) scan.damaged = true;
  }
  return scan;
}

bool EventLog::index_line(const std::string& line, std::uint64_t offset) {
  constexpr std::int64_t kMaxGap = 1'000'000;
  std::int64_t seq = 0;
  std::string type;
  const auto next = static_cast<std::int64_t>(offsets_.size()) + 1;
  // A gap is events lost to write errors (a full disk): they stay missing. A seq that goes back, or a jump no
  // write error explains, is not this log's.
  if (!parse_prefix(line, seq, type) || seq < next || seq > next + kMaxGap || line.back() != '}') return false;
  while (static_cast<std::int64_t>(offsets_.size()) + 1 < seq) {
    offsets_.push_back(kUnwritten);
    types_.push_back(0);
  }
  offsets_.push_back(offset);
  types_.push_back(type_index(type));
  return true;
}

void EventLog::set_damaged_file_aside(int fd) {
  // Not a crash artefact (every line is written whole by one write()): keep the file as it is, continue on a
  // copy of the good part.
  const std::string aside = path_ + ".damaged-" + std::to_string(now_unix_us() / 1000000);
  problem_ = "events.ndjson is damaged after event " + std::to_string(offsets_.size()) + " (byte " +
             std::to_string(file_size_) + "); the file is kept as " + aside.substr(aside.rfind('/') + 1) +
             " and the events before the damage are served";
  log_line("events: " + path_ + ": " + problem_);
  const std::string copy = path_ + ".tmp";
  ::unlink(copy.c_str());
  if (!copy_prefix(fd, copy, file_size_) || ::rename(path_.c_str(), aside.c_str()) != 0 ||
      ::rename(copy.c_str(), path_.c_str()) != 0) {
    log_line("events: cannot set " + path_ + " aside (" + std::strerror(errno) +
             "); it is served up to the damage and never written to");
    ::unlink(copy.c_str());
    if (::access(path_.c_str(), F_OK) != 0) ::rename(aside.c_str(), path_.c_str());
    frozen_ = true;
  }
}

void EventLog::cut_torn_line(int fd, std::uint64_t read_bytes) {
  log_line("events: cut " + std::to_string(read_bytes - file_size_) + " bytes of a torn last line from " + path_);
  if (::ftruncate(fd, static_cast<off_t>(file_size_)) != 0)
    log_line("events: cannot truncate " + path_ + ": " + std::strerror(errno));
}

std::string EventLog::problem() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return problem_;
}

std::int64_t EventLog::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

bool EventLog::unreadable_after(std::int64_t after) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return unreadable_from_ > 0 && after + 1 >= unreadable_from_;
}

void EventLog::damaged_locked(std::int64_t seq, const std::string& problem) const {
  if (unreadable_from_ > 0 && unreadable_from_ <= seq) return;
  unreadable_from_ = seq;
  problem_ = problem;
  log_line("events: " + path_ + ": " + problem);
}

void EventLog::open_for_append_locked() {
  if (fd_ >= 0 || discarded_ || frozen_) return;
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    if (file_ok_) log_line("events: cannot open " + path_ + ": " + std::strerror(errno));
    file_ok_ = false;
    return;
  }
  struct stat st {};
  if (::fstat(fd_, &st) == 0) file_size_ = static_cast<std::uint64_t>(st.st_size);
}

std::int64_t EventLog::append(const std::string& type, const nlohmann::json& fields) {
  std::int64_t seq = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (discarded_) return 0;
    seq = static_cast<std::int64_t>(offsets_.size()) + 1;
    // The fixed prefix first (so the file can be indexed without parsing every line), then the fields.
    std::string line =
        "{\"seq\":" + std::to_string(seq) + ",\"type\":\"" + type + "\",\"time\":\"" + now_iso8601() + "\"";
    const std::string rest =
        fields.is_object() ? fields.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) : std::string("{}");
    line += rest.size() > 2 ? "," + rest.substr(1) : std::string("}");
    if (type == "iteration" && file_size_ + line.size() + 1 > max_bytes_) {
      if (dropped_++ == 0)
        log_line("events: " + path_ + " has reached its cap of " + std::to_string(max_bytes_) +
                 " bytes; further iteration events are not recorded");
      return 0;
    }
    open_for_append_locked();
    std::uint64_t offset = kUnwritten;
    if (fd_ >= 0) {
      const std::string with_newline = line + "\n";
      std::size_t written = 0;
      while (written < with_newline.size()) {
        const ssize_t n = ::write(fd_, with_newline.data() + written, with_newline.size() - written);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        written += static_cast<std::size_t>(n);
      }
      if (written == with_newline.size()) {
        offset = file_size_;
        file_size_ += written;
      } else {
        if (file_ok_) log_line("events: cannot write " + path_ + ": " + std::strerror(errno));
        file_ok_ = false;
        ++dropped_;  // not recorded (a full disk): served from memory while the job lives, counted as dropped
        // Cut the partial line so that the file stays a sequence of complete events.
        if (::ftruncate(fd_, static_cast<off_t>(file_size_)) != 0) {
          ::close(fd_);
          fd_ = -1;
        }
      }
    }
    offsets_.push_back(offset);
    types_.push_back(type_index(type));
    recent_.push_back(std::move(line));
    if (recent_.size() > kRecent) recent_.pop_front();
  }
  changed_.notify_all();
  return seq;
}

std::string EventLog::read_range(std::uint64_t begin, std::uint64_t end) const {
  std::string bytes(end - begin, '\0');
  const int fd = ::open(path_.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  std::size_t got = 0;
  if (fd >= 0) {
    while (got < bytes.size()) {
      const ssize_t n = ::pread(fd, bytes.data() + got, bytes.size() - got, static_cast<off_t>(begin + got));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += static_cast<std::size_t>(n);
    }
    ::close(fd);
  }
  bytes.resize(got);
  return bytes;
}

bool EventLog::events_from_file(const std::string& bytes, std::uint64_t begin, std::int64_t seq,
                                const std::vector<std::uint64_t>& offsets, const std::vector<std::uint8_t>& types,
                                std::vector<Event>& events) const {
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    if (offsets[k] == kUnwritten) continue;  // lost to a write error: skipped
    const std::size_t from = offsets[k] - begin;
    if (from >= bytes.size()) break;
    const std::size_t newline = bytes.find('\n', from);
    if (newline == std::string::npos) break;
    const std::int64_t event_seq = seq + static_cast<std::int64_t>(k);
    std::string line = bytes.substr(from, newline - from);
    // Only whole events are served: a line changed on disk since it was written is reported, not sent.
    std::int64_t line_seq = 0;
    std::string line_type;
    if (!parse_prefix(line, line_seq, line_type) || line_seq != event_seq || !nlohmann::json::accept(line)) {
      std::function<void(const std::string&)> report;
      {
        std::lock_guard<std::mutex> relock(mutex_);
        damaged_locked(event_seq, "events.ndjson: the line of event " + std::to_string(event_seq) +
                                      " is not a valid event; the stream stops before it");
        report = on_damage_;
      }
      if (report) report(problem());
      return false;
    }
    events.push_back({event_seq, kTypes[types[k]], std::move(line)});
  }
  return true;
}

std::vector<Event> EventLog::read_after(std::int64_t after, std::size_t max_count) const {
  std::vector<Event> events;
  if (after < 0) after = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  std::int64_t last = static_cast<std::int64_t>(offsets_.size());
  if (unreadable_from_ > 0) last = std::min(last, unreadable_from_ - 1);
  if (discarded_ || after >= last || max_count == 0) return events;
  const std::int64_t first_recent = last - static_cast<std::int64_t>(recent_.size()) + 1;
  // Events a write error lost (a full disk) and memory no longer holds are stepped over: counted from the first
  // event that can be served, so that a run of more than max_count of them does not answer "nothing new" for ever
  // (a stream would wait there, heartbeats and all, also after its job ended).
  std::int64_t seq = after + 1;
  while (seq < first_recent && offsets_[static_cast<std::size_t>(seq - 1)] == kUnwritten) ++seq;
  const std::int64_t until = std::min<std::int64_t>(last, seq - 1 + static_cast<std::int64_t>(max_count));

  // Older events come from the file: one read of the byte range [offsets_[seq-1], end of the last wanted one).
  if (seq < first_recent) {
    const std::int64_t file_until = std::min(until, first_recent - 1);
    std::uint64_t begin = kUnwritten, end = 0;
    for (std::int64_t s = seq; s <= file_until; ++s) {
      if (offsets_[static_cast<std::size_t>(s - 1)] == kUnwritten) continue;
      if (begin == kUnwritten) begin = offsets_[static_cast<std::size_t>(s - 1)];
    }
    // The end of the range is the start of the next event written to the file (or the file's size).
    end = file_size_;
    for (std::int64_t s = file_until + 1; s <= last; ++s)
      if (offsets_[static_cast<std::size_t>(s - 1)] != kUnwritten) {
        end = offsets_[static_cast<std::size_t>(s - 1)];
        break;
      }
    std::vector<std::uint8_t> types(types_.begin() + (seq - 1), types_.begin() + file_until);
    std::vector<std::uint64_t> offsets(offsets_.begin() + (seq - 1), offsets_.begin() + file_until);
    lock.unlock();  // the file part is read without the lock: the worker keeps appending meanwhile
    if (begin != kUnwritten && end > begin &&
        !events_from_file(read_range(begin, end), begin, seq, offsets, types, events))
      return events;
    seq = file_until + 1;
    if (seq > until) return events;
    lock.lock();
  }
  const std::int64_t first_now =
      static_cast<std::int64_t>(offsets_.size()) - static_cast<std::int64_t>(recent_.size()) + 1;
  for (; seq <= until; ++seq) {
    if (seq < first_now) break;  // fell out of memory while unlocked (very fast writer): the caller asks again
    events.push_back(
        {seq, kTypes[types_[static_cast<std::size_t>(seq - 1)]], recent_[static_cast<std::size_t>(seq - first_now)]});
  }
  return events;
}

void EventLog::wait_after(std::int64_t after, std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return discarded_ || static_cast<std::int64_t>(offsets_.size()) > after; });
}

std::int64_t EventLog::last_seq() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<std::int64_t>(offsets_.size());
}

std::string EventLog::last_type() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return types_.empty() ? std::string() : std::string(kTypes[types_.back()]);
}

void EventLog::sync_and_close() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (file_ok_) recent_.clear();  // from now on replays read the file: a finished job costs no memory
  if (fd_ < 0) return;
  ::fsync(fd_);
  ::close(fd_);
  fd_ = -1;
}

void EventLog::discard() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    discarded_ = true;
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    recent_.clear();
  }
  changed_.notify_all();
}

bool EventLog::discarded() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return discarded_;
}

}  // namespace contactd
