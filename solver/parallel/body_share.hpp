// What a body's task leaves for the other processes. Per-body work runs on the process that owns the body (one
// process for threads; one MPI rank among several, solver/mpi/); afterwards every process needs the task's
// outputs (a displacement, a Schur complement, an error message). BodyShare says how those outputs become bytes
// on the owner and objects again on every other process. Threads of one process share memory and never call it.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace contact::parallel {

class Packer {
 public:
  explicit Packer(std::vector<char>& out) : out_(out) {}
  void put(double v) { raw(&v, sizeof v); }
  void put(std::int64_t v) { raw(&v, sizeof v); }
  void put(const std::string& s) {
    put(static_cast<std::int64_t>(s.size()));
    raw(s.data(), s.size());
  }
  void put(const Eigen::VectorXd& v) {
    put(static_cast<std::int64_t>(v.size()));
    raw(v.data(), sizeof(double) * static_cast<size_t>(v.size()));
  }
  void put(const Eigen::MatrixXd& m) {  // column-major, rows and columns first
    put(static_cast<std::int64_t>(m.rows()));
    put(static_cast<std::int64_t>(m.cols()));
    raw(m.data(), sizeof(double) * static_cast<size_t>(m.size()));
  }
  template <int C, int O>
  void put(const Eigen::Matrix<double, Eigen::Dynamic, C, O>& m) {
    put(Eigen::MatrixXd(m));
  }

 private:
  void raw(const void* p, size_t n) {
    const char* c = static_cast<const char*>(p);
    out_.insert(out_.end(), c, c + n);
  }
  std::vector<char>& out_;
};

class Unpacker {
 public:
  Unpacker(const char* data, size_t size) : at_(data), end_(data + size) {}
  double get_double() { return get<double>(); }
  std::int64_t get_int() { return get<std::int64_t>(); }
  std::string get_string() {
    const size_t n = count();
    std::string s(at_, n);
    at_ += n;
    return s;
  }
  Eigen::VectorXd get_vector() {
    const size_t n = count(sizeof(double));
    Eigen::VectorXd v(static_cast<Eigen::Index>(n));
    copy(v.data(), n * sizeof(double));
    return v;
  }
  Eigen::MatrixXd get_matrix() {
    const std::int64_t r = get_int(), c = get_int();
    if (r < 0 || c < 0 || (c > 0 && static_cast<size_t>(r) > remaining() / sizeof(double) / static_cast<size_t>(c)))
      throw std::runtime_error("body data from another process is truncated (matrix)");
    Eigen::MatrixXd m(r, c);
    copy(m.data(), static_cast<size_t>(r * c) * sizeof(double));
    return m;
  }
  // The next n bytes as their own reader (one body's outputs inside a larger message).
  Unpacker take(size_t n) {
    if (n > remaining()) throw std::runtime_error("body data from another process is truncated");
    Unpacker sub(at_, n);
    at_ += n;
    return sub;
  }
  bool done() const { return at_ == end_; }

 private:
  size_t remaining() const { return static_cast<size_t>(end_ - at_); }
  size_t count(size_t item = 1) {
    const std::int64_t n = get_int();
    if (n < 0 || static_cast<size_t>(n) > remaining() / item)
      throw std::runtime_error("body data from another process is truncated");
    return static_cast<size_t>(n);
  }
  template <class T>
  T get() {
    T v;
    copy(&v, sizeof v);
    return v;
  }
  void copy(void* p, size_t n) {
    if (n > remaining()) throw std::runtime_error("body data from another process is truncated");
    if (n) std::memcpy(p, at_, n);
    at_ += n;
  }
  const char* at_;
  const char* end_;
};

struct BodyShare {
  std::function<void(size_t body, Packer&)> pack;      // on the owner, after the body's task
  std::function<void(size_t body, Unpacker&)> unpack;  // on every other process, in the same order
};

}  // namespace contact::parallel
