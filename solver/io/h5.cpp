#include "h5.hpp"

#include <algorithm>

namespace contact::io::h5 {

namespace {

herr_t collect_error(unsigned /*n*/, const H5E_error2_t* err, void* client) {
  auto* messages = static_cast<std::vector<std::string>*>(client);
  if (err != nullptr && err->desc != nullptr && err->desc[0] != '\0') {
    std::string m = err->desc;
    if (std::find(messages->begin(), messages->end(), m) == messages->end()) messages->push_back(std::move(m));
  }
  return 0;
}

std::string join_path(hid_t loc, const std::string& name) {
  std::string parent = object_name(loc);
  if (parent.empty() || parent.back() != '/') parent += '/';
  return parent + name;
}

Handle check(hid_t id, Handle::Closer closer, const std::string& step) {
  if (id < 0) fail(step);
  return Handle(id, closer);
}

Handle dataspace(const std::vector<hsize_t>& dims) {
  if (dims.empty()) return check(H5Screate(H5S_SCALAR), H5Sclose, "create a scalar dataspace");
  return check(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, "create a dataspace");
}

Handle string_type(bool variable, size_t size = 0) {
  Handle t = check(H5Tcopy(H5T_C_S1), H5Tclose, "copy the string type");
  if (variable) {
    if (H5Tset_size(t, H5T_VARIABLE) < 0 || H5Tset_cset(t, H5T_CSET_UTF8) < 0) fail("make a UTF-8 string type");
  } else {
    if (H5Tset_size(t, size) < 0 || H5Tset_strpad(t, H5T_STR_NULLPAD) < 0 || H5Tset_cset(t, H5T_CSET_ASCII) < 0)
      fail("make a fixed-length string type");
  }
  return t;
}

hsize_t element_count(const std::vector<hsize_t>& dims) {
  hsize_t n = 1;
  for (hsize_t d : dims) n *= d;
  return n;
}

// A dataset or an attribute, opened, for the shared read paths.
struct Source {
  Handle object;
  bool attribute = false;
  std::string what;  // for messages: "dataset '/a/b'" or "attribute 'x' of '/a'"

  Handle space() const {
    return check(attribute ? H5Aget_space(object) : H5Dget_space(object), H5Sclose, "get the dataspace of " + what);
  }
  Handle type() const {
    return check(attribute ? H5Aget_type(object) : H5Dget_type(object), H5Tclose, "get the type of " + what);
  }
  void read(hid_t mem_type, void* buffer) const {
    const herr_t status = attribute ? H5Aread(object, mem_type, buffer)
                                    : H5Dread(object, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer);
    if (status < 0) fail("read " + what);
  }
};

Source open_dataset(hid_t loc, const std::string& name) {
  const std::string what = "dataset '" + join_path(loc, name) + "'";
  return Source{check(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose, "open " + what), false, what};
}

Source open_attribute(hid_t obj, const std::string& name) {
  const std::string what = "attribute '" + name + "' of '" + object_name(obj) + "'";
  return Source{check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose, "open " + what), true, what};
}

hsize_t point_count(const Source& src) {
  Handle space = src.space();
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  if (n < 0) fail("count the elements of " + src.what);
  return static_cast<hsize_t>(n);
}

std::vector<std::string> read_strings(const Source& src) {
  Handle type = src.type();
  if (H5Tget_class(type) != H5T_STRING) throw Error(src.what + " is not a string");
  const hsize_t n = point_count(src);
  std::vector<std::string> out;
  out.reserve(n);
  const htri_t variable = H5Tis_variable_str(type);
  if (variable < 0) fail("inspect the string type of " + src.what);
  if (variable > 0) {
    Handle mem = string_type(true);
    if (H5Tset_cset(mem, H5Tget_cset(type)) < 0) fail("set the character set for " + src.what);
    std::vector<char*> pointers(n, nullptr);
    if (n > 0) src.read(mem, pointers.data());
    for (char* p : pointers) {
      out.emplace_back(p != nullptr ? p : "");
      H5free_memory(p);
    }
  } else {
    const size_t size = H5Tget_size(type);
    if (size == 0) fail("get the size of " + src.what);
    Handle mem = check(H5Tget_native_type(type, H5T_DIR_ASCEND), H5Tclose, "get the memory type of " + src.what);
    std::vector<char> buffer(n * size);
    if (n > 0) src.read(mem, buffer.data());
    for (hsize_t k = 0; k < n; ++k) {
      const char* begin = buffer.data() + k * size;
      const char* end = std::find(begin, begin + size, '\0');
      out.emplace_back(begin, end);
    }
  }
  return out;
}

void write_strings_to(hid_t loc, const std::string& name, const std::vector<std::string>& values, bool scalar,
                      bool attribute) {
  const std::string what =
      (attribute ? "attribute '" + name + "' of '" + object_name(loc) + "'" : "dataset '" + join_path(loc, name) + "'");
  Handle type = string_type(true);
  Handle space = scalar ? dataspace({}) : dataspace({static_cast<hsize_t>(values.size())});
  std::vector<const char*> pointers;
  pointers.reserve(values.size());
  for (const auto& v : values) pointers.push_back(v.c_str());
  if (attribute) {
    Handle a = check(H5Acreate2(loc, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, "create " + what);
    if (!pointers.empty() && H5Awrite(a, type, pointers.data()) < 0) fail("write " + what);
  } else {
    Handle d = check(H5Dcreate2(loc, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose,
                     "create " + what);
    if (!pointers.empty() && H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, pointers.data()) < 0)
      fail("write " + what);
  }
}

}  // namespace

void fail(const std::string& step) {
  std::vector<std::string> messages;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect_error, &messages);
  std::string text = step;
  // The innermost messages say what went wrong (e.g. the errno of a failed open); the outer ones repeat the API.
  const size_t shown = std::min<size_t>(messages.size(), 2);
  for (size_t k = 0; k < shown; ++k) {
    std::string m = messages[k];
    std::replace(m.begin(), m.end(), '\n', ' ');
    text += (k == 0 ? ": " : "; ") + m;
  }
  throw Error(text);
}

