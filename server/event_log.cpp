#include "event_log.hpp"

#include "util.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string_view>

namespace contactd {

namespace {

const char* const kTypes[] = {"state", "iteration", "step", "end"};
constexpr std::uint64_t kUnwritten = ~std::uint64_t{0};

std::uint8_t type_index(const std::string& type) {
  for (std::uint8_t i = 0; i < 4; ++i)
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

EventLog::EventLog(std::string path) : path_(std::move(path)) {}

EventLog::~EventLog() {
  if (fd_ >= 0) ::close(fd_);
}

std::int64_t EventLog::load() {
  std::lock_guard<std::mutex> lock(mutex_);
  offsets_.clear();
  types_.clear();
  recent_.clear();
  file_size_ = 0;
  std::string content;
  try {
    content = read_whole_file(path_);
  } catch (const std::exception&) {
    return 0;  // no events yet
  }
  std::uint64_t position = 0;
  const std::string_view view(content);
  while (position < content.size()) {
    const std::size_t newline = content.find('\n', position);
    if (newline == std::string::npos) break;  // torn last line: the crash hit the one write() of a line
    const std::string_view line = view.substr(position, newline - position);
    std::int64_t seq = 0;
    std::string type;
    if (!parse_prefix(line, seq, type) || seq != static_cast<std::int64_t>(offsets_.size()) + 1) break;
    // Every line is written whole by one write(), so only the last one can be damaged: check it fully.
    if (newline + 1 >= content.size() && !nlohmann::json::accept(line)) break;
    offsets_.push_back(position);
    types_.push_back(type_index(type));
    position = newline + 1;  // events read back stay on disk only: a finished job costs no memory
  }
  file_size_ = position;
  if (position < content.size()) {
    log_line("events: cut " + std::to_string(content.size() - position) + " bytes of a torn or foreign tail from " +
             path_);
    if (::truncate(path_.c_str(), static_cast<off_t>(position)) != 0)
      log_line("events: cannot truncate " + path_ + ": " + std::strerror(errno));
  }
  return static_cast<std::int64_t>(offsets_.size());
}

void EventLog::open_for_append_locked() {
  if (fd_ >= 0 || discarded_) return;
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
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

std::vector<Event> EventLog::read_after(std::int64_t after, std::size_t max_count) const {
  std::vector<Event> events;
  if (after < 0) after = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  const std::int64_t last = static_cast<std::int64_t>(offsets_.size());
  if (discarded_ || after >= last || max_count == 0) return events;
  const std::int64_t until = std::min<std::int64_t>(last, after + static_cast<std::int64_t>(max_count));
  const std::int64_t first_recent = last - static_cast<std::int64_t>(recent_.size()) + 1;
  std::int64_t seq = after + 1;

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
    if (begin != kUnwritten && end > begin) {
      std::string bytes(end - begin, '\0');
      const int fd = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
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
      for (std::size_t k = 0; k < offsets.size(); ++k) {
        if (offsets[k] == kUnwritten) continue;  // lost to a write error: skipped
        const std::size_t from = offsets[k] - begin;
        if (from >= bytes.size()) break;
        const std::size_t newline = bytes.find('\n', from);
        if (newline == std::string::npos) break;
        events.push_back({seq + static_cast<std::int64_t>(k), kTypes[types[k]], bytes.substr(from, newline - from)});
      }
    }
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
