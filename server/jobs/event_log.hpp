// The progress events of one job: an append-only sequence kept in memory (the recent tail) and in
// `events.ndjson` (every event, one JSON object per line), with waiting for new events.
//
// Events are numbered 1, 2, 3, ... (`seq`); the numbering continues across restarts of the server, so a client's
// Last-Event-ID stays meaningful. Each line is a complete JSON object that starts
// {"seq":N,"type":"...","time":"...", followed by the type's own fields (see docs/server.md).
//
// Bounded: once the file has `max_bytes`, further `iteration` events are dropped (counted by dropped()); the few
// state, step and end events are always written, where the disk takes them (an event a write error lost, e.g. on a
// full disk, is served to the streams from memory and counted by dropped() too). Damage is never served: a line that is
// not a whole event is not sent to any client, and the log's problem() says where it is (the job store reports it).
//
// Thread safety: every member may be called from any thread. append() (the worker) never waits for readers: it
// holds the lock only to write one line and to notify.
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace contactd {

struct Event {
  std::int64_t seq = 0;
  std::string type;  // "state", "iteration", "adaptive_step", "step" or "end"
  std::string json;  // the whole event, one line without the newline
};

class EventLog {
 public:
  // `path` is the job's events.ndjson; it is created on the first append.
  EventLog(std::string path, std::uint64_t max_bytes);
  ~EventLog();
  EventLog(const EventLog&) = delete;
  EventLog& operator=(const EventLog&) = delete;

  // Reads an existing file back (start-up), as a stream (only the index is kept: 9 bytes per event): indexes
  // every complete line and cuts off a torn last line (a crash in the middle of its one write). A damaged line
  // before the end (not the next event, or not an object), or a file that is a symbolic link, is not cut: the
  // file is renamed to events.ndjson.damaged-<time> (kept for inspection) and the events before the damage are
  // copied into a new events.ndjson; problem() says what was found. Returns the number of events kept.
  std::int64_t load();

  // What is wrong with the log ("" when nothing): found by load() or by a read (a line that is not JSON).
  std::string problem() const;
  // Called (once) when a read finds damage, with the problem; set before the log is used.
  void on_damage(std::function<void(const std::string&)> callback) { on_damage_ = std::move(callback); }
  // Events not recorded in the file: iteration events past max_bytes, and events a write error lost.
  std::int64_t dropped() const;
  // True when the event after `after` exists but cannot be read (damaged): a stream ends there.
  bool unreadable_after(std::int64_t after) const;

  // Appends one event of `type` with `fields` (a JSON object; seq, type and time are added) and wakes waiters.
  // Returns the event's seq. An I/O error is logged, not thrown: the event still reaches live subscribers.
  std::int64_t append(const std::string& type, const nlohmann::json& fields);

  // Up to `max_count` events with seq > after, in order (from memory when recent, from the file otherwise).
  std::vector<Event> read_after(std::int64_t after, std::size_t max_count) const;

  // Waits until an event with seq > after exists, the log is discarded, or `timeout` passes.
  void wait_after(std::int64_t after, std::chrono::milliseconds timeout) const;

  std::int64_t last_seq() const;
  std::string last_type() const;  // "" when empty

  // Flushes the file to disk (fsync) and closes it; the next append reopens it. Called when a job ends or stops.
  void sync_and_close();

  // The job was deleted: wakes waiters; reads return nothing from now on.
  void discard();
  bool discarded() const;

 private:
  // load() in phases (under the lock): open the file (a planted symbolic link is moved aside), index its lines
  // (a line is indexed by index_line when its prefix is this log's next event), then set a damaged file aside
  // (serving a copy of the good part) or cut a torn last line.
  struct LoadScan {
    std::uint64_t read_bytes = 0, good_bytes = 0;  // read, and up to the end of the last good line
    bool damaged = false, torn = false;
  };
  int open_for_load();
  LoadScan index_lines(int fd);
  bool index_line(const std::string& line, std::uint64_t offset);
  void set_damaged_file_aside(int fd);
  void cut_torn_line(int fd, std::uint64_t read_bytes);
  // read_after's file part (without the lock): the bytes [begin, end) of the file, then the events in them from
  // `seq` on (their offsets and types copied under the lock); false when a line is not the event it should be
  // (the log is then marked damaged and on_damage_ told).
  std::string read_range(std::uint64_t begin, std::uint64_t end) const;
  bool events_from_file(const std::string& bytes, std::uint64_t begin, std::int64_t seq,
                        const std::vector<std::uint64_t>& offsets, const std::vector<std::uint8_t>& types,
                        std::vector<Event>& events) const;

  void open_for_append_locked();
  void damaged_locked(std::int64_t seq, const std::string& problem) const;  // found by a read: mutable state

  static constexpr std::size_t kRecent = 512;  // events kept in memory per job

  const std::string path_;
  const std::uint64_t max_bytes_;
  std::function<void(const std::string&)> on_damage_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  int fd_ = -1;
  std::uint64_t file_size_ = 0;
  std::vector<std::uint64_t> offsets_;  // offsets_[seq - 1]: where event seq starts in the file
  std::vector<std::uint8_t> types_;     // types_[seq - 1]: index into kTypes
  std::deque<std::string> recent_;      // the last events; recent_.back() is seq == offsets_.size()
  bool discarded_ = false;
  bool file_ok_ = true;  // false after a write error: older events may be missing from the file
  bool frozen_ = false;  // damaged and could not be set aside: never written to (appends reach streams only)
  std::int64_t dropped_ = 0;
  mutable std::int64_t unreadable_from_ = 0;  // > 0: the first seq whose line is damaged (never served)
  mutable std::string problem_;
};

}  // namespace contactd