QuietErrors::QuietErrors() {
  H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

QuietErrors::~QuietErrors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

Handle create_file(const std::string& path) {
  Handle fapl = check(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "create a file access property list");
  // Strong: closing the file closes anything still open in it, so the file is complete once closed.
  if (H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) < 0) fail("set the file close degree");
  // Attributes larger than an object header (64 KiB: the names of thousands of bodies or pairs) need dense
  // attribute storage, which the file format of HDF5 1.8 has: every HDF5 reader since 2008 reads it.
  if (H5Pset_libver_bounds(fapl, H5F_LIBVER_V18, H5F_LIBVER_LATEST) < 0) fail("set the file format bounds");
  Handle fcpl = check(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "create a file creation property list");
  if (H5Pset_attr_phase_change(fcpl, 0, 0) < 0) fail("set dense attribute storage");
  return check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl, fapl), H5Fclose, "create the file");
}

Handle open_file(const std::string& path) {
  return check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "open the file");
}

Handle create_group(hid_t loc, const std::string& name) {
  // Dense attribute storage (create_file): a group's attributes may exceed its object header.
  Handle gcpl = check(H5Pcreate(H5P_GROUP_CREATE), H5Pclose, "create a group creation property list");
  if (H5Pset_attr_phase_change(gcpl, 0, 0) < 0) fail("set dense attribute storage");
  return check(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, gcpl, H5P_DEFAULT), H5Gclose,
               "create group '" + join_path(loc, name) + "'");
}

Handle open_group(hid_t loc, const std::string& name) {
  return check(H5Gopen2(loc, name.c_str(), H5P_DEFAULT), H5Gclose, "open group '" + join_path(loc, name) + "'");
}

bool has_link(hid_t loc, const std::string& name) {
  const htri_t r = H5Lexists(loc, name.c_str(), H5P_DEFAULT);
  if (r < 0) fail("look up '" + join_path(loc, name) + "'");
  return r > 0;
}

void hard_link(hid_t loc, const std::string& existing, const std::string& name) {
  if (H5Lcreate_hard(loc, existing.c_str(), loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT) < 0)
    fail("link '" + join_path(loc, name) + "' to '" + existing + "'");
}

bool has_attribute(hid_t obj, const std::string& name) {
  const htri_t r = H5Aexists(obj, name.c_str());
  if (r < 0) fail("look up attribute '" + name + "' of '" + object_name(obj) + "'");
  return r > 0;
}

std::string object_name(hid_t obj) {
  const ssize_t n = H5Iget_name(obj, nullptr, 0);
  if (n <= 0) return "?";
  std::string name(static_cast<size_t>(n) + 1, '\0');
  H5Iget_name(obj, name.data(), name.size());
  name.resize(static_cast<size_t>(n));
  return name;
}

std::vector<std::string> link_names(hid_t group) {
  H5G_info_t info;
  if (H5Gget_info(group, &info) < 0) fail("list the members of '" + object_name(group) + "'");
  std::vector<std::string> names;
  for (hsize_t k = 0; k < info.nlinks; ++k) {
    const ssize_t n = H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, k, nullptr, 0, H5P_DEFAULT);
    if (n < 0) fail("get a member name of '" + object_name(group) + "'");
    std::string name(static_cast<size_t>(n) + 1, '\0');
    if (H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, k, name.data(), name.size(), H5P_DEFAULT) < 0)
      fail("get a member name of '" + object_name(group) + "'");
    name.resize(static_cast<size_t>(n));
    names.push_back(std::move(name));
  }
  return names;
}

