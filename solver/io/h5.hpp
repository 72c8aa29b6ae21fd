// Internal to solver/io: small RAII wrappers over the HDF5 C API and typed read/write helpers.
//
// Every handle is owned by an h5::Handle that closes it with the matching H5*close, so nothing leaks when an
// exception unwinds. Every failing HDF5 call throws h5::Error whose message names the step ("create dataset
// '/steps/0/bodies/upper/points'") followed by the innermost messages of HDF5's error stack. Callers add the
// file path. Not part of the public API: include contact/result_file.hpp instead.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace contact::io::h5 {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws Error("<step>: <HDF5 error stack>"). Call right after the failing HDF5 call, before any other HDF5
// call clears the stack.
[[noreturn]] void fail(const std::string& step);

// Owns one HDF5 identifier; move-only.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      closer_ = o.closer_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  ~Handle() { reset(); }

  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }  // NOLINT: the wrappers are passed straight to the C API
  void reset() {
    if (id_ >= 0 && closer_ != nullptr) closer_(id_);
    id_ = H5I_INVALID_HID;
  }
  // Closes now and reports a failure (a file close flushes, so its failure matters).
  void close(const std::string& step) {
    const hid_t id = id_;
    id_ = H5I_INVALID_HID;
    if (id >= 0 && closer_ != nullptr && closer_(id) < 0) fail(step);
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

// Turns off HDF5's automatic printing of error stacks to stderr for this scope (per thread in the thread-safe
// library Debian ships); errors become exceptions instead. Restores the previous handler.
class QuietErrors {
 public:
  QuietErrors();
  ~QuietErrors();
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// ---- types --------------------------------------------------------------------------------------------
// Memory type and little-endian file type of the element types stored in result files.
template <class T>
struct Type;
template <>
struct Type<double> {
  static hid_t mem() { return H5T_NATIVE_DOUBLE; }
  static hid_t file() { return H5T_IEEE_F64LE; }
};
template <>
struct Type<std::int64_t> {
  static hid_t mem() { return H5T_NATIVE_INT64; }
  static hid_t file() { return H5T_STD_I64LE; }
};
template <>
struct Type<std::int32_t> {
  static hid_t mem() { return H5T_NATIVE_INT32; }
  static hid_t file() { return H5T_STD_I32LE; }
};
template <>
struct Type<std::int8_t> {
  static hid_t mem() { return H5T_NATIVE_INT8; }
  static hid_t file() { return H5T_STD_I8LE; }
};
template <>
struct Type<std::uint8_t> {
  static hid_t mem() { return H5T_NATIVE_UINT8; }
  static hid_t file() { return H5T_STD_U8LE; }
};

// ---- objects --------------------------------------------------------------------------------------------
Handle create_file(const std::string& path);  // truncates; strong close degree
Handle open_file(const std::string& path);    // read-only
Handle create_group(hid_t loc, const std::string& name);
Handle open_group(hid_t loc, const std::string& name);
bool has_link(hid_t loc, const std::string& name);  // one path component
// A second name for an existing object in the same group (an HDF5 hard link: one object, two names).
void hard_link(hid_t loc, const std::string& existing, const std::string& name);
bool has_attribute(hid_t obj, const std::string& name);
std::string object_name(hid_t obj);                // full path inside the file, for messages
std::vector<std::string> link_names(hid_t group);  // members of a group, in name order
std::vector<hsize_t> dataset_shape(hid_t loc, const std::string& name);

// ---- writing --------------------------------------------------------------------------------------------
// A dataset of `dims` (row-major, as HDF5 and numpy store it) from `data`, which holds the product of dims
// elements (may be null when that product is 0).
void write_raw(hid_t loc, const std::string& name, hid_t mem_type, hid_t file_type, const void* data,
               const std::vector<hsize_t>& dims);
template <class T>
void write_dataset(hid_t loc, const std::string& name, const std::vector<T>& data, const std::vector<hsize_t>& dims) {
  write_raw(loc, name, Type<T>::mem(), Type<T>::file(), data.data(), dims);
}
template <class T>
void write_vector(hid_t loc, const std::string& name, const std::vector<T>& data) {
  write_dataset(loc, name, data, {static_cast<hsize_t>(data.size())});
}
void write_string_dataset(hid_t loc, const std::string& name, const std::string& value);  // scalar, UTF-8
void write_strings_dataset(hid_t loc, const std::string& name, const std::vector<std::string>& values);

void write_attribute_raw(hid_t obj, const std::string& name, hid_t mem_type, hid_t file_type, const void* data,
                         const std::vector<hsize_t>& dims);  // dims empty = scalar
template <class T>
void write_attribute(hid_t obj, const std::string& name, T value) {
  write_attribute_raw(obj, name, Type<T>::mem(), Type<T>::file(), &value, {});
}
template <class T>
void write_attribute_array(hid_t obj, const std::string& name, const std::vector<T>& values) {
  write_attribute_raw(obj, name, Type<T>::mem(), Type<T>::file(), values.data(), {static_cast<hsize_t>(values.size())});
}
void write_attribute(hid_t obj, const std::string& name, const std::string& value);  // variable-length UTF-8
void write_attribute(hid_t obj, const std::string& name, const char* value);
void write_attribute(hid_t obj, const std::string& name, const std::vector<std::string>& values);
// A fixed-length ASCII string attribute of exactly value.size() bytes, NUL-padded (no terminator stored).
void write_fixed_string_attribute(hid_t obj, const std::string& name, const std::string& value);

// ---- reading --------------------------------------------------------------------------------------------
// Reads a whole dataset converted to T; `dims` receives its shape. Throws if its rank is not `rank`.
void read_raw(hid_t loc, const std::string& name, hid_t mem_type, size_t elem_size, int rank,
              std::vector<hsize_t>& dims, std::vector<unsigned char>& bytes);
template <class T>
std::vector<T> read_dataset(hid_t loc, const std::string& name, int rank, std::vector<hsize_t>& dims) {
  std::vector<unsigned char> bytes;
  read_raw(loc, name, Type<T>::mem(), sizeof(T), rank, dims, bytes);
  std::vector<T> out(bytes.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());
  return out;
}
template <class T>
std::vector<T> read_vector(hid_t loc, const std::string& name) {
  std::vector<hsize_t> dims;
  return read_dataset<T>(loc, name, 1, dims);
}
std::string read_string_dataset(hid_t loc, const std::string& name);
std::vector<std::string> read_strings_dataset(hid_t loc, const std::string& name);

void read_attribute_raw(hid_t obj, const std::string& name, hid_t mem_type, size_t elem_size,
                        std::vector<unsigned char>& bytes);
template <class T>
T read_attribute(hid_t obj, const std::string& name) {
  std::vector<unsigned char> bytes;
  read_attribute_raw(obj, name, Type<T>::mem(), sizeof(T), bytes);
  if (bytes.size() != sizeof(T)) throw Error("attribute '" + name + "' of " + object_name(obj) + " is not a scalar");
  T value;
  std::memcpy(&value, bytes.data(), sizeof(T));
  return value;
}
template <class T>
std::vector<T> read_attribute_array(hid_t obj, const std::string& name) {
  std::vector<unsigned char> bytes;
  read_attribute_raw(obj, name, Type<T>::mem(), sizeof(T), bytes);
  std::vector<T> out(bytes.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());
  return out;
}
// Fixed- or variable-length string attribute; a scalar.
std::string read_string_attribute(hid_t obj, const std::string& name);
std::vector<std::string> read_strings_attribute(hid_t obj, const std::string& name);

// How a string attribute is stored: its size in bytes if fixed-length (0 if variable-length) and its padding.
struct StringTypeInfo {
  bool is_string = false;
  bool variable_length = false;
  size_t size = 0;
  H5T_str_t padding = H5T_STR_ERROR;
  H5T_cset_t charset = H5T_CSET_ERROR;
};
StringTypeInfo string_attribute_type(hid_t obj, const std::string& name);

}  // namespace contact::io::h5
