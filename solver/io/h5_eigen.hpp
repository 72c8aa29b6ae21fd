// Internal to solver/io: Eigen matrices and vectors as HDF5 datasets (row-major rows x cols), written and read.
#pragma once

#include "h5.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace contact::io::h5 {

// Any Eigen matrix (either storage order) as a rows x cols dataset in HDF5's row-major order.
template <class Derived>
inline void write_matrix(hid_t loc, const std::string& name, const Eigen::MatrixBase<Derived>& m) {
  using T = typename Derived::Scalar;
  const auto rows = static_cast<size_t>(m.rows());
  const auto cols = static_cast<size_t>(m.cols());
  std::vector<T> data(rows * cols);
  for (size_t r = 0; r < rows; ++r)
    for (size_t c = 0; c < cols; ++c)
      data[r * cols + c] = m(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
  write_dataset(loc, name, data, {static_cast<hsize_t>(rows), static_cast<hsize_t>(cols)});
}

template <class Derived>
inline void write_column(hid_t loc, const std::string& name, const Eigen::MatrixBase<Derived>& v) {
  using T = typename Derived::Scalar;
  std::vector<T> data(static_cast<size_t>(v.size()));
  for (Eigen::Index k = 0; k < v.size(); ++k) data[static_cast<size_t>(k)] = v(k);
  write_vector(loc, name, data);
}

// A rows x cols dataset into a column-major Eigen matrix (its columns checked unless expected_cols < 0).
template <class T>
inline Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> read_matrix(hid_t loc, const std::string& name,
                                                                    Eigen::Index expected_cols = -1) {
  std::vector<hsize_t> dims;
  const std::vector<T> data = read_dataset<T>(loc, name, 2, dims);
  const auto rows = static_cast<Eigen::Index>(dims[0]);
  const auto cols = static_cast<Eigen::Index>(dims[1]);
  if (expected_cols >= 0 && cols != expected_cols)
    throw Error("dataset '" + object_name(loc) + "/" + name + "' has " + std::to_string(cols) + " columns, expected " +
                std::to_string(expected_cols));
  using RowMajor = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  return Eigen::Map<const RowMajor>(data.data(), rows, cols);
}

// A 1-D dataset as an Eigen vector.
template <class T>
inline Eigen::Matrix<T, Eigen::Dynamic, 1> read_column(hid_t loc, const std::string& name) {
  const std::vector<T> data = read_vector<T>(loc, name);
  return Eigen::Map<const Eigen::Matrix<T, Eigen::Dynamic, 1>>(data.data(), static_cast<Eigen::Index>(data.size()));
}

// A row-major n x 3 copy of an n x 2 field with a zero third column (VTK's vectors are 3-D).
inline Eigen::MatrixX3d with_zero_z(const Eigen::MatrixX2d& m) {
  Eigen::MatrixX3d out = Eigen::MatrixX3d::Zero(m.rows(), 3);
  out.leftCols<2>() = m;
  return out;
}

}  // namespace contact::io::h5