std::vector<hsize_t> dataset_shape(hid_t loc, const std::string& name) {
  Source src = open_dataset(loc, name);
  Handle space = src.space();
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 0) fail("get the rank of " + src.what);
  std::vector<hsize_t> dims(static_cast<size_t>(rank), 0);
  if (rank > 0 && H5Sget_simple_extent_dims(space, dims.data(), nullptr) < 0) fail("get the shape of " + src.what);
  return dims;
}

void write_raw(hid_t loc, const std::string& name, hid_t mem_type, hid_t file_type, const void* data,
               const std::vector<hsize_t>& dims) {
  const std::string what = "dataset '" + join_path(loc, name) + "'";
  Handle space = dataspace(dims);
  Handle d = check(H5Dcreate2(loc, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose,
                   "create " + what);
  if (element_count(dims) > 0 && H5Dwrite(d, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) fail("write " + what);
}

void write_string_dataset(hid_t loc, const std::string& name, const std::string& value) {
  write_strings_to(loc, name, {value}, true, false);
}

void write_strings_dataset(hid_t loc, const std::string& name, const std::vector<std::string>& values) {
  write_strings_to(loc, name, values, false, false);
}

void write_attribute_raw(hid_t obj, const std::string& name, hid_t mem_type, hid_t file_type, const void* data,
                         const std::vector<hsize_t>& dims) {
  const std::string what = "attribute '" + name + "' of '" + object_name(obj) + "'";
  Handle space = dataspace(dims);
  Handle a =
      check(H5Acreate2(obj, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, "create " + what);
  if (element_count(dims) > 0 && H5Awrite(a, mem_type, data) < 0) fail("write " + what);
}

void write_attribute(hid_t obj, const std::string& name, const std::string& value) {
  write_strings_to(obj, name, {value}, true, true);
}

void write_attribute(hid_t obj, const std::string& name, const char* value) {
  write_attribute(obj, name, std::string(value != nullptr ? value : ""));
}

void write_attribute(hid_t obj, const std::string& name, const std::vector<std::string>& values) {
  write_strings_to(obj, name, values, false, true);
}

void write_fixed_string_attribute(hid_t obj, const std::string& name, const std::string& value) {
  const std::string what = "attribute '" + name + "' of '" + object_name(obj) + "'";
  if (value.empty()) throw Error("write " + what + ": a fixed-length string cannot be empty");
  Handle type = string_type(false, value.size());
  Handle space = dataspace({});
  Handle a = check(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, "create " + what);
  if (H5Awrite(a, type, value.data()) < 0) fail("write " + what);
}

void read_raw(hid_t loc, const std::string& name, hid_t mem_type, size_t elem_size, int rank,
              std::vector<hsize_t>& dims, std::vector<unsigned char>& bytes) {
  Source src = open_dataset(loc, name);
  Handle space = src.space();
  const int actual = H5Sget_simple_extent_ndims(space);
  if (actual < 0) fail("get the rank of " + src.what);
  if (actual != rank)
    throw Error(src.what + " has rank " + std::to_string(actual) + ", expected " + std::to_string(rank));
  dims.assign(static_cast<size_t>(rank), 0);
  if (rank > 0 && H5Sget_simple_extent_dims(space, dims.data(), nullptr) < 0) fail("get the shape of " + src.what);
  bytes.assign(static_cast<size_t>(element_count(dims)) * elem_size, 0);
  if (!bytes.empty()) src.read(mem_type, bytes.data());
}

std::string read_string_dataset(hid_t loc, const std::string& name) {
  Source src = open_dataset(loc, name);
  auto values = read_strings(src);
  if (values.size() != 1) throw Error(src.what + " is not a single string");
  return values.front();
}

std::vector<std::string> read_strings_dataset(hid_t loc, const std::string& name) {
  return read_strings(open_dataset(loc, name));
}

void read_attribute_raw(hid_t obj, const std::string& name, hid_t mem_type, size_t elem_size,
                        std::vector<unsigned char>& bytes) {
  Source src = open_attribute(obj, name);
  bytes.assign(static_cast<size_t>(point_count(src)) * elem_size, 0);
  if (!bytes.empty()) src.read(mem_type, bytes.data());
}

std::string read_string_attribute(hid_t obj, const std::string& name) {
  Source src = open_attribute(obj, name);
  auto values = read_strings(src);
  if (values.size() != 1) throw Error(src.what + " is not a single string");
  return values.front();
}

std::vector<std::string> read_strings_attribute(hid_t obj, const std::string& name) {
  return read_strings(open_attribute(obj, name));
}

StringTypeInfo string_attribute_type(hid_t obj, const std::string& name) {
  Source src = open_attribute(obj, name);
  Handle type = src.type();
  StringTypeInfo info;
  info.is_string = H5Tget_class(type) == H5T_STRING;
  if (!info.is_string) return info;
  info.variable_length = H5Tis_variable_str(type) > 0;
  info.size = info.variable_length ? 0 : H5Tget_size(type);
  info.padding = H5Tget_strpad(type);
  info.charset = H5Tget_cset(type);
  return info;
}

}  // namespace contact::io::h5
